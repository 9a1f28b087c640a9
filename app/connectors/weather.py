"""An Open-Meteo-compatible weather API over HTTP: the hourly forecast, or the archive for
past dates, at the depot.

``GET {url}/v1/forecast?latitude=…&longitude=…&hourly=temperature_2m,direct_radiation,
diffuse_radiation,cloud_cover,wind_speed_10m,wind_direction_10m&start_date=…&end_date=…
&timezone=UTC`` (``{archive_url}/v1/archive`` with the same query for days that have passed),
read from the documented JSON: ``hourly.time`` (ISO 8601 local to ``utc_offset_seconds``), the
``hourly`` arrays and their ``hourly_units``. Any failure — unreachable, slow, an error status,
garbage, missing hours — raises :class:`core.exceptions.ServiceUnavailableError`; the planner
then falls back to the climatology and says so.
"""

from __future__ import annotations

import datetime as dt
from typing import Any

import httpx
import numpy as np

from core.exceptions import ServiceUnavailableError
from core.physics.weather import HourlyWeather

SERVICE = "weather"
HOURLY = (
    "temperature_2m",
    "direct_radiation",
    "diffuse_radiation",
    "cloud_cover",
    "wind_speed_10m",
    "wind_direction_10m",
)
#: Days before today from which the archive answers instead of the forecast.
ARCHIVE_AFTER_DAYS = 2
_WIND_TO_MPS = {"km/h": 1 / 3.6, "m/s": 1.0, "mph": 0.44704, "kn": 0.514444, "kt": 0.514444}


class OpenMeteo:
    """A :class:`core.routing.roads.WeatherService` for an Open-Meteo-compatible API.

    Parameters
    ----------
    url, archive_url
        Base URLs of the forecast and the archive API.
    timeout_s
        Timeout of each call [s].
    """

    def __init__(self, url: str, archive_url: str, timeout_s: float) -> None:
        self.url = url.rstrip("/")
        self.archive_url = archive_url.rstrip("/")
        self._client = httpx.Client(
            timeout=httpx.Timeout(timeout_s), transport=httpx.HTTPTransport(retries=1)
        )

    def hourly(self, lat: float, lon: float, start: dt.datetime, end: dt.datetime) -> HourlyWeather:
        """Hourly weather from the hour before ``start`` to the hour after ``end`` (UTC)."""
        first = (start - dt.timedelta(hours=1)).astimezone(dt.UTC).date()
        last = (end + dt.timedelta(hours=1)).astimezone(dt.UTC).date()
        today = dt.datetime.now(dt.UTC).date()
        archived = last < today - dt.timedelta(days=ARCHIVE_AFTER_DAYS)
        endpoint = f"{self.archive_url}/v1/archive" if archived else f"{self.url}/v1/forecast"
        params = {
            "latitude": f"{lat:.4f}",
            "longitude": f"{lon:.4f}",
            "hourly": ",".join(HOURLY),
            "start_date": first.isoformat(),
            "end_date": last.isoformat(),
            "timezone": "UTC",
        }
        try:
            response = self._client.get(endpoint, params=params)
        except httpx.TimeoutException:
            raise ServiceUnavailableError(SERVICE, f"{endpoint} did not answer in time") from None
        except httpx.HTTPError as error:
            raise ServiceUnavailableError(
                SERVICE, f"{endpoint} is unreachable ({type(error).__name__})"
            ) from None
        if response.status_code != 200:
            raise ServiceUnavailableError(
                SERVICE, f"{endpoint} answered HTTP {response.status_code}"
            )
        try:
            body = response.json()
            weather = _parse(body, "archive" if archived else "forecast")
        except (ValueError, KeyError, TypeError) as error:
            raise ServiceUnavailableError(
                SERVICE, f"{endpoint} answered garbage ({error})"
            ) from None
        if weather.time_utc_s[0] > start.timestamp() or weather.time_utc_s[-1] < end.timestamp():
            raise ServiceUnavailableError(SERVICE, f"{endpoint} does not cover the whole round")
        return weather


def _parse(body: Any, source: str) -> HourlyWeather:
    """The documented JSON → :class:`HourlyWeather`; hours with a missing value are dropped."""
    hourly, units = body["hourly"], body.get("hourly_units", {})
    offset_s = float(body.get("utc_offset_seconds", 0))
    times = np.array(
        [
            dt.datetime.fromisoformat(t).replace(tzinfo=dt.UTC).timestamp() - offset_s
            for t in hourly["time"]
        ]
    )
    columns = {
        name: np.array(hourly[name], dtype=float) for name in HOURLY if name != "cloud_cover"
    }
    if any(c.shape != times.shape for c in columns.values()):
        raise ValueError("hourly arrays differ in length")
    complete = np.all([np.isfinite(c) for c in columns.values()], axis=0)
    temperature = columns["temperature_2m"]
    if units.get("temperature_2m", "°C") in ("°F", "fahrenheit"):
        temperature = (temperature - 32.0) / 1.8
    wind_unit = units.get("wind_speed_10m", "km/h")
    if wind_unit not in _WIND_TO_MPS:
        raise ValueError(f"unknown wind unit {wind_unit!r}")
    return HourlyWeather(
        time_utc_s=times[complete],
        temperature_c=temperature[complete],
        direct_radiation_w_m2=columns["direct_radiation"][complete],
        diffuse_radiation_w_m2=columns["diffuse_radiation"][complete],
        wind_speed_mps=columns["wind_speed_10m"][complete] * _WIND_TO_MPS[wind_unit],
        wind_direction_deg=columns["wind_direction_10m"][complete],
        source="archive" if source == "archive" else "forecast",
    )
