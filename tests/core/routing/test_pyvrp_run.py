"""PyVRP's search counted in work: its iterations and the moves its local search evaluates,
stopped when those make the effort's reference seconds (``core/routing/pyvrp_run.py``)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import pyvrp

from core.routing import pyvrp_run
from core.routing.effort import PYVRP_ITERATION_S, PYVRP_MOVE_S, Effort
from core.routing.pyvrp_run import above_routes


def test_the_work_of_iterations_and_moves_by_hand():
    """1,000 iterations evaluating 10⁶ moves on 100 clients: 1,000 × (34 + 0.16 × 100) µs +
    10⁶ × (27 + 0.034 × 100) ns = 50 ms + 30.4 ms; with stops optional, 0.57 of that."""
    assert PYVRP_ITERATION_S == (34e-6, 0.16e-6) and PYVRP_MOVE_S == (27e-9, 0.034e-9)
    assert Effort.pyvrp_spent_s(1_000, 10**6, 100) == pytest.approx(0.0804)
    assert Effort.pyvrp_spent_s(1_000, 10**6, 100, optional=True) == pytest.approx(0.0804 * 0.57)


def instance(vans: int, clients: int = 60) -> pyvrp.ProblemData:
    """``clients`` of 1 unit in a 1,000-unit square, no windows, ``vans`` that can just carry
    them all."""
    rng = np.random.default_rng(3)
    xy = np.vstack([[500.0, 500.0], rng.uniform(0, 1000, (clients, 2))])
    distance = np.rint(np.sqrt(((xy[:, None] - xy[None]) ** 2).sum(-1))).astype(np.int64)
    return pyvrp.ProblemData(
        [pyvrp.Location(float(x), float(y)) for x, y in xy],
        [pyvrp.Client(location=k, delivery=[1]) for k in range(1, clients + 1)],
        [pyvrp.Depot(location=0)],
        [pyvrp.VehicleType(num_available=vans, capacity=[math.ceil(clients / vans)])],
        [distance],
        [distance],
    )


@pytest.mark.parametrize("vans", [1, 12])
def test_a_search_ends_when_its_iterations_and_moves_make_its_work(vans):
    """Its counted work reaches the effort's, and the last iteration took it there: it is
    short of the effort by less than an iteration's (at most the moves of an exhaustive
    search, about a millisecond here)."""
    work_s = 0.5
    result, stop = pyvrp_run.solve(instance(vans), Effort(work_s, math.inf, seed=2))
    assert stop.ended == "work" and result.is_feasible()
    assert work_s <= stop.spent_s() < work_s * 1.01
    assert stop.search.moves > 100 * stop.done  # moves counted


def test_the_same_work_is_fewer_iterations_where_each_evaluates_more_moves():
    """Iterations are not the measure: the same work on one long route and on twelve short
    ones (whose iterations evaluate about twice the moves: more routes to move between) runs
    about half the iterations on the short ones."""
    ends = {
        vans: pyvrp_run.solve(instance(vans), Effort(0.5, math.inf, seed=2))[1] for vans in (1, 12)
    }
    moves = {vans: stop.search.moves / stop.done for vans, stop in ends.items()}
    assert moves[12] > 1.5 * moves[1]
    assert ends[12].done < ends[1].done / 1.3


def test_the_same_effort_gives_the_same_routes():
    data = instance(12)
    first, second = (pyvrp_run.solve(data, Effort(0.3, math.inf, seed=5))[0].best for _ in range(2))
    assert first == second


def test_a_fixed_cost_above_any_routes_puts_fewer_vehicles_first():
    """Every split of four customers into routes and every order (an asymmetric matrix): the
    dearest routes of k vehicles cost less than the cheapest of k + 1 once each vehicle costs
    :func:`above_routes` — on a hundred customers a twentieth of the sum of all arcs, the
    bound E-VRPTW's step 1 had."""
    rng = np.random.default_rng(7)
    distance = rng.integers(1, 1000, size=(5, 5))
    np.fill_diagonal(distance, 0)
    fixed = above_routes(distance, 4)
    costs: dict[int, list[int]] = {}
    for labels in itertools.product(range(4), repeat=4):  # customer → its route's label
        groups = [[c + 1 for c in range(4) if labels[c] == g] for g in set(labels)]
        for orders in itertools.product(*(itertools.permutations(g) for g in groups)):
            cost = sum(
                sum(distance[a, b] for a, b in itertools.pairwise([0, *order, 0]))
                for order in orders
            )
            costs.setdefault(len(groups), []).append(cost + fixed * len(groups))
    for k in range(1, 4):
        assert max(costs[k]) < min(costs[k + 1])
    big = rng.integers(1, 1000, size=(101, 101))  # a hundred customers
    assert above_routes(big, 100) < big.sum() / 20
