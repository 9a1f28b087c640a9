"""Charging curve, charge times and partial charges against hand calculations
(core/physics/charging.py's closed forms: t = C/η·∫ds/P(s))."""

from __future__ import annotations

import datetime as dt
import math
from zoneinfo import ZoneInfo

import numpy as np
import pytest

from core.exceptions import InvalidParameterError
from core.params import BatteryParams, ChargingSpell, Interval, Location, VanParams, Weather
from core.physics.charging import charge_curve
from core.physics.simulate import Along, simulate, with_battery

KWH = 3.6e6
VIENNA = Location(lat=48.21, lon=16.37)
#: 40 kWh, 90 % charging efficiency, 50 kW van, default curve (flat to 80 %, 10 kW at full).
BATTERY = BatteryParams(usable_capacity_kwh=40.0, charging_efficiency=0.9)


def test_a_22_kw_charger_caps_the_curve_until_the_taper_falls_below_it():
    curve = charge_curve(BATTERY, 22_000.0)
    # 50 − 40·(s − 0.8)/0.2 = 22 kW at s = 0.94: flat 22 kW up to there, then 22 → 10 kW.
    assert curve.soc.tolist() == pytest.approx([0.0, 0.8, 0.94, 1.0])
    assert curve.power_w.tolist() == pytest.approx([22e3, 22e3, 22e3, 10e3])
    # 0.20 → 0.94 at 22 kW: 0.74 · 40 kWh / (0.9 · 22 kW) = 5381.8 s.
    flat_s = 0.74 * 40 * KWH / (0.9 * 22e3)
    assert curve.time_s(0.2, 0.94) == pytest.approx(flat_s, rel=1e-9)
    # 0.94 → 1.00 tapering 22 → 10 kW: 0.06/(10 − 22 kW) · ln(10/22) · C/η = 630.8 s.
    taper_s = 0.06 / (10e3 - 22e3) * math.log(10 / 22) * 40 * KWH / 0.9
    assert taper_s == pytest.approx(630.8, abs=0.1)
    assert curve.time_s(0.2, 1.0) == pytest.approx(flat_s + taper_s, rel=1e-9)


def test_a_fast_charger_is_capped_by_the_van_and_slows_past_80_percent():
    curve = charge_curve(BATTERY, 150_000.0)
    assert curve.power_at_w([0.5, 0.8, 0.9, 1.0]).tolist() == pytest.approx(
        [50e3, 50e3, 30e3, 10e3]
    )
    # 10 % → 80 %: 0.7 · 40 kWh / (0.9 · 50 kW) = 2240 s; 80 → 90 %: 50 → 30 kW.
    assert curve.time_s(0.1, 0.8) == pytest.approx(2240.0, rel=1e-9)
    taper = 0.1 / (30e3 - 50e3) * math.log(30 / 50) * 40 * KWH / 0.9
    assert curve.time_s(0.8, 0.9) == pytest.approx(taper, rel=1e-9)
    # the same 10 % of charge takes longer above 80 % than below
    assert curve.time_s(0.8, 0.9) > curve.time_s(0.6, 0.7)


def test_soc_after_inverts_the_charge_time_and_stops_at_full():
    curve = charge_curve(BATTERY, 22_000.0)
    times = np.array([0.0, 600.0, curve.time_s(0.3, 0.94), curve.time_s(0.3, 0.99), 1e6])
    after = curve.soc_after(0.3, times)
    # 600 s at 22 kW stores 0.9 · 22 kW · 600 s = 3.3 kWh: 0.3 + 3.3/40 = 0.3825.
    assert after.tolist() == pytest.approx([0.3, 0.3825, 0.94, 0.99, 1.0], rel=1e-9)
    assert curve.stored_j(0.3, 600.0) == pytest.approx(3.3 * KWH, rel=1e-9)


def test_an_own_curve_is_held_flat_beyond_its_points():
    battery = BatteryParams(
        usable_capacity_kwh=40.0,
        charging_efficiency=0.9,
        charging_curve=[
            {"soc": 0.2, "power_kw": 40.0},
            {"soc": 0.6, "power_kw": 40.0},
            {"soc": 0.9, "power_kw": 20.0},
        ],
    )
    curve = charge_curve(battery, 100_000.0)
    assert curve.power_at_w([0.0, 0.2, 0.75, 0.95]).tolist() == pytest.approx(
        [40e3, 40e3, 30e3, 20e3]
    )
    # 0.9 → 1.0 at the last point's 20 kW: 0.1 · 40 kWh / (0.9 · 20 kW) = 800 s.
    assert curve.time_s(0.9, 1.0) == pytest.approx(800.0, rel=1e-9)


def test_a_colder_day_has_less_to_fill():
    full = charge_curve(BATTERY, 22_000.0)
    derated = charge_curve(BATTERY, 22_000.0, usable_share=0.9)
    assert derated.time_s(0.2, 0.8) == pytest.approx(0.9 * full.time_s(0.2, 0.8), rel=1e-9)


