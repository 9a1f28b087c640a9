"""Chargers on the way: the summer day that runs flat on 40 kWh (tests/core/planning/
test_recharge.py) charges at a fast charger between stops instead of the depot, waits for a
charger's opening, never uses one that is closed or out of reach, prefers a fast one to a slow
one nearer, and its charge minutes follow the charging curve by hand (core/physics/charging.py).
"""

from __future__ import annotations

import datetime as dt
import math

import pytest

from core.exceptions import InvalidMatrixError, InvalidStopsError
from core.params import Charger, RoadMatrix
from core.planning.day.recharge import PARTIAL_CHARGE_MARGIN
from core.planning.model import PlanProblem, PlanResult, StartState
from core.planning.round.planner import plan
from tests.core.planning.day.test_recharge import stretch_lows, summer_day

KWH = 3.6e6
#: A 150 kW charger 2.3 km east of the depot (Prater), and an 11 kW one beside the depot.
FAST = {"id": "hpc-prater", "lat": 48.215, "lon": 16.40, "power_kw": 150, "price_per_kwh": 0.59}
SLOW = {"id": "ac-slow", "lat": 48.212, "lon": 16.372, "power_kw": 11}


def with_chargers(*chargers: dict[str, object], problem: PlanProblem | None = None) -> PlanProblem:
    problem = problem or summer_day(None)
    return problem.model_copy(update={"chargers": [Charger(**c) for c in chargers]})  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def flat() -> PlanResult:
    return plan(summer_day(None))


@pytest.fixture(scope="module")
def fast() -> PlanResult:
    return plan(with_chargers(FAST))


def charge_start(result: PlanResult, k: int, plug_s: float = 120.0) -> dt.datetime:
    """When charge k's current begins: after plugging in (half the plug minutes)."""
    charge = result.charges[k]
    return charge.depart - dt.timedelta(seconds=charge.minutes * 60 + plug_s / 2)


def test_a_charger_on_the_way_makes_the_flat_day_feasible(fast, flat):
    assert not flat.battery.feasible
    assert fast.battery.feasible and fast.battery.min_soc >= 0.1
    assert fast.charges and all(c.charger_id == "hpc-prater" for c in fast.charges)
    visits = [k for k, place in enumerate(fast.tour) if place == "hpc-prater"]
    assert len(visits) == len(fast.charges)
    # between stops, never first or last; every stop served once; no return to the depot
    assert min(visits) > 0 and max(visits) < len(fast.tour) - 1
    assert fast.tour.count("depot") == 2
    assert sorted(p for p in fast.tour if p != "hpc-prater") == sorted(flat.tour)
    assert {s.id for s in fast.stops} == {s.id for s in flat.stops}
    for k, charge in zip(visits, fast.charges, strict=True):
        assert fast.legs[k - 1].arrive == charge.arrive and fast.legs[k].depart == charge.depart
        assert (charge.lat, charge.lon) == (FAST["lat"], FAST["lon"])
        assert charge.cost == pytest.approx(0.59 * charge.grid_kwh)


def test_charge_minutes_follow_the_curve_by_hand(fast):
    # 150 kW into the van's 50 kW: the default curve, 50 kW up to 80 %, then linearly to
    # 10 kW at full, P(s) = 50 kW − 200 kW·(s − 0.8); η = 0.9 on the aged usable capacity C:
    # t = C/η·[(min(s₁, 0.8) − s₀)/50 kW + ln(P(0.8)/P(s₁))/200 kW].
    capacity_j = fast.battery.usable_capacity_kwh * KWH
    for charge in fast.charges:
        s0, s1 = charge.soc_before, charge.soc_after
        assert charge.battery_kwh == pytest.approx((s1 - s0) * capacity_j / KWH, rel=1e-6)
        flat_s = (min(s1, 0.8) - s0) * capacity_j / (0.9 * 50e3)
        taper_s = math.log(50e3 / (50e3 - 200e3 * max(s1 - 0.8, 0.0))) / 200e3 * capacity_j / 0.9
        assert charge.minutes * 60 == pytest.approx(flat_s + taper_s, abs=1.0)
        # plugged in and out besides (2 min by default), the cab and box from the grid
        assert (charge.depart - charge.arrive).total_seconds() == pytest.approx(
            charge.minutes * 60 + 120, abs=2
        )
        assert charge.grid_kwh > charge.battery_kwh / 0.9
    # partial: each stretch after a charge ends its lowest near the reserve plus the margin
    for low, after in stretch_lows(fast):
        assert 0.1 <= low <= 0.1 + PARTIAL_CHARGE_MARGIN + 0.01 or after >= 0.99


