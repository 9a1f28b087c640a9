"""Ambient temperature over the day (paper §3.1) and a default climatology.

The paper's daily sine: ``x = sin((hr − 8)·π/12)``,
``ϑ_amb = (ϑ⁺ + ϑ⁻)/2 + (ϑ⁺ − ϑ⁻)/2 · x`` — lowest at 02:00, highest at 14:00 local time.
"""

from __future__ import annotations

import datetime as dt
import math
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray
from core.params import Weather

WeatherSource = Literal["request", "climatology"]

# Coarse sea-level climatology by absolute latitude [°]: annual mean [°C], half the difference
# between the warmest and the coldest month [K], and the mean daily range (max − min) [K].
# Rounded values representative of WMO 1991–2020 climate normals of low-lying stations at those
# latitudes (e.g. 48° ≈ Vienna: annual mean 11 °C, January ≈ 0.5 °C, July ≈ 21.5 °C, daily
# range ≈ 8 K; 0° ≈ Singapore; 60° ≈ Helsinki). A coarse default: send a forecast to plan.
_CLIMATE_LAT_DEG = np.array([0.0, 15.0, 30.0, 40.0, 48.0, 55.0, 60.0, 70.0, 90.0])
_CLIMATE_MEAN_C = np.array([27.0, 26.0, 20.0, 15.0, 11.0, 8.5, 6.0, -1.0, -18.0])
_CLIMATE_SEASONAL_K = np.array([1.0, 3.0, 7.5, 9.5, 10.5, 9.5, 11.0, 13.0, 15.0])
_CLIMATE_DAILY_RANGE_K = np.array([7.0, 9.0, 11.0, 11.0, 8.5, 7.5, 7.0, 6.0, 4.0])
# Day of year of the coldest month's middle in the northern hemisphere (mid-January); the
# warmest comes half a year later (mid-July). Swapped south of the equator.
_COLDEST_DAY_NORTH = 15


def daily_temperature_c(weather: Weather, local_hour: ArrayLike) -> FloatArray:
    """Ambient temperature at a local clock hour [°C] (paper §3.1).

    Parameters
    ----------
    weather
        The day's lowest and highest temperature ϑ⁻, ϑ⁺ [°C].
    local_hour
        Local clock time in hours since midnight [h] (values beyond 24 wrap to the next day).
    """
    x = np.sin((np.asarray(local_hour, dtype=float) - 8.0) * np.pi / 12.0)
    mean = 0.5 * (weather.t_max_c + weather.t_min_c)
    half_range = 0.5 * (weather.t_max_c - weather.t_min_c)
    return mean + half_range * x


def climatology(date: dt.date, lat: float) -> Weather:
    """Default daily extremes for a date and latitude from the coarse climatology above.

    The annual cycle is a cosine with its minimum in mid-January (mid-July in the southern
    hemisphere); the daily extremes are the day's mean ∓ half the daily range.

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
    daily_range = float(np.interp(abs_lat, _CLIMATE_LAT_DEG, _CLIMATE_DAILY_RANGE_K))
    coldest = _COLDEST_DAY_NORTH if lat >= 0 else _COLDEST_DAY_NORTH + 182.5
    phase = 2.0 * math.pi * (date.timetuple().tm_yday - coldest) / 365.25
    day_mean = mean - seasonal * math.cos(phase)
    return Weather(
        t_min_c=round(day_mean - daily_range / 2, 1), t_max_c=round(day_mean + daily_range / 2, 1)
    )


def resolve_weather(
    weather: Weather | None, date: dt.date, lat: float
) -> tuple[Weather, WeatherSource]:
    """The forecast if one was given, else the climatology; and which of the two was used."""
    if weather is not None:
        return weather, "request"
    return climatology(date, lat), "climatology"
