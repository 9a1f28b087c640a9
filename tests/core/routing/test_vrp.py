"""The routing solver on instances small enough to know the optimum by hand: places on a line
(node k at k km from the depot, one minute per km)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from core.routing.effort import Effort
from core.routing.units import (
    energy_units_down,
    energy_units_up,
    payload_units_down,
    payload_units_up,
)
from core.routing.vrp import (
    RoutingInput,
    VehicleSpec,
    _kept,
    _ortools_routes,
    _pyvrp_routes,
    solve_routes,
)

#: A second of search work, the deadline far enough not to stop it.
WORK = Effort(1.0, float("inf"))


def line(positions: list[int]) -> np.ndarray:
    xs = np.array([0, *positions])
    return np.abs(xs[:, None] - xs[None, :]).astype(np.int64)


def problem(
    positions: list[int],
    vans: int = 1,
    windows: list[list[tuple[int, int]]] | None = None,
    demand: list[int] | None = None,
    payload: int = 10**9,
    energy_capacity: int | None = None,
    horizon: int = 10_000,
    fixed: int = 0,
) -> RoutingInput:
    km = line(positions)
    n = km.shape[0]
    vehicle = VehicleSpec(
        arc_cost=km * 1000,  # metres
        energy=None if energy_capacity is None else km * 10,
        energy_capacity=energy_capacity or 0,
        payload_capacity_g=payload,
        shift_s=(0, horizon),
        fixed_cost=fixed,
    )
    return RoutingInput(
        travel_s=km * 60,
        service_s=np.zeros(n, dtype=np.int64),
        windows_s=windows or [[] for _ in range(n)],
        demand_g=np.array([0, *(demand or [0] * (n - 1))], dtype=np.int64),
        vehicles=[vehicle] * vans,
        horizon_s=horizon,
        drop_penalty=10**9,
    )


def cost(routes: list[list[int]], positions: list[int]) -> int:
    km = line(positions)
    return sum(int(km[[0, *r], [*r, 0]].sum()) for r in routes if r)


def test_one_van_drives_out_and_back():
    positions = [3, 1, 4, 2]
    outcome = solve_routes(problem(positions), WORK)
    assert outcome is not None
    # Out to 4 km and back: 8 km whatever the order, but only the sorted order does it.
    assert cost(outcome.routes, positions) == 8


def test_payload_splits_the_stops_between_two_vans():
    # Two stops at 1 km, two at 5 km; 2 kg each, 4 kg per van: each van takes a pair.
    positions = [1, 1, 5, 5]
    outcome = solve_routes(problem(positions, vans=2, demand=[2000] * 4, payload=4000), WORK)
    assert outcome is not None
    assert sorted(sorted(r) for r in outcome.routes) == [[1, 2], [3, 4]]
    assert cost(outcome.routes, positions) == 2 + 10


def test_windows_order_the_stops():
    # Node 1 (1 km) only after 10 min, node 2 (3 km) before 5 min: 2 first, then 1.
    positions = [1, 3]
    windows = [[], [(600, 10_000)], [(0, 300)]]
    outcome = solve_routes(problem(positions, windows=windows), WORK)
    assert outcome is not None and outcome.routes == [[2, 1]]


def test_energy_is_a_constraint_and_an_impossible_stop_is_left_out():
    # 10 units per km; 60 units take the van to 3 km and back, not to 4.
    positions = [1, 3, 4]
    outcome = solve_routes(problem(positions, energy_capacity=60), WORK)
    assert outcome is not None
    assert sorted(outcome.routes[0]) == [1, 2]


def test_a_fixed_cost_keeps_the_second_van_home():
    positions = [1, 1]
    outcome = solve_routes(problem(positions, vans=2, fixed=10**6), WORK)
    assert outcome is not None
    assert sorted(len(r) for r in outcome.routes) == [0, 2]


def test_the_solver_units_round_what_is_taken_up_and_limits_down():
    assert energy_units_up([360.0, 360.1]).tolist() == [1, 2]
    assert energy_units_down(719.9) == 1
    assert payload_units_up([0.3, 60.0]).tolist() == [300, 60_000]
    assert payload_units_down(0.0015) == 1


def test_a_route_the_search_left_infeasible_keeps_the_stops_that_fit():
    """PyVRP's best may break a rule when its search was cut short: the van keeps, in order,
    the stops it reaches inside their windows and can carry, and is back within its shift."""
    from core.routing.vrp import _kept

    # stops at 1, 3, 5 and 2 km, 1 min per km: stop 2 (3 km) closes at 2 min; the van reaches
    # it at 3 min after stop 1 → left out; stop 4 (2 kg) would overload the 3 kg van.
    positions = [1, 3, 5, 2]
    windows = [[], [], [(0, 120)], [], []]
    routes = problem(positions, windows=windows, demand=[1000, 1000, 1000, 2000], payload=3000)
    assert _kept(routes, 0, [1, 2, 3, 4]) == [1, 3]
    # a shift that ends before the van is back from stop 3 (5 km, back at 10 min): stop 3 goes
    short = problem(positions, horizon=500)
    assert _kept(short, 0, [1, 3]) == [1]


def test_a_van_too_small_for_every_stop_serves_the_most_it_can_nearest_first():
    """Five 1 kg stops, a 3 kg van: no routes serve them all, so the search with every stop
    required gives up and the one with stops optional serves three — the three nearest, the
    cheapest three (at 1, 2 and 3 km: 6 km out and back)."""
    positions = [5, 1, 4, 2, 3]
    routes = problem(positions, demand=[1000] * 5, payload=3000)
    outcome = solve_routes(routes, WORK)
    assert outcome is not None and outcome.ended == "work"
    assert sorted(outcome.routes[0]) == [2, 4, 5]
    assert cost(outcome.routes, positions) == 6


def test_pyvrp_is_given_costs_in_the_root_of_what_a_second_of_driving_costs():
    """Metres against seconds (here 1,000 m per 60 s) are divided by the root of 1,000 / 60,
    so PyVRP's penalties and neighbourhoods weigh time nearer to what they were tuned to; a
    large fixed cost keeps its scale (and stays larger than any routes)."""
    from core.routing.vrp import _pyvrp_model

    positions = [1, 2, 4]
    plain = problem(positions)
    model = _pyvrp_model(plain, required=True)
    per_s = 1000 / 60
    np.testing.assert_array_equal(
        np.asarray(model.data.distance_matrix(0)),
        np.rint(line(positions) * 1000 / np.sqrt(per_s)),
    )
    fixed = _pyvrp_model(problem(positions, vans=3, fixed=10**6), required=True)
    np.testing.assert_array_equal(np.asarray(fixed.data.distance_matrix(0)), line(positions) * 1000)
    assert fixed.data.vehicle_type(0).fixed_cost > 4_000 * 4 * 3


@pytest.mark.parametrize("engine", ["pyvrp", "ortools"])
def test_each_engine_serves_a_pinned_stop_only_by_its_van(engine):
    # Two vans, stops at 1 and 5 km; one van could serve all for 10 km and a second costs a
    # fixed 10**6. Stop 1 pinned to van 1 (forbidden for van 0): van 1 serves all, van 0 none.
    base = problem([1, 1, 5, 5], vans=2, fixed=10**6)
    vehicles = [replace(base.vehicles[0], forbidden=frozenset({1})), base.vehicles[1]]
    pinned = replace(base, vehicles=vehicles)
    if engine == "pyvrp":
        routes, _ = _pyvrp_routes(pinned, WORK, None)
    else:
        outcome = _ortools_routes(pinned, WORK, None)
        assert outcome is not None
        routes = outcome.routes
    assert routes is not None and routes[0] == [] and sorted(routes[1]) == [1, 2, 3, 4]
    assert cost(routes, [1, 1, 5, 5]) == 10


def test_a_route_cut_from_an_infeasible_search_drops_a_stop_pinned_elsewhere():
    base = problem([1, 2, 3])
    pinned = replace(base, vehicles=[replace(base.vehicles[0], forbidden=frozenset({2}))])
    assert _kept(pinned, 0, [1, 2, 3]) == [1, 3]
