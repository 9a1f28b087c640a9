"""The fleet search beside its peer: Solomon's instances against PyVRP at the same budget in
the same run, and fleets from few vans to many."""

from __future__ import annotations

from collections import Counter

import pytest

from core.planning.fleet.planner import plan_fleet
from core.planning.model import FleetProblem
from testbed.fleets import pyvrp_solomon, solomon, solomon_problem, vienna_grid


def distance_units(name: str, budget_s: float, minimize: bool) -> tuple[float, int, int]:
    instance = solomon(name)
    ours = plan_fleet(solomon_problem(instance, budget_s, minimize))
    return (
        ours.distance_m / (instance.km_per_unit * 1000.0),
        ours.vehicles_used,
        len(ours.unassigned),
    )


@pytest.mark.parametrize("name", ["RC208", "C101"])
@pytest.mark.slow
def test_solomon_distance_is_on_par_with_pyvrp(name):
    # ../shared/reference/vrptw/: the bar is 2 % on any instance at the same budget
    theirs, _ = pyvrp_solomon(solomon(name), 4.0, minimize_vehicles=False)
    ours, _, unserved = distance_units(name, 4.0, minimize=False)
    assert unserved == 0
    assert ours <= theirs * 1.02


@pytest.mark.slow
def test_minimize_vehicles_uses_no_more_vans_than_pyvrp_with_a_fixed_cost_per_van():
    # R201: the best known is 4 vans (README of vrptw/); PyVRP with a large fixed cost per van
    theirs, their_vans = pyvrp_solomon(solomon("R201"), 4.0, minimize_vehicles=True)
    ours, vans, unserved = distance_units("R201", 4.0, minimize=True)
    assert unserved == 0
    assert vans <= their_vans
    assert ours <= theirs * 1.03


def short_shifts(problem: FleetProblem) -> FleetProblem:
    """The same fleet with two-hour shifts: a van then serves a fraction of the grid."""
    vans = [
        v.model_copy(update={"shift_end": v.shift_start.replace(hour=8)}) for v in problem.vehicles
    ]
    return problem.model_copy(update={"vehicles": vans})


@pytest.mark.slow
def test_more_vans_never_serve_fewer_stops():
    few = plan_fleet(short_shifts(vienna_grid(150, 2, 4.0)))
    many = plan_fleet(short_shifts(vienna_grid(150, 40, 4.0)))
    served_few = sum(len(r.plan.stops) for r in few.routes)
    served_many = sum(len(r.plan.stops) for r in many.routes)
    assert 0 < served_few < 150
    assert served_many == 150 and not many.unassigned
    assert many.vehicles_used > few.vehicles_used
    # what two vans leave, they leave for their shifts, or (where the estimates say a stop
    # would still fit) for the search's time limit; never for another reason
    assert set(Counter(u.reason for u in few.unassigned)) <= {"shift", "time_limit"}
