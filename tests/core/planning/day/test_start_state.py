"""The rest of a day planned again from where the van is: from its position, time, charge,
box temperature, payload and driving since its last break, through the stops left, to the
depot."""

from __future__ import annotations

import datetime as dt
from zoneinfo import ZoneInfo

import pytest

from core.exceptions import InvalidParameterError
from core.params import RoadMatrix, TimeWindow
from core.planning.fleet.planner import plan_fleet
from core.planning.model import (
    START_ID,
    FleetProblem,
    FleetVehicle,
    RoundFields,
    StartState,
    fields_of,
)
from core.planning.round.planner import plan
from tests.core.planning.day.test_recharge import summer_day

VIENNA = ZoneInfo("Europe/Vienna")


@pytest.fixture(scope="module")
def morning():
    """A 20-stop day on a battery that lasts, planned from the depot at 07:00."""
    problem = summer_day(None)
    return problem.model_copy(update={"stops": problem.stops[:20]})


@pytest.fixture(scope="module")
def planned(morning):
    return plan(morning)


def at_noon(morning, planned, **state):
    """The round from where the planned van is after its 8th stop, with the stops left."""
    done = planned.stops[7]
    left = {s.id for s in planned.stops[8:]}
    fields = {
        "lat": done.lat,
        "lon": done.lon,
        "time": done.departure,
        "soc": done.soc_departure,
        "payload_kg": done.payload_after_kg,
    } | state
    return morning.model_copy(
        update={
            "stops": [s for s in morning.stops if s.id in left],
            "start_state": StartState(**fields),
        }
    )


def test_the_rest_of_the_day_leaves_from_the_van_and_ends_at_the_depot(morning, planned):
    rest = plan(at_noon(morning, planned))
    done = planned.stops[7]
    assert rest.tour[0] == START_ID and rest.tour[-1] == morning.depot.id
    assert sorted(rest.tour[1:-1]) == sorted(s.id for s in planned.stops[8:])
    assert rest.legs[0].depart == done.departure
    assert rest.legs[0].soc_start == pytest.approx(done.soc_departure)
    assert rest.stops[0].payload_after_kg == pytest.approx(
        done.payload_after_kg - next(s for s in morning.stops if s.id == rest.tour[1]).delivery_kg
    )
    assert rest.grid_kwh == 0.0  # under way: nothing is pre-conditioned
    # The original order from there on is one of the paths the search considers: the rest is
    # never longer (estimated metres, the objective).
    remaining_m = sum(leg.distance_m for leg in planned.legs[8:])
    assert rest.solved.objective_value <= remaining_m * 1.005


def test_a_warm_box_costs_the_refrigeration_more_than_one_at_its_set_point(morning, planned):
    cold = plan(at_noon(morning, planned))
    warm = plan(at_noon(morning, planned, box_temperature_c=9.0))
    assert warm.tour == cold.tour
    assert warm.legs[0].energy_kwh["refrigeration"] > cold.legs[0].energy_kwh["refrigeration"]


def test_the_driving_since_the_last_break_counts_toward_the_eu_limit(morning, planned):
    state = at_noon(morning, planned, driving_since_break_s=4 * 3600 + 25 * 60)
    rest = plan(state.model_copy(update={"breaks": "eu-561"}))
    assert rest.breaks and rest.breaks[0].kind == "eu-561"
    driven_before_s = sum(leg.duration_s for leg in rest.legs if leg.depart < rest.breaks[0].end)
    assert driven_before_s <= 5 * 60  # at most the 5 min left of the 4 h 30


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"soc": 0.105}, "start_state.soc"),  # within 0.01 of the reserve 0.1
        ({"time": dt.datetime(2026, 7, 16, 12, 0, tzinfo=dt.UTC)}, "start_state.time"),
        ({"payload_kg": 1.0}, "start_state.payload_kg"),
    ],
)
def test_a_start_state_that_cannot_be_planned_is_refused_naming_the_field(
    morning, planned, change, field
):
    with pytest.raises(InvalidParameterError) as raised:
        plan(at_noon(morning, planned, **change))
    assert raised.value.field == field


