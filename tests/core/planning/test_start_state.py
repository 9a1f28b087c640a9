"""The rest of a day planned again from where the van is: from its position, time, charge,
box temperature, payload and driving since its last break, through the stops left, to the
depot."""

from __future__ import annotations

import datetime as dt

import pytest

from core.exceptions import InvalidParameterError
from core.params import RoadMatrix, TimeWindow
from core.planning.model import StartState
from core.planning.round import plan
from core.planning.start_state import START_ID
from tests.core.planning.test_recharge import summer_day


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


def test_a_start_state_with_windows_or_a_client_matrix_is_refused(morning, planned):
    state = at_noon(morning, planned)
    stops = [
        state.stops[0].model_copy(
            update={"time_windows": [TimeWindow(start="14:00", end="15:00")]}
        ),
        *state.stops[1:],
    ]
    with pytest.raises(InvalidParameterError) as raised:
        plan(state.model_copy(update={"stops": stops}))
    assert raised.value.field == "start_state"
    n = len(state.stops) + 1
    off = [[0.0 if i == j else 1000.0 for j in range(n)] for i in range(n)]
    matrix = RoadMatrix(distances_m=off, durations_s=[[v / 10 for v in row] for row in off])
    with pytest.raises(InvalidParameterError) as raised:
        plan(state.model_copy(update={"matrix": matrix}))
    assert raised.value.field == "start_state"
