"""Outside conditions along a trace: temperature, sun and wind.

Three sources, best first:

* an hourly forecast or archive (:class:`HourlyWeather`, from an Open-Meteo-compatible service
  that the web layer reads): temperature interpolated between the hours, the measured or
  forecast sun instead of the clear sky, and the wind;
* a request's daily extremes (:class:`core.params.Weather`) on the paper's daily sine (§3.1):
  ``x = sin((hr − 8)·π/12)``, ``ϑ_amb = (ϑ⁺ + ϑ⁻)/2 + (ϑ⁺ − ϑ⁻)/2 · x`` — lowest at 02:00,
  highest at 14:00 local time;
* a coarse climatology by latitude and date, on the same sine, one day at a time.
"""

from __future__ import annotations

import datetime as dt
import math
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np
from numpy.typing import ArrayLike
from pydantic import Field

from core.arrays import FloatArray
from core.clock import LocalClock
from core.exceptions import InvalidParameterError, ServiceUnavailableError
from core.params import Result, Weather

WeatherSource = Literal["request", "forecast", "archive", "climatology"]

# Coarse sea-level climatology by absolute latitude [°]: annual mean [°C], half the difference
# between the warmest and the coldest month [K], the annual mean daily range (max − min) [K] and
# half the difference between the summer and the winter daily range [K]. Rounded values
# representative of WMO 1991–2020 climate normals of low-lying stations at those latitudes
# (e.g. 48° ≈ Vienna: annual mean 11 °C, January ≈ 0.5 °C, July ≈ 21.5 °C, daily range ≈ 5 K
# in January and ≈ 10.5 K in July; 0° ≈ Singapore; 60° ≈ Helsinki). A coarse default: send a
# forecast to plan.
_CLIMATE_LAT_DEG = np.array([0.0, 15.0, 30.0, 40.0, 48.0, 55.0, 60.0, 70.0, 90.0])
_CLIMATE_MEAN_C = np.array([27.0, 26.0, 20.0, 15.0, 11.0, 8.5, 6.0, -1.0, -18.0])
_CLIMATE_SEASONAL_K = np.array([1.0, 3.0, 7.5, 9.5, 10.5, 9.5, 11.0, 13.0, 15.0])
_CLIMATE_DAILY_RANGE_K = np.array([7.0, 9.0, 11.0, 11.0, 8.0, 7.5, 7.0, 6.0, 4.0])
_CLIMATE_RANGE_SEASONAL_K = np.array([0.5, 1.0, 2.0, 2.5, 2.8, 2.8, 3.0, 2.5, 1.5])
# Day of year of the coldest month's middle in the northern hemisphere (mid-January); the
# warmest comes half a year later (mid-July). Swapped south of the equator.
_COLDEST_DAY_NORTH = 15

#: Wind at the van's height over the 10 m wind of a forecast [–]: power law with exponent 1/7
#: from 10 m down to 2 m (the neutral-stability profile over open terrain; streets shelter
#: more, so this errs on the windy side).
WIND_HEIGHT_FACTOR = (2.0 / 10.0) ** (1.0 / 7.0)


def daily_temperature_c(
    t_min_c: ArrayLike, t_max_c: ArrayLike, local_hour: ArrayLike
) -> FloatArray:
    """Ambient temperature at a local clock hour [°C] (paper §3.1).

    Parameters
    ----------
    t_min_c, t_max_c
        The day's lowest and highest temperature ϑ⁻, ϑ⁺ [°C], scalars or one per hour value.
    local_hour
        Local clock time in hours since midnight [h].
    """
    x = np.sin((np.asarray(local_hour, dtype=float) - 8.0) * np.pi / 12.0)
    low = np.asarray(t_min_c, dtype=float)
    high = np.asarray(t_max_c, dtype=float)
    return 0.5 * (high + low) + 0.5 * (high - low) * x


