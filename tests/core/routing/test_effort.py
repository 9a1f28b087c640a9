"""The clock and its replay: every search the deadline cuts records where, and a replay of
those records stops each search at the same place without reading the clock — the same
result to the last node, for each engine (the round trip's local search, CP-SAT, PyVRP,
OR-Tools, the charging search)."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from ortools.sat.python import cp_model

from core.exceptions import ServerLimitError
from core.routing.effort import Clock, Effort
from core.routing.evrp import solve_evrptw
from core.routing.tsp import _solve_exact, solve_tour
from core.routing.vrp import RoutingInput, VehicleSpec, _ortools_routes, _pyvrp_routes
from testbed.evrptw import read
from testbed.reference import euc_2d_matrix


def cut(work_s: float, time_limit_s: float) -> Effort:
    """Far more work than the limit lets it do: the clock cuts it."""
    return Effort.starting_now(work_s, time_limit_s, seed=1)


def replay_of(effort: Effort) -> Effort:
    """The same work replayed from ``effort``'s records, with a deadline already past: a
    replay that read the clock would stop at once."""
    return Effort.starting_now(effort.work_s, -1.0, effort.seed, dict(effort.clock.stops))


def test_a_watch_records_where_the_deadline_stopped_it_and_only_that():
    clock = Clock()
    past, future = clock.watch(time.perf_counter() - 1), clock.watch(math.inf)
    assert not future.passed(10)
    assert past.passed(7) and past.passed(9)  # once passed, passed
    assert clock.stops == {0: 7}
    future.mark(3)  # a solver that saw its own time limit
    assert clock.stops == {0: 7, 1: 3}


def test_a_replayed_watch_stops_where_the_record_says_and_ignores_the_clock():
    clock = Clock(replayed={1: 4})
    first, second = clock.watch(time.perf_counter() - 1), clock.watch(time.perf_counter() - 1)
    assert not first.passed(10**6)  # no record: it ran its work, whatever the clock
    assert [second.passed(k) for k in (3, 4, 5)] == [False, True, True]
    assert (first.replayed_at(), second.replayed_at()) == (None, 4)
    assert clock.stops == {}  # a replay records nothing
    assert Effort.starting_now(1.0, -1.0, 0, {}).left_s() == math.inf


def test_a_round_trip_the_clock_cut_is_replayed_to_the_node(reference_dir):
    cost = euc_2d_matrix(reference_dir / "tsplib" / "kroA200.tsp")
    effort = cut(30.0, 0.3)
    first = solve_tour(cost, effort)
    assert first.ended == "time_limit" and effort.clock.stops
    again = solve_tour(cost, replay_of(effort))
    assert (again.order, again.ended) == (first.order, first.ended)


def test_cpsat_cut_by_its_own_limit_is_thrown_away_and_skipped_in_a_replay(
    reference_dir, monkeypatch
):
    cost = euc_2d_matrix(reference_dir / "tsplib" / "kroA100.tsp")
    start = [*range(100), 0]  # far from the optimum: no proof within the limit
    effort = cut(1000.0, 1.0)
    assert _solve_exact(cost, start, effort) == (None, False, True)
    assert list(effort.clock.stops.values()) == [1]

    def never(*_: object) -> None:
        raise AssertionError("a replay solved what the cut threw away")

    monkeypatch.setattr(cp_model.CpSolver, "solve", never)
    assert _solve_exact(cost, start, replay_of(effort)) == (None, False, True)


def vrptw(n: int, seed: int = 4) -> RoutingInput:
    """``n`` stops on a 20 km square, tight windows, a payload for about eight stops a van."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 20_000, size=(n + 1, 2))
    metres = np.rint(np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1))).astype(np.int64)
    travel = metres // 10
    opens = rng.integers(0, 6 * 3600, size=n)
    vehicle = VehicleSpec(
        arc_cost=metres,
        energy=metres // 100,
        energy_capacity=int(metres.max()) // 4,
        payload_capacity_g=8,
        shift_s=(0, 10 * 3600),
    )
    return RoutingInput(
        travel_s=travel,
        service_s=np.full(n + 1, 300, dtype=np.int64),
        windows_s=[[], *([(int(a), int(a) + 3600)] for a in opens)],
        demand_g=np.array([0, *[1] * n], dtype=np.int64),
        vehicles=[vehicle] * (n // 6),
        horizon_s=10 * 3600,
        drop_penalty=10**12,
    )


def test_pyvrp_cut_by_the_clock_is_replayed_to_the_node():
    problem = vrptw(120)
    effort = cut(100.0, 0.5)
    first = _pyvrp_routes(problem, effort, None)
    assert first[1] == "time_limit" and effort.clock.stops
    assert _pyvrp_routes(problem, replay_of(effort), None) == first


@pytest.mark.parametrize("limit_s", [0.3, 0.8])
def test_ortools_cut_by_its_own_limit_is_replayed_to_the_node(limit_s):
    problem = vrptw(60)
    effort = cut(1000.0, limit_s)
    first = _ortools_routes(problem, effort, None)
    assert first is not None and first.ended == "time_limit"
    (found,) = effort.clock.stops.values()  # the solutions it had found by then
    assert found > 0
    assert _ortools_routes(problem, replay_of(effort), None) == first


@pytest.mark.slow
def test_the_charging_search_cut_by_the_clock_is_replayed_to_the_node(reference_dir):
    instance = read(reference_dir / "evrptw" / "rc101_21.txt").problem
    effort = cut(60.0, 2.0)
    first = solve_evrptw(instance, effort)
    assert first.ended == "time_limit" and effort.clock.stops
    assert solve_evrptw(instance, replay_of(effort)) == first


def test_a_replay_past_its_limit_is_refused_naming_replay():
    """A replay's watches do not read the deadline, but its limit: past it, at a watch or where
    a solver's own time limit (the replay limit's) cut it, the replay is refused."""
    clock = Clock(replayed={}, guard=time.perf_counter() - 1, guard_s=5.0)
    with pytest.raises(ServerLimitError, match="more than the 5 s") as refused:
        clock.watch(math.inf).passed(0)
    assert refused.value.field == "replay"
    unlimited = Clock(replayed={}, guard=math.inf).watch(-1.0)
    assert not unlimited.passed(10**9)
    with pytest.raises(ServerLimitError):  # a solver's own limit cut a replay
        unlimited.mark(3)
    within = Effort.starting_now(1000.0, -1.0, 1, {}, "", replay_limit_s=0.3)
    assert 0 < within.left_s() <= 0.3  # what the solvers' own limits get
    with pytest.raises(ServerLimitError):
        _ortools_routes(vrptw(60), within, None)
