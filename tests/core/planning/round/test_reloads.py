"""Several trips: the summer day's 40 stops (tests/core/planning/day/test_recharge.py) at 20 kg
each take 800 kg on a 400 kg van — two trips with a reload at the depot between — and the
payloads, the reload's minutes and what a client may get wrong, by hand."""

from __future__ import annotations

import datetime as dt
import itertools

import pytest

from core.exceptions import InvalidParameterError, InvalidStopsError
from core.params import ChargePoint, TimeWindow
from core.planning.fleet.planner import plan_fleet
from core.planning.model import FleetProblem, FleetVehicle, RoundFields, default_work_s, fields_of
from core.planning.round.planner import plan
from tests.core.planning.day.test_recharge import summer_day


def heavy(**fields):
    day = summer_day(None)
    stops = [stop.model_copy(update={"delivery_kg": 20.0}) for stop in day.stops]
    return day.model_copy(update={"stops": stops, **fields})


@pytest.fixture(scope="module")
def two_trips():
    return plan(heavy(max_trips=3, reload_minutes=20))


def test_a_round_heavier_than_the_van_comes_back_to_reload(two_trips):
    result = two_trips
    assert result.tour.count("depot") == 3  # out, back to reload, out again, home
    (reload,) = result.reloads
    back = result.tour.index("depot", 1)
    assert result.legs[back - 1].arrive == reload.arrive
    assert result.legs[back].depart == reload.depart
    # 20 minutes parked at the depot, and the van leaves with its payload again
    assert (reload.depart - reload.arrive).total_seconds() == pytest.approx(20 * 60, abs=1)
    assert reload.payload_kg == 400
    # 400 kg is 20 stops: the first trip unloads to 0, the second starts again from 400
    payloads = [stop.payload_after_kg for stop in result.stops]
    assert payloads[:20] == [400 - 20 * (k + 1) for k in range(20)]
    assert payloads[20:] == [400 - 20 * (k + 1) for k in range(20)]
    assert sorted(s.id for s in result.stops) == sorted(s.id for s in heavy().stops)


def test_the_reload_is_parked_time_the_cab_and_box_draw_on(two_trips):
    one = plan(heavy(max_trips=3, reload_minutes=0))
    assert two_trips.duration_s == pytest.approx(one.duration_s + 20 * 60, abs=60)
    assert two_trips.energy_kwh["refrigeration"] > one.energy_kwh["refrigeration"]


def test_what_the_trips_cannot_carry_is_refused_naming_the_field():
    with pytest.raises(InvalidStopsError) as caught:
        plan(heavy())  # max_trips 1: 800 kg on 400
    assert caught.value.field == "stops" and "max_trips" in caught.value.message
    with pytest.raises(InvalidStopsError) as caught:
        plan(
            heavy(max_trips=2).model_copy(
                update={"van": heavy().van.model_copy(update={"payload_kg": 300})}
            )
        )
    assert caught.value.field == "stops" and "2 trips" in caught.value.message
    day = heavy(max_trips=5)
    stops = [*day.stops[:-1], day.stops[-1].model_copy(update={"delivery_kg": 450.0})]
    with pytest.raises(InvalidStopsError) as caught:
        plan(day.model_copy(update={"stops": stops}))
    assert caught.value.field == "stops[39].delivery_kg"


@pytest.mark.slow
def test_a_round_with_time_windows_comes_back_to_reload():
    """Windows and reloads together (they were a 422): the fleet search with this one van
    places the returns; the windowed stop is served inside its window, no trip carries more
    than the 400 kg payload."""
    day = heavy(max_trips=3, reload_minutes=20)
    window = TimeWindow(start=dt.time(11), end=dt.time(12))
    stops = [day.stops[0].model_copy(update={"time_windows": [window]}), *day.stops[1:20]]
    stops = [stop.model_copy(update={"delivery_kg": 40.0}) for stop in stops]  # 800 kg
    result = plan(day.model_copy(update={"stops": stops}))
    assert sorted(s.id for s in result.stops) == sorted(s.id for s in stops)
    assert len(result.reloads) >= 1
    served = next(s for s in result.stops if s.id == stops[0].id)
    assert dt.time(11) <= served.service_start.time() <= dt.time(12)
    payloads = [stop.payload_after_kg for stop in result.stops]
    assert min(payloads) >= 0 and max(payloads) <= 400 - 40
    # each trip starts again from the full payload: a reload per rise of the payload
    rises = sum(b > a for a, b in itertools.pairwise(payloads))
    assert rises == len(result.reloads)