def climatology(date: dt.date, lat: float) -> Weather:
    """Default daily extremes for a date and latitude from the coarse climatology above.

    The annual cycles of the daily mean and of the daily range are cosines with their minimum
    in mid-January (mid-July in the southern hemisphere); the extremes are the day's mean ∓ half
    the day's range.

    Parameters
    ----------
    date
        The day.
    lat
        Latitude [°], north positive.
    """
    abs_lat = abs(lat)
    mean = float(np.interp(abs_lat, _CLIMATE_LAT_DEG, _CLIMATE_MEAN_C))
    seasonal = float(np.interp(abs_lat, _CLIMATE_LAT_DEG, _CLIMATE_SEASONAL_K))
    mean_range = float(np.interp(abs_lat, _CLIMATE_LAT_DEG, _CLIMATE_DAILY_RANGE_K))
    range_seasonal = float(np.interp(abs_lat, _CLIMATE_LAT_DEG, _CLIMATE_RANGE_SEASONAL_K))
    coldest = _COLDEST_DAY_NORTH if lat >= 0 else _COLDEST_DAY_NORTH + 182.5
    winterness = math.cos(2.0 * math.pi * (date.timetuple().tm_yday - coldest) / 365.25)
    day_mean = mean - seasonal * winterness
    daily_range = mean_range - range_seasonal * winterness
    return Weather(
        t_min_c=round(day_mean - daily_range / 2, 1), t_max_c=round(day_mean + daily_range / 2, 1)
    )


@dataclass(frozen=True)
class HourlyWeather:
    """An hourly forecast or archive at one place (Open-Meteo's ``hourly`` block).

    Attributes
    ----------
    time_utc_s
        Start of each hour, seconds since 1970-01-01T00:00Z [s], strictly rising.
    temperature_c
        Air temperature at 2 m at each time [°C].
    direct_radiation_w_m2, diffuse_radiation_w_m2
        Direct and diffuse shortwave radiation on a horizontal surface, mean of the hour that
        ends at each time [W/m²].
    wind_speed_mps
        Wind speed at 10 m [m/s].
    wind_direction_deg
        Direction the wind comes from [°], 0 north, 90 east.
    source
        ``forecast`` or ``archive``.
    """

    time_utc_s: FloatArray
    temperature_c: FloatArray
    direct_radiation_w_m2: FloatArray
    diffuse_radiation_w_m2: FloatArray
    wind_speed_mps: FloatArray
    wind_direction_deg: FloatArray
    source: Literal["forecast", "archive"] = "forecast"

    def __post_init__(self) -> None:
        n = self.time_utc_s.size
        limits = {
            "temperature_c": (-90.0, 60.0),
            "direct_radiation_w_m2": (0.0, 1400.0),
            "diffuse_radiation_w_m2": (0.0, 1400.0),
            "wind_speed_mps": (0.0, 120.0),
            "wind_direction_deg": (0.0, 360.0),
        }
        if n < 2 or np.any(np.diff(self.time_utc_s) <= 0):
            raise InvalidParameterError(
                "hourly weather needs at least two strictly rising times", "weather.time"
            )
        for name, (low, high) in limits.items():
            values = getattr(self, name)
            if values.shape != (n,):
                raise InvalidParameterError(f"{name} must hold one value per time", name)
            if not np.all(np.isfinite(values) & (values >= low) & (values <= high)):
                raise InvalidParameterError(f"{name} must be finite and within {low}..{high}", name)


Forecast = Weather | HourlyWeather


class DayWeather(Result):
    """One local day's temperatures."""

    date: dt.date = Field(..., description="The local day.")
    t_min_c: float = Field(..., description="Lowest temperature of the day's moments [°C].")
    t_max_c: float = Field(..., description="Highest temperature of the day's moments [°C].")


@dataclass(frozen=True)
class Conditions:
    """Outside conditions at every moment of a trace.

    Attributes
    ----------
    ambient_c
        Air temperature [°C].
    direct_horizontal_w_m2, diffuse_horizontal_w_m2
        Measured or forecast sun on a horizontal surface [W/m²]; None: the clear sky of eq. 13.
    wind_from_east_mps, wind_from_north_mps
        The wind at the van's height as the vector it comes from [m/s]: ``w·sin θ``,
        ``w·cos θ`` for wind from θ (0 north, 90 east); vectors interpolate where angles
        cannot.
    days
        The extremes of each local day.
    source
        Where they came from.
    """

    ambient_c: FloatArray
    direct_horizontal_w_m2: FloatArray | None
    diffuse_horizontal_w_m2: FloatArray | None
    wind_from_east_mps: FloatArray
    wind_from_north_mps: FloatArray
    days: list[DayWeather]
    source: WeatherSource


