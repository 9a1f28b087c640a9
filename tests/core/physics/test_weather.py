import datetime as dt
from zoneinfo import ZoneInfo

import numpy as np
import pytest

from core.clock import local_clock
from core.exceptions import InvalidParameterError
from core.params import Weather
from core.physics.weather import (
    WIND_HEIGHT_FACTOR,
    HourlyWeather,
    climatology,
    conditions,
    daily_temperature_c,
    headwind_mps,
)

DAY = Weather(t_min_c=12, t_max_c=28)
VIENNA = ZoneInfo("Europe/Vienna")


def test_daily_sine_extremes_and_mean():
    # paper §3.1: minimum at 02:00, maximum at 14:00, mean at 08:00 and 20:00
    assert daily_temperature_c(12, 28, 2.0) == pytest.approx(12)
    assert daily_temperature_c(12, 28, 14.0) == pytest.approx(28)
    assert daily_temperature_c(12, 28, 8.0) == pytest.approx(20)
    assert daily_temperature_c(12, 28, 20.0) == pytest.approx(20)
    # 11:00: x = sin(3π/12) = 0.7071 → 20 + 8 · 0.7071 = 25.66
    assert daily_temperature_c(12, 28, 11.0) == pytest.approx(25.657, abs=1e-3)


def test_climatology_vienna_summer_and_winter():
    # Vienna 48.2° N normals (WMO 1991–2020): July daily mean ≈ 21.5 °C, January ≈ 0.5 °C
    july = climatology(dt.date(2026, 7, 15), 48.2)
    january = climatology(dt.date(2026, 1, 15), 48.2)
    assert (july.t_min_c + july.t_max_c) / 2 == pytest.approx(21.5, abs=1.5)
    assert (january.t_min_c + january.t_max_c) / 2 == pytest.approx(0.5, abs=1.5)


def test_climatology_daily_range_follows_the_season():
    # Vienna (Hohe Warte, 1991–2020): mean daily range ≈ 5 K in January, ≈ 10 K in July
    july = climatology(dt.date(2026, 7, 15), 48.2)
    january = climatology(dt.date(2026, 1, 15), 48.2)
    assert january.t_max_c - january.t_min_c == pytest.approx(5.0, abs=1.0)
    assert july.t_max_c - july.t_min_c == pytest.approx(10.5, abs=1.0)


def test_climatology_seasons_flip_south_of_equator():
    north = climatology(dt.date(2026, 1, 15), 40.0)
    south = climatology(dt.date(2026, 1, 15), -40.0)
    assert south.t_max_c > north.t_max_c + 10


def _clock(start, hours):
    return local_clock(start, np.arange(0, hours * 3600 + 1, 600.0))


def test_request_weather_applies_every_day_and_climatology_each_its_own():
    start = dt.datetime(2026, 1, 15, 20, tzinfo=VIENNA)
    clock = _clock(start, 20)  # until 16:00 on 16 January
    forecast = conditions(DAY, clock, 48.2)
    assert forecast.source == "request" and len(forecast.days) == 2
    assert all((d.t_min_c, d.t_max_c) == (12, 28) for d in forecast.days)
    default = conditions(None, clock, 48.2)
    assert default.source == "climatology"
    assert [d.date for d in default.days] == [dt.date(2026, 1, 15), dt.date(2026, 1, 16)]
    assert [(d.t_min_c, d.t_max_c) for d in default.days] == [
        (w.t_min_c, w.t_max_c)
        for w in (climatology(dt.date(2026, 1, 15), 48.2), climatology(dt.date(2026, 1, 16), 48.2))
    ]


def _hourly(**overrides):
    hours = np.arange(0, 48)
    base = dict(
        time_utc_s=dt.datetime(2026, 7, 15, tzinfo=dt.UTC).timestamp() + hours * 3600.0,
        temperature_c=20 + hours % 24 * 0.5,
        direct_radiation_w_m2=np.full(48, 300.0),
        diffuse_radiation_w_m2=np.full(48, 100.0),
        wind_speed_mps=np.full(48, 10.0),
        wind_direction_deg=np.where(hours < 10, 350.0, 10.0),
    )
    return HourlyWeather(**(base | overrides))


def test_hourly_forecast_is_interpolated_between_hours():
    start = dt.datetime(2026, 7, 15, 5, 30, tzinfo=dt.UTC)
    clock = local_clock(start, np.array([0.0, 1800.0]))
    outside = conditions(_hourly(), clock, 48.2)
    # 05:30 lies between 22.5 °C (05:00) and 23.0 °C (06:00); 06:00 is 23.0 °C
    assert outside.ambient_c == pytest.approx([22.75, 23.0])
    assert outside.source == "forecast"
    assert outside.direct_horizontal_w_m2 == pytest.approx([300, 300])


def test_wind_direction_interpolates_through_north():
    # 09:30 UTC lies between wind from 350° and from 10°: from 0° at 10 m/s·cos(10°)
    clock = local_clock(dt.datetime(2026, 7, 15, 9, 30, tzinfo=dt.UTC), np.array([0.0]))
    outside = conditions(_hourly(), clock, 48.2)
    assert outside.wind_from_east_mps == pytest.approx([0.0], abs=1e-9)
    expected = 10 * np.cos(np.radians(10)) * WIND_HEIGHT_FACTOR
    assert outside.wind_from_north_mps == pytest.approx([expected])
    # driving north into a north wind: headwind; driving south: tailwind; east: none
    north = outside.wind_from_north_mps
    east = outside.wind_from_east_mps
    assert headwind_mps(east, north, np.array([0.0])) == pytest.approx(north)
    assert headwind_mps(east, north, np.array([180.0])) == pytest.approx(-north)
    assert headwind_mps(east, north, np.array([90.0])) == pytest.approx([0.0], abs=1e-9)
    assert headwind_mps(east, north, np.array([np.nan])) == [0.0]


def test_wind_at_van_height():
    # power law 1/7 from 10 m to 2 m: (0.2)^(1/7) = 0.7945
    assert pytest.approx(0.7945, abs=1e-4) == WIND_HEIGHT_FACTOR


@pytest.mark.parametrize(
    "change",
    [
        {"temperature_c": np.full(48, np.nan)},
        {"wind_speed_mps": np.full(47, 1.0)},
        {"direct_radiation_w_m2": np.full(48, -5.0)},
        {"time_utc_s": np.zeros(48)},
    ],
)
def test_hourly_weather_rejects_garbage(change):
    with pytest.raises(InvalidParameterError):
        _hourly(**change)