def test_a_charger_that_opens_later_is_waited_for():
    opens = {"opening_hours": [{"start": "13:00", "end": "22:00"}]}
    result = plan(with_chargers(FAST | opens))
    assert result.battery.feasible and result.charges
    one_pm = dt.datetime(2026, 7, 15, 13, 0, tzinfo=result.charges[0].arrive.tzinfo)
    for k, charge in enumerate(result.charges):
        assert charge_start(result, k) >= one_pm - dt.timedelta(seconds=1)
        assert charge.depart.time() <= dt.time(22, 0)
    # the first comes before the opening and waits, parked: the wait draws on the battery
    first = result.charges[0]
    assert first.arrive < one_pm
    arrived = next(leg for leg in result.legs if leg.arrive == first.arrive)
    assert first.soc_before < arrived.soc_end


def test_a_charger_closed_all_day_or_out_of_reach_is_never_visited(flat):
    closed = {"opening_hours": [{"start": "05:00", "end": "06:00"}]}  # before the 07:00 start
    far = {"id": "far", "lat": 50.0, "lon": 16.37, "power_kw": 150}  # 200 km north
    result = plan(with_chargers(FAST | closed, far))
    assert result.charges == [] and sorted(result.tour) == sorted(flat.tour)
    assert result.distance_m == pytest.approx(flat.distance_m, rel=0.01)
    assert not result.battery.feasible
    assert any("no charger within reach" in w for w in result.warnings)


def test_a_charger_closing_before_the_charge_is_done_is_not_chosen():
    # open only 09:00–09:40: too short for what the day needs at the only charger there
    result = plan(with_chargers(FAST | {"opening_hours": [{"start": "09:00", "end": "09:40"}]}))
    for charge in result.charges:
        assert dt.time(9, 0) <= charge.arrive.time() and charge.depart.time() <= dt.time(9, 40)


def test_a_fast_charger_a_little_farther_wins_over_a_slow_one_nearer(fast):
    both = plan(with_chargers(SLOW, FAST))
    slow = plan(with_chargers(SLOW))
    assert both.battery.feasible and slow.battery.feasible
    assert {c.charger_id for c in both.charges} == {"hpc-prater"}
    assert {c.charger_id for c in slow.charges} == {"ac-slow"}
    minutes = sum(c.minutes for c in both.charges)
    assert minutes < sum(c.minutes for c in slow.charges)
    assert both.duration_s < slow.duration_s


def test_a_van_under_way_with_little_charge_charges_before_it_runs_out():
    morning = summer_day(None)
    state = StartState(
        lat=48.25, lon=16.42, time=dt.datetime.fromisoformat("2026-07-15T12:00:00+02:00"), soc=0.2
    )
    under_way = morning.model_copy(update={"stops": morning.stops[:20], "start_state": state})
    without = plan(under_way)
    assert not without.battery.feasible
    result = plan(with_chargers(FAST, problem=under_way))
    assert result.battery.feasible and result.tour[0] == "start"
    assert result.charges and result.charges[0].soc_before >= 0.1
    assert result.charges[0].arrive < without.legs[without.first_infeasible_leg or 0].arrive


def test_charger_ids_are_their_own_and_a_matrix_needs_rows_for_them():
    stop_id = summer_day(None).stops[0].id
    with pytest.raises(InvalidStopsError) as caught:
        plan(with_chargers(FAST | {"id": stop_id}))
    assert caught.value.field == "chargers[0].id" and "used twice" in caught.value.message
    with pytest.raises(InvalidStopsError) as caught:
        plan(with_chargers(FAST, FAST))
    assert caught.value.field == "chargers[1].id"
    with pytest.raises(InvalidStopsError) as caught:
        plan(
            with_chargers(
                FAST | {"id": "depot"},
                problem=summer_day(None).model_copy(
                    update={"depot": summer_day(None).depot.model_copy(update={"id": "hub"})}
                ),
            )
        )
    assert caught.value.field == "chargers[0].id" and "depot's charger" in caught.value.message
    problem = with_chargers(FAST)
    n = len(problem.stops) + 1
    matrix = RoadMatrix(distances_m=[[0.0] * n] * n, durations_s=[[0.0] * n] * n)
    with pytest.raises(InvalidMatrixError) as caught:  # no row for the charger
        plan(problem.model_copy(update={"matrix": matrix}))
    assert caught.value.field == "matrix.distances_m" and "chargers" in caught.value.message