@pytest.mark.parametrize(
    ("curve", "where"),
    [
        ([{"soc": 0.0, "power_kw": 20}, {"soc": 0.8, "power_kw": 30}], "[1].power_kw"),
        ([{"soc": 0.5, "power_kw": 20}, {"soc": 0.5, "power_kw": 10}], "[1].soc"),
        ([{"soc": 0.0, "power_kw": 20}, {"soc": 1.2, "power_kw": 10}], "[1].soc"),
        ([{"soc": 0.0, "power_kw": 0}, {"soc": 1.0, "power_kw": 5}], "[0].power_kw"),
        ([{"soc": 0.0, "power_kw": 20}], ""),
    ],
)
def test_a_curve_that_rises_or_leaves_0_to_1_is_refused_naming_the_point(curve, where):
    with pytest.raises(InvalidParameterError) as raised:
        BatteryParams(charging_curve=curve)
    assert raised.value.field == f"charging_curve{where}"


def test_a_plugged_in_spell_charges_along_the_curve_while_the_consumers_run_from_the_grid():
    van = VanParams(battery=BatteryParams(usable_capacity_kwh=40.0, initial_soc=0.5))
    start = dt.datetime(2026, 7, 15, 12, 0, tzinfo=ZoneInfo("Europe/Vienna"))
    spell = ChargingSpell(start_s=600.0, duration_s=1800.0, power_kw=22.0)
    hot = Weather(t_min_c=20, t_max_c=31)
    parked = [Interval(start_s=0.0, duration_s=3600.0)]
    plugged = simulate(
        np.zeros(3601), 1.0, start, VIENNA, van, hot, Along(parked=parked, charging=[spell])
    )
    unplugged = simulate(np.zeros(3601), 1.0, start, VIENNA, van, hot, Along(parked=parked))
    load_j = sum(unplugged.power_w.values())  # the same consumers either way
    assert sum(plugged.power_w.values()) == pytest.approx(load_j)
    capacity_j = 40 * KWH
    before = 0.5 - load_j[:600].sum() / capacity_j
    # 1800 s at 22 kW, 90 % stored: 9.9 kWh, all below 80 % (no taper): +0.2475.
    after = before + 0.9 * 22e3 * 1800 / capacity_j
    charge = plugged.charges[0]
    assert charge.soc_before == pytest.approx(before, rel=1e-9)
    assert charge.soc_after == pytest.approx(after, rel=1e-9)
    assert charge.stored_j == pytest.approx(9.9 * KWH, rel=1e-9)
    assert charge.charge_grid_j == pytest.approx(11.0 * KWH, rel=1e-9)
    assert charge.consumers_grid_j == pytest.approx(load_j[600:2400].sum(), rel=1e-9)
    assert plugged.soc[2400] == pytest.approx(after, rel=1e-9)
    assert plugged.soc[-1] == pytest.approx(after - load_j[2400:].sum() / capacity_j, rel=1e-9)
    assert unplugged.soc[-1] == pytest.approx(0.5 - load_j.sum() / capacity_j, rel=1e-9)
    # another battery on the same day: by hand without charging, refused with charging
    larger = BatteryParams(usable_capacity_kwh=80.0, initial_soc=0.5)
    assert with_battery(unplugged, larger).soc[-1] == pytest.approx(
        0.5 - load_j.sum() / (80 * KWH), rel=1e-9
    )
    with pytest.raises(ValueError, match="charges"):
        with_battery(plugged, larger)


def test_a_long_spell_fills_the_battery_through_the_taper_and_no_further():
    van = VanParams(battery=BatteryParams(usable_capacity_kwh=40.0, initial_soc=0.7))
    start = dt.datetime(2026, 4, 15, 10, 0, tzinfo=ZoneInfo("Europe/Vienna"))
    spell = ChargingSpell(start_s=0.0, duration_s=7200.0, power_kw=150.0)
    result = simulate(np.zeros(7201), 1.0, start, VIENNA, van, along=Along(charging=[spell]))
    curve = charge_curve(van.battery, 150e3)
    full_s = curve.time_s(0.7, 1.0)
    # 0.7 → 0.8 at 50 kW: 0.1·40 kWh/(0.9·50 kW) = 320 s; 0.8 → 1.0 tapering 50 → 10 kW
    assert full_s == pytest.approx(
        320.0 + 0.2 / (10e3 - 50e3) * math.log(10 / 50) * 40 * KWH / 0.9, rel=1e-9
    )
    assert result.soc[round(full_s) + 1] == pytest.approx(1.0)
    assert result.charges[0].soc_after == pytest.approx(1.0)
    assert result.charges[0].stored_j == pytest.approx(0.3 * 40 * KWH, rel=1e-9)