@pytest.mark.parametrize(
    ("fields", "field"),
    [
        ({"max_trips": 0}, "max_trips"),
        ({"max_trips": 21}, "max_trips"),
        ({"reload_minutes": -1}, "reload_minutes"),
        ({"reload_minutes": 241}, "reload_minutes"),
    ],
)
def test_bad_trips_are_refused(fields, field):
    with pytest.raises(InvalidParameterError) as caught:
        type(heavy())(**(heavy().model_dump() | fields))
    assert caught.value.field == field


def fleet_of_trips(max_trips: int, charger=None, capacity_kwh: float = 40.0) -> FleetProblem:
    """30 of the summer day's stops at 25 kg (750 kg) for one 400 kg van of the fleet."""
    day = summer_day(charger)
    stops = [stop.model_copy(update={"delivery_kg": 25.0}) for stop in day.stops[:30]]
    battery = day.van.battery.model_copy(update={"usable_capacity_kwh": capacity_kwh})
    van = day.van.model_copy(update={"battery": battery})
    vehicle = FleetVehicle(
        id="van",
        shift_start="07:00",
        shift_end="20:00",
        max_trips=max_trips,
        reload_minutes=20,
        van=van,
    )
    # a default request's work (30 stops: a 1.8 s limit) with the time to do it: a busy
    # machine's clock once cut it into another day, its charge no longer at the reload
    return FleetProblem(
        **fields_of(day, RoundFields) | {"stops": stops},
        vehicles=[vehicle],
        time_limit_s=60,
        work_s=default_work_s(1.8),
    )


def trip_loads(result) -> list[float]:
    """What each trip delivers, by the stops between the depot visits that reload."""
    reloaded = {reload.arrive for reload in result.reloads}
    delivered = {stop.id: 25.0 for stop in result.stops}
    loads = [0.0]
    for leg in result.legs[:-1]:
        if leg.to_id == "depot" and leg.arrive in reloaded:
            loads.append(0.0)
        loads[-1] += delivered.get(leg.to_id, 0.0)
    return loads


def test_a_fleet_van_comes_back_to_reload_when_its_trips_allow():
    one = plan_fleet(fleet_of_trips(1, capacity_kwh=90.0))
    # one trip: 16 stops are 400 kg, the other 14 stay for capacity
    assert sorted(u.reason for u in one.unassigned) == ["capacity"] * 14
    two = plan_fleet(fleet_of_trips(2, capacity_kwh=90.0))
    assert two.unassigned == []
    (route,) = two.routes
    (reload,) = route.plan.reloads
    assert (reload.depart - reload.arrive).total_seconds() == pytest.approx(20 * 60, abs=1)
    loads = trip_loads(route.plan)
    assert len(loads) == 2 and sum(loads) == 750 and max(loads) <= 400
    # the second trip leaves with 400 kg again
    first_after = route.plan.tour[route.plan.tour.index("depot", 1) + 1]
    after = next(s for s in route.plan.stops if s.id == first_after)
    assert after.payload_after_kg == 400 - 25
    assert route.plan.battery.feasible


def test_a_fleet_van_charges_at_the_depot_while_it_reloads():
    """On 40 kWh the day takes more than the battery: with the depot's 22 kW charger the
    van charges while it reloads, one stop at the depot for both."""
    flat = plan_fleet(fleet_of_trips(2))
    assert any(u.reason == "battery" for u in flat.unassigned)
    charged = plan_fleet(fleet_of_trips(2, ChargePoint(power_kw=22.0)))
    assert charged.unassigned == []
    (route,) = charged.routes
    plan_ = route.plan
    assert plan_.battery.feasible and plan_.battery.min_soc >= 0.1
    (reload,) = plan_.reloads
    both = next(c for c in plan_.charges if c.arrive == reload.arrive)
    assert both.depart == reload.depart
    standing_s = (both.depart - both.arrive).total_seconds()
    assert standing_s >= max(20 * 60, both.minutes * 60 + 120) - 1
    assert max(trip_loads(plan_)) <= 400
