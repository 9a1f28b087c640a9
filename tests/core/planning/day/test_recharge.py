"""Rounds that come back to the depot to charge: the summer day that runs flat on 40 kWh
becomes feasible with a 22 kW charger, the charge fits what the rest of the day needs, and
its minutes follow the charging curve by hand (core/physics/charging.py)."""

from __future__ import annotations

import datetime as dt
import math

import numpy as np
import pytest

from core.params import PRESETS, BatteryParams, ChargePoint, Depot, Stop, TimeWindow, Weather
from core.planning.day.recharge import PARTIAL_CHARGE_MARGIN
from core.planning.model import PlanProblem, PlanResult
from core.planning.round.planner import plan

KWH = 3.6e6


def summer_day(charger: ChargePoint | None, **battery: object) -> PlanProblem:
    """40 stops within 15 km of central Vienna (10 min each, 3 min door), the paper's van with
    40 kWh, 31 °C: about 60 kWh in the day."""
    rng = np.random.default_rng(3)
    angle = rng.uniform(0, 2 * np.pi, 40)
    radius_m = 15_000 * np.sqrt(rng.uniform(0.2, 1, 40))
    van = (
        PRESETS["paper-generic"]
        .van()
        .model_copy(
            update={
                "battery": BatteryParams(usable_capacity_kwh=40.0, **battery),  # type: ignore[arg-type]
                "payload_kg": 400,
            }
        )
    )
    return PlanProblem(
        date=dt.date(2026, 7, 15),
        timezone="Europe/Vienna",
        start_time="07:00",
        depot=Depot(id="depot", lat=48.21, lon=16.37, charger=charger),
        stops=[
            Stop(
                id=f"S{k}",
                lat=48.21 + radius_m[k] * np.sin(angle[k]) / 111e3,
                lon=16.37 + radius_m[k] * np.cos(angle[k]) / 74e3,
                service_time_s=600,
                door_open_s=180,
                delivery_kg=8,
            )
            for k in range(40)
        ],
        weather=Weather(t_min_c=21, t_max_c=31),
        van=van,
        time_limit_s=30.0,  # the search ends long before: the same order on a loaded machine
        work_s=3.0,
    )


def stretch_lows(result: PlanResult) -> list[tuple[float, float]]:
    """The lowest state of charge after each charge until the next (or the end), with the
    charge's soc_after."""
    starts = [
        k for k, leg in enumerate(result.legs) if leg.depart in {c.depart for c in result.charges}
    ]
    out = []
    for n, (k, charge) in enumerate(zip(starts, result.charges, strict=True)):
        end = starts[n + 1] if n + 1 < len(starts) else len(result.legs)
        legs = result.legs[k:end]
        out.append((min(min(leg.soc_start, leg.soc_end) for leg in legs), charge.soc_after))
    return out


@pytest.fixture(scope="module")
def flat():
    return plan(summer_day(None))


@pytest.fixture(scope="module")
def charged():
    return plan(summer_day(ChargePoint(power_kw=22.0, price_per_kwh=0.3)))


def test_the_day_runs_flat_without_a_charger(flat):
    assert not flat.battery.feasible
    assert flat.charges == []
    assert flat.tour.count("depot") == 2


def test_a_22_kw_depot_charger_makes_it_feasible_with_a_mid_day_charge(charged, flat):
    assert charged.battery.feasible
    assert charged.battery.min_soc >= 0.1
    assert len(charged.charges) >= 1
    returns = [k for k, place in enumerate(charged.tour) if place == "depot"][1:-1]
    assert len(returns) == len(charged.charges)
    assert sorted(charged.tour) == sorted([*flat.tour, *["depot"] * len(returns)])
    for k, charge in zip(returns, charged.charges, strict=True):
        # the return leg arrives when the charge's visit begins, the next leg leaves after it
        assert charged.legs[k - 1].arrive == charge.arrive
        assert charged.legs[k].depart == charge.depart
        assert charged.legs[k - 1].soc_end == pytest.approx(charge.soc_before, abs=1e-3)
        # (the minute to unplug runs on the battery)
        assert charged.legs[k].soc_start == pytest.approx(charge.soc_after, abs=2e-3)
    # the cab and the refrigeration kept running: the day's energy includes the standing
    assert charged.duration_s > flat.duration_s + sum(c.minutes for c in charged.charges) * 60


