"""A route's rules as its simulation says: each failure found on a simulated day."""

from __future__ import annotations

from core.params import BatteryParams
from core.planning.day.verify import route_failure
from tests.utils.fleets import at, day_of, fleet, two_clusters, van, window


def failure_of(problem, route, battery_enforced=True):
    day = day_of(problem)
    shift = day.shifts[0]
    result = day.simulate(0, route)
    return route_failure(
        shift.id, shift.problem, day.scene.places, result, shift.end, battery_enforced
    )


def test_a_route_that_holds():
    stops, matrix = two_clusters()
    assert failure_of(fleet(stops, [van("a")], matrix=matrix), [1, 2, 3]) is None


def test_a_stop_reached_after_its_window_names_the_stop():
    stops, matrix = two_clusters()
    stops[2] = stops[2].model_copy(update={"time_windows": [window("08:00", "08:20")]})
    # E1 08:10–08:15, E2 08:17–08:22, E3 at 08:24: after 08:20.
    failure = failure_of(fleet(stops, [van("a")], matrix=matrix), [1, 2, 3])
    assert failure is not None and (failure.reason, failure.node) == ("time_window", 3)


def test_back_after_the_shift_names_the_time():
    stops, matrix = two_clusters()
    failure = failure_of(fleet(stops, [van("a", "08:00", "08:30")], matrix=matrix), [1, 2, 3])
    assert failure is not None and failure.reason == "shift" and failure.node is None
    assert "08:39" in failure.detail and "08:30" in failure.detail
    assert at("08:39").strftime("%H:%M") in failure.detail


def test_below_the_reserve_only_where_the_battery_is_a_rule():
    stops, matrix = two_clusters()
    small = BatteryParams(usable_capacity_kwh=1.0, min_soc=0.15)
    problem = fleet(stops, [van("a", battery=small)], matrix=matrix)
    failure = failure_of(problem, [1, 2, 3, 4, 5, 6])
    assert failure is not None and failure.reason == "battery" and "15%" in failure.detail
    assert failure_of(problem, [1, 2, 3, 4, 5, 6], battery_enforced=False) is None
