"""Routes made to hold: cut by the estimates, stripped by the simulation."""

from __future__ import annotations

import numpy as np

from core.planning.day.verify import Failure
from core.planning.search.feasibility import Feasibility
from core.planning.search.repair import costliest, fitting, repair
from tests.utils.fleets import day_of, fleet, two_clusters, van


def test_fitting_drops_the_last_stops_until_the_estimates_accept_the_route():
    stops, matrix = two_clusters()
    # 08:00–08:30: E1, E2 back at 08:32 — one stop too many; E1 alone back at 08:25.
    day = day_of(fleet(stops, [van("a", "08:00", "08:30")], matrix=matrix))
    rules = Feasibility(day, np.rint(day.duration_s).astype(np.int64), [None])
    assert fitting(rules, 0, [1, 2, 3]) == [1]


def test_the_costliest_stop_is_the_detour():
    stops, matrix = two_clusters()
    day = day_of(fleet(stops, [van("a")], matrix=matrix))
    # E1, W1, E2: W1 is 30 min away from both; leaving it out saves the most energy.
    assert costliest(day.estimates[0], [1, 4, 2]) == 4


def test_repair_removes_the_named_stop_then_the_costliest_until_the_route_holds():
    stops, matrix = two_clusters()
    day = day_of(fleet(stops, [van("a")], matrix=matrix))
    checked = []

    def check(route, _result):
        checked.append(list(route))
        return None if len(route) <= 2 else Failure("battery", None, "still too long")

    repaired = repair(
        [1, 4, 2, 3],
        Failure("time_window", 3, "late"),
        lambda route: day.simulate(0, route),
        check,
        day.estimates[0],
    )
    # E3 goes for its window, then the detour W1 for the battery.
    assert repaired.route == [1, 2]
    assert [r.reason for r in repaired.removed.values()] == ["time_window", "battery"]
    assert list(repaired.removed) == [3, 4]
    assert checked == [[1, 4, 2], [1, 2]]
    assert repaired.result is not None and repaired.result.tour == ["depot", "E1", "E2", "depot"]


def test_a_route_that_loses_every_stop_has_no_simulation():
    stops, matrix = two_clusters()
    day = day_of(fleet(stops, [van("a")], matrix=matrix))
    repaired = repair(
        [1],
        Failure("shift", None, "late"),
        lambda route: day.simulate(0, route),
        lambda _r, _s: None,
        day.estimates[0],
    )
    assert repaired.route == [] and repaired.result is None and list(repaired.removed) == [1]