def test_a_round_under_way_keeps_its_windows(morning, planned):
    """The fleet search with this one van from its position: the stop that wants 14:00–15:00
    is served then, the others around it."""
    state = at_noon(morning, planned)
    window = TimeWindow(start="14:00", end="15:00")
    stops = [state.stops[0].model_copy(update={"time_windows": [window]}), *state.stops[1:]]
    rest = plan(state.model_copy(update={"stops": stops, "time_limit_s": 3.0}))
    assert rest.tour[0] == START_ID and rest.tour[-1] == morning.depot.id
    assert sorted(rest.tour[1:-1]) == sorted(s.id for s in stops)
    assert rest.legs[0].depart == state.start_state.time  # it waits where the window is
    assert rest.legs[0].soc_start == pytest.approx(state.start_state.soc)
    served = next(s for s in rest.stops if s.id == stops[0].id).service_start.time()
    assert window.start <= served <= window.end
    assert rest.late_stops == []


def test_a_start_state_with_a_client_matrix_is_refused(morning, planned):
    state = at_noon(morning, planned)
    n = len(state.stops) + 1
    off = [[0.0 if i == j else 1000.0 for j in range(n)] for i in range(n)]
    matrix = RoadMatrix(distances_m=off, durations_s=[[v / 10 for v in row] for row in off])
    with pytest.raises(InvalidParameterError) as raised:
        plan(state.model_copy(update={"matrix": matrix}))
    assert raised.value.field == "start_state"


# --- fleets: each van from where it is ---------------------------------------------------


def fleet_morning(**fields) -> FleetProblem:
    """The summer day's first 30 stops at 15 kg (450 kg: two vans) for two 60 kWh vans of
    400 kg, 07:00–19:00, the first five stops wanting the afternoon."""
    day = summer_day(None)
    afternoon = [TimeWindow(start="13:00", end="18:00")]
    stops = [
        s.model_copy(update={"time_windows": afternoon if k < 5 else [], "delivery_kg": 15.0})
        for k, s in enumerate(day.stops[:30])
    ]
    battery = day.van.battery.model_copy(update={"usable_capacity_kwh": 60.0})
    van = day.van.model_copy(update={"battery": battery})
    vans = [
        FleetVehicle(id=f"van-{k}", shift_start="07:00", shift_end="19:00", van=van)
        for k in range(2)
    ]
    return FleetProblem(
        **fields_of(day, RoundFields) | {"stops": stops} | fields,
        vehicles=vans,
        time_limit_s=40.0,  # the work, not a busy machine's clock, ends the search
        work_s=0.4,
    )


def state_after(route, k: int) -> StartState:
    done = route.plan.stops[k]
    return StartState(
        lat=done.lat,
        lon=done.lon,
        time=done.departure,
        soc=done.soc_departure,
        payload_kg=done.payload_after_kg,
    )


@pytest.fixture(scope="module")
def fleet_at_noon():
    """The morning's fleet plan, and the rest of it planned again from where each van is
    after its 4th stop, with one stop more that came in meanwhile."""
    morning = fleet_morning()
    planned = plan_fleet(morning)
    assert len(planned.routes) == 2 and planned.unassigned == []
    by_id = {route.vehicle_id: route for route in planned.routes}
    done = {s.id for route in planned.routes for s in route.plan.stops[:4]}
    extra = summer_day(None).stops[35].model_copy(update={"id": "late-order"})
    left = [s for s in morning.stops if s.id not in done] + [extra]
    vans = [
        v.model_copy(update={"start_state": state_after(by_id[v.id], 3)}) for v in morning.vehicles
    ]
    rest = morning.model_copy(update={"stops": left, "vehicles": vans})
    return rest, plan_fleet(rest)