def conditions(weather: Forecast | None, clock: LocalClock, lat: float) -> Conditions:
    """Outside conditions at each moment of ``clock``.

    Parameters
    ----------
    weather
        An hourly forecast, a request's daily extremes, or None for the climatology of each
        local day at latitude ``lat`` [°].
    clock
        The moments.
    """
    calm = np.zeros(clock.hour.size)
    if isinstance(weather, HourlyWeather):
        t = weather.time_utc_s
        ambient = np.interp(clock.utc_s, t, weather.temperature_c)
        # Radiation is the mean of the hour that ends at its time stamp: centre it.
        centred = t - 1800.0
        direct = np.interp(clock.utc_s, centred, weather.direct_radiation_w_m2)
        diffuse = np.interp(clock.utc_s, centred, weather.diffuse_radiation_w_m2)
        # The direction is interpolated through its components, so 350° and 10° meet at 0°.
        radians = np.radians(weather.wind_direction_deg)
        east = np.interp(clock.utc_s, t, weather.wind_speed_mps * np.sin(radians))
        north = np.interp(clock.utc_s, t, weather.wind_speed_mps * np.cos(radians))
        days = [
            DayWeather(
                date=date,
                t_min_c=float(ambient[clock.day_index == index].min()),
                t_max_c=float(ambient[clock.day_index == index].max()),
            )
            for index, date in enumerate(clock.dates)
            if np.any(clock.day_index == index)
        ]
        return Conditions(
            ambient_c=ambient,
            direct_horizontal_w_m2=direct,
            diffuse_horizontal_w_m2=diffuse,
            wind_from_east_mps=east * WIND_HEIGHT_FACTOR,
            wind_from_north_mps=north * WIND_HEIGHT_FACTOR,
            days=days,
            source=weather.source,
        )
    if weather is not None:
        daily = [weather] * len(clock.dates)
        source: WeatherSource = "request"
    else:
        daily = [climatology(date, lat) for date in clock.dates]
        source = "climatology"
    low = clock.per_moment([w.t_min_c for w in daily])
    high = clock.per_moment([w.t_max_c for w in daily])
    return Conditions(
        ambient_c=daily_temperature_c(low, high, clock.hour),
        direct_horizontal_w_m2=None,
        diffuse_horizontal_w_m2=None,
        wind_from_east_mps=calm,
        wind_from_north_mps=calm,
        days=[
            DayWeather(date=d, t_min_c=w.t_min_c, t_max_c=w.t_max_c)
            for d, w in zip(clock.dates, daily, strict=True)
        ],
        source=source,
    )


def headwind_mps(
    wind_from_east_mps: FloatArray, wind_from_north_mps: FloatArray, heading_deg: FloatArray
) -> FloatArray:
    """Wind against the van's direction of travel [m/s] (negative: tailwind).

    ``w·cos(θ_wind_from − θ_heading) = E·sin θ_h + N·cos θ_h`` with the wind's "from" vector
    (E, N); zero where the heading is unknown (NaN).
    """
    heading = np.asarray(heading_deg, dtype=float)
    # A road's heading changes segment by segment: take the trigonometry once per run.
    if heading.size:
        before, after = heading[:-1], heading[1:]
        same = (after == before) | (np.isnan(after) & np.isnan(before))
        changes = np.flatnonzero(~same) + 1
        runs = np.concatenate(([0], changes))
        lengths = np.diff(np.append(runs, heading.size))
        radians = np.radians(heading[runs])
        east, north = np.repeat(np.sin(radians), lengths), np.repeat(np.cos(radians), lengths)
    else:
        east = north = heading
    head = wind_from_east_mps * east + wind_from_north_mps * north
    return np.where(np.isfinite(head), head, 0.0)


class WeatherService(Protocol):
    """An hourly forecast (or archive) at one place."""

    def hourly(self, lat: float, lon: float, start: dt.datetime, end: dt.datetime) -> HourlyWeather:
        """Hourly weather covering ``start``..``end`` (UTC-aware); raises
        :class:`core.exceptions.ServiceUnavailableError` when it cannot."""
        ...


def forecast_for(
    requested: Weather | None,
    service: WeatherService | None,
    lat: float,
    lon: float,
    start: dt.datetime,
    span_s: float,
) -> tuple[Forecast | None, list[str]]:
    """The weather to simulate ``span_s`` seconds from ``start`` with, and any warning.

    The request's own weather wins; else the service's hourly forecast; else None (the
    climatology) — with a warning when the service was asked and failed.
    """
    if requested is not None or service is None:
        return requested, []
    begin = start.astimezone(dt.UTC)
    try:
        return service.hourly(lat, lon, begin, begin + dt.timedelta(seconds=span_s)), []
    except ServiceUnavailableError as error:
        return None, [
            f"weather service unavailable ({error.message}); used the climatology for the "
            "date and latitude"
        ]
