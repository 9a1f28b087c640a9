"""Clients of the outside services, built from the settings; each implements a protocol of
:mod:`core.routing.roads` and hands the core plain arrays."""

from __future__ import annotations

from functools import lru_cache

from app.connectors.osrm import OsrmRouter
from app.connectors.weather import OpenMeteo
from app.settings import Settings
from core.physics.weather import WeatherService
from core.routing.roads import RoadRouter


def router(settings: Settings) -> RoadRouter | None:
    """The configured road router, or None for the built-in estimate."""
    if settings.osrm_url is None:
        return None
    return _osrm(
        settings.osrm_url,
        settings.osrm_timeout_s,
        settings.osrm_table_size,
        settings.max_snap_distance_m,
    )


def weather_service(settings: Settings) -> WeatherService | None:
    """The configured weather service, or None for the climatology."""
    if settings.weather_url is None:
        return None
    return _open_meteo(
        settings.weather_url,
        settings.weather_archive_url or settings.weather_url,
        settings.weather_timeout_s,
    )


# One client per configuration and process: connections are pooled and reused across requests.
@lru_cache(maxsize=8)
def _osrm(url: str, timeout_s: float, table_size: int, max_snap_m: float) -> OsrmRouter:
    return OsrmRouter(url, timeout_s, table_size, max_snap_m)


@lru_cache(maxsize=8)
def _open_meteo(url: str, archive_url: str, timeout_s: float) -> OpenMeteo:
    return OpenMeteo(url, archive_url, timeout_s)