def test_a_fleet_plans_the_rest_of_the_day_from_where_each_van_is(fleet_at_noon):
    rest, replanned = fleet_at_noon
    assert replanned.unassigned == []
    served = sorted(s.id for route in replanned.routes for s in route.plan.stops)
    assert served == sorted(s.id for s in rest.stops)
    for route in replanned.routes:
        state = next(v for v in rest.vehicles if v.id == route.vehicle_id).start_state
        plan_ = route.plan
        assert plan_.tour[0] == START_ID and plan_.tour[-1] == rest.depot.id
        assert plan_.legs[0].depart == state.time
        assert plan_.legs[0].soc_start == pytest.approx(state.soc)
        if plan_.stops:  # a van left with nothing to do drives home
            first = next(s for s in rest.stops if s.id == plan_.tour[1])
            assert plan_.stops[0].payload_after_kg == pytest.approx(
                state.payload_kg - first.delivery_kg
            )
        assert plan_.battery.feasible and plan_.late_stops == []
        assert plan_.legs[-1].arrive.time() <= dt.time(19, 0)
        # the afternoon windows still hold
        for stop in plan_.stops:
            wanted = next(s for s in rest.stops if s.id == stop.id).time_windows
            for window in wanted:
                assert window.start <= stop.service_start.time() <= window.end


def test_a_van_under_way_carries_on_its_first_trip_what_it_has_aboard():
    """50 kg aboard, the stops left 25 kg each: two stops, then back to reload."""
    day = summer_day(None)
    stops = [s.model_copy(update={"delivery_kg": 25.0}) for s in day.stops[:8]]
    state = StartState(
        lat=48.25,
        lon=16.40,
        time=dt.datetime(2026, 7, 15, 12, 0, tzinfo=VIENNA),
        soc=0.95,
        payload_kg=50,
    )
    van = FleetVehicle(
        id="van",
        shift_start="07:00",
        shift_end="20:00",
        max_trips=3,
        start_state=state,
        van=fleet_morning().vehicles[0].van,  # 60 kWh
    )
    problem = FleetProblem(
        **fields_of(day, RoundFields) | {"stops": stops},
        vehicles=[van],
        time_limit_s=30.0,
        work_s=0.3,
    )
    (route,) = plan_fleet(problem).routes
    first_return = route.plan.tour.index(day.depot.id)
    assert first_return <= 3  # start, at most two stops, the depot
    assert route.plan.reloads and len(route.plan.stops) == 8
    payloads = [stop.payload_after_kg for stop in route.plan.stops]
    assert payloads[: first_return - 1] == [50 - 25 * (k + 1) for k in range(first_return - 1)]
    assert payloads[first_return - 1] == 400 - 25  # reloaded


@pytest.mark.parametrize(
    ("state", "field"),
    [
        ({"time": dt.datetime(2026, 7, 15, 6, 0, tzinfo=VIENNA)}, "time"),
        ({"time": dt.datetime(2026, 7, 15, 19, 30, tzinfo=VIENNA)}, "time"),
        ({"time": dt.datetime(2026, 7, 16, 12, 0, tzinfo=VIENNA)}, "time"),
        ({"soc": 0.105}, "soc"),
        ({"payload_kg": 401}, "payload_kg"),
    ],
)
def test_a_start_state_a_fleet_cannot_plan_from_names_the_van(state, field):
    fields = {
        "lat": 48.25,
        "lon": 16.40,
        "time": dt.datetime(2026, 7, 15, 12, 0, tzinfo=VIENNA),
        "soc": 0.6,
    } | state
    problem = fleet_morning()
    vans = [
        problem.vehicles[0],
        problem.vehicles[1].model_copy(update={"start_state": StartState(**fields)}),
    ]
    with pytest.raises(InvalidParameterError) as caught:
        plan_fleet(problem.model_copy(update={"vehicles": vans}))
    assert caught.value.field == f"vehicles[1].start_state.{field}"