def test_the_charge_is_what_the_rest_needs_and_its_minutes_follow_the_curve(charged):
    charge = charged.charges[-1]
    capacity_kwh = charged.battery.usable_capacity_kwh
    assert charge.battery_kwh == pytest.approx(
        (charge.soc_after - charge.soc_before) * capacity_kwh, rel=1e-6
    )
    # Partial: each charge gives what the stretch after it needs — it ends its lowest near the
    # reserve plus the margin, not far above it — unless that takes a full battery.
    assert charge.soc_after < 0.99
    for low, after in stretch_lows(charged):
        assert 0.1 <= low <= 0.1 + PARTIAL_CHARGE_MARGIN + 0.01 or after >= 0.99
    # 22 kW into a 50 kW van: flat 22 kW up to 94 % (the default curve's taper, 50 kW at 80 %
    # to 10 kW at full, crosses 22 kW there), then P(s) = 22 kW − 200 kW·(s − 0.94):
    # t = C/η·[(0.94 − s₀)/22 kW + ln(P(0.94)/P(s₁))/200 kW], to the second.
    capacity_j = capacity_kwh * KWH
    s0, s1 = charge.soc_before, charge.soc_after
    flat_s = (min(s1, 0.94) - s0) * capacity_j / (0.9 * 22e3)
    taper_s = math.log(22e3 / (22e3 - 200e3 * max(s1 - 0.94, 0))) / 200e3 * capacity_j / 0.9
    assert charge.minutes * 60 == pytest.approx(flat_s + taper_s, abs=1.0)
    # the grid gives the stored energy / 0.9 and the consumers' while plugged in, at 0.30/kWh
    assert charge.grid_kwh > charge.battery_kwh / 0.9
    assert charge.cost == pytest.approx(0.3 * charge.grid_kwh)
    last_return = max(k for k, place in enumerate(charged.tour[:-1]) if place == "depot")
    depart = charged.legs[last_return].depart
    assert (depart - charge.arrive).total_seconds() == pytest.approx(
        charge.minutes * 60 + 120, abs=2
    )


def test_charge_to_full_fills_through_the_taper():
    result = plan(summer_day(ChargePoint(power_kw=22.0), charge_to_full=True))
    assert result.battery.feasible
    charge = result.charges[0]
    assert charge.soc_after == pytest.approx(1.0, abs=1e-3)
    # from soc_before to 94 % at 22 kW, then 22 → 10 kW to full (default curve, 40 kWh·share)
    capacity_j = result.battery.usable_capacity_kwh * KWH
    flat_s = (0.94 - charge.soc_before) * capacity_j / (0.9 * 22e3)
    taper_s = 0.06 / (10e3 - 22e3) * math.log(10 / 22) * capacity_j / 0.9
    # planned to full from the arrival the previous simulation saw: within a minute of it
    assert charge.minutes * 60 == pytest.approx(flat_s + taper_s, abs=60.0)


def test_a_day_the_battery_lasts_does_not_come_back():
    problem = summer_day(ChargePoint(power_kw=22.0))
    short = problem.model_copy(update={"stops": problem.stops[:12]})
    result = plan(short)
    assert result.battery.feasible
    assert result.charges == [] and result.tour.count("depot") == 2


def test_a_stop_beyond_any_charge_says_so():
    problem = summer_day(ChargePoint(power_kw=22.0))
    far = Stop(id="far", lat=48.21, lon=16.37 + 2.2, service_time_s=600, door_open_s=60)
    result = plan(problem.model_copy(update={"stops": [*problem.stops[:5], far]}))
    assert not result.battery.feasible
    assert any(
        "even with charging" in w and "no charger within reach" in w for w in result.warnings
    )


def test_each_trip_is_put_in_its_own_best_order(charged, flat):
    # The same round in the order the round trip found, kept as it is: the returns are cut
    # into it where they fall. Letting each trip find its own order is never longer.
    problem = summer_day(ChargePoint(power_kw=22.0, price_per_kwh=0.3))
    by_id = {stop.id: stop for stop in problem.stops}
    as_found = problem.model_copy(
        update={"stops": [by_id[i] for i in flat.tour[1:-1]], "keep_order": True}
    )
    kept = plan(as_found)
    assert kept.battery.feasible and len(kept.charges) == len(charged.charges)
    assert charged.distance_m <= kept.distance_m


def windowed_day(charger: ChargePoint | None) -> PlanProblem:
    """The summer day with every tenth stop wanting the morning, every tenth the afternoon."""
    day = summer_day(charger)
    morning = TimeWindow(start="07:00", end="12:00")
    afternoon = TimeWindow(start="13:00", end="21:00")
    windows = {1: [morning], 2: [afternoon]}
    stops = [
        s.model_copy(update={"time_windows": windows.get(k % 10, [])})
        for k, s in enumerate(day.stops)
    ]
    return day.model_copy(update={"stops": stops, "time_limit_s": 5.0})


@pytest.mark.slow
def test_a_round_with_time_windows_charges_where_its_windows_leave_time():
    """The order is the fleet search's (the windows first); the charges go where the forward
    slack allows them, and no window is missed."""
    assert not plan(windowed_day(None)).battery.feasible
    day = windowed_day(ChargePoint(power_kw=22.0))
    result = plan(day)
    assert result.battery.feasible and result.battery.min_soc >= 0.1
    assert result.charges and result.late_stops == []
    served = {stop.id: stop.service_start for stop in result.stops}
    for stop in day.stops:
        for window in stop.time_windows:
            assert window.start <= served[stop.id].time() <= window.end, stop.id
