import datetime as dt

import pytest

from core.params import Weather
from core.weather import climatology, daily_temperature_c, resolve_weather

DAY = Weather(t_min_c=12, t_max_c=28)


def test_daily_sine_extremes_and_mean():
    # paper §3.1: minimum at 02:00, maximum at 14:00, mean at 08:00 and 20:00
    assert daily_temperature_c(DAY, 2.0) == pytest.approx(12)
    assert daily_temperature_c(DAY, 14.0) == pytest.approx(28)
    assert daily_temperature_c(DAY, 8.0) == pytest.approx(20)
    assert daily_temperature_c(DAY, 20.0) == pytest.approx(20)
    # 11:00: x = sin(3π/12) = 0.7071 → 20 + 8 · 0.7071 = 25.66
    assert daily_temperature_c(DAY, 11.0) == pytest.approx(25.657, abs=1e-3)


def test_climatology_vienna_summer_and_winter():
    # Vienna 48.2° N normals (WMO 1991–2020): July daily mean ≈ 21.5 °C, January ≈ 0.5 °C
    july = climatology(dt.date(2026, 7, 15), 48.2)
    january = climatology(dt.date(2026, 1, 15), 48.2)
    assert (july.t_min_c + july.t_max_c) / 2 == pytest.approx(21.5, abs=1.5)
    assert (january.t_min_c + january.t_max_c) / 2 == pytest.approx(0.5, abs=1.5)
    assert 6 <= july.t_max_c - july.t_min_c <= 12


def test_climatology_seasons_flip_south_of_equator():
    north = climatology(dt.date(2026, 1, 15), 40.0)
    south = climatology(dt.date(2026, 1, 15), -40.0)
    assert south.t_max_c > north.t_max_c + 10


def test_forecast_wins_over_climatology():
    assert resolve_weather(DAY, dt.date(2026, 1, 1), 48.2) == (DAY, "request")
    weather, source = resolve_weather(None, dt.date(2026, 1, 1), 48.2)
    assert source == "climatology" and weather.t_max_c < 10
