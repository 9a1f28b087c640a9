"""The round trip: one van, start and end at the depot (paper §4).

Two tools, each where it is strongest (measured beside LKH-3 on clustered, uniform and TSPLIB
rounds, ``benchmarks/bench_planner.py``):

1. An iterated local search (:mod:`core.routing.ils`: 2-opt and Or-opt on near places and
   the spanning tree's links, double-bridge kicks), :data:`RUNS` runs from Christofides' tour
   with their own seeds, the best kept. Each run ends after its share of the work's kicks or
   after :data:`STALL_KICKS` kicks without improvement.
2. CP-SAT's circuit constraint with its LP relaxation (linearization level 2) and the 2-cycle
   cuts ``x_ij + x_ji ≤ 1``, which the circuit's LP lacks and which make it much tighter, on
   every arc: from the local search's tour it proves the optimum of rounds up to
   :data:`PROOF_MAX_NODES` places within a few hundred milliseconds, of rounds up to
   :data:`FULL_GRAPH_MAX_NODES` places in tens. A proof over every arc is the only
   ``optimal`` status; a model on fewer arcs (each place's nearest, say) proves nothing, for on
   clustered rounds the arcs between clusters that the best tour takes are seldom among them.

Every search is single-threaded, seeded and stopped by its work (:mod:`core.routing.effort`:
kicks, CP-SAT's deterministic time), so a busy machine does not change the answer; the deadline
only caps it, and the tour says when it did (``ended``).
Costs are non-negative integers: the caller rounds explicitly (metres, seconds, Wh).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from ortools.constraint_solver import pywrapcp, routing_enums_pb2
from ortools.sat.python import cp_model

from core.exceptions import InvalidParameterError
from core.routing.effort import Effort, SearchEnd, combined

SolverStatus = Literal["optimal", "feasible", "fixed_order"]
#: Rounds up to this many nodes (depot included) are proven on the full graph from
#: Christofides' tour: tens of milliseconds.
FULL_GRAPH_MAX_NODES = 30
#: Up to this many, the full graph after a first local search: a proof in a few hundred
#: milliseconds on most delivery rounds.
PROOF_MAX_NODES = 60
#: Share of the work the local search has before a proof is tried (beyond
#: :data:`FULL_GRAPH_MAX_NODES`), and the share the two have together; the local search has
#: the rest when no proof comes.
PROOF_SEARCH_SHARE = 0.3
PROOF_SHARE = 0.8
#: Independent runs of the local search sharing its budget.
RUNS = 3
#: Kicks without improvement after which a run of the local search ends early.
STALL_KICKS = 20_000


@dataclass(frozen=True)
class Tour:
    """A solved round trip.

    Attributes
    ----------
    order
        Node indices, starting and ending at the depot 0.
    status
        ``optimal`` (proven over all arcs), ``feasible`` (the best found) or ``fixed_order``.
    cost
        Sum of the integer arc costs along the tour.
    runtime_s
        Wall-clock time of the search [s].
    ended
        How the search stopped: its optimum proven, its work done, or at the deadline.
    """

    order: list[int]
    status: SolverStatus
    cost: int
    runtime_s: float
    ended: SearchEnd = "work"


def tour_cost(cost: NDArray[np.int64], order: list[int]) -> int:
    """Sum of ``cost[i, j]`` along consecutive nodes of ``order``."""
    return int(cost[order[:-1], order[1:]].sum())


def solve_tour(cost: NDArray[np.int64], effort: Effort, keep_order: bool = False) -> Tour:
    """Shortest round trip from node 0 through every other node and back.

    Parameters
    ----------
    cost
        Square matrix of non-negative integer arc costs; may be asymmetric.
    effort
        The search's work, its deadline and its seed.
    keep_order
        Evaluate the order 0, 1, …, n−1, 0 as given instead of optimising.

    Returns
    -------
    Tour
        The same for the same input and effort, unless the deadline stopped it (``ended``).
    """
    cost = np.asarray(cost, dtype=np.int64)
    n = cost.shape[0]
    if cost.ndim != 2 or cost.shape != (n, n) or n < 1 or (cost < 0).any():
        raise InvalidParameterError("cost must be a square matrix of non-negative integers", "cost")
    started = time.perf_counter()

    def done(order: list[int], status: SolverStatus, *ends: SearchEnd) -> Tour:
        elapsed = time.perf_counter() - started
        return Tour(order, status, tour_cost(cost, order), elapsed, combined(ends))

    if keep_order or n <= 3:
        order = [*range(n), 0]
        if n == 3 and not keep_order:
            order = min(([0, 1, 2, 0], [0, 2, 1, 0]), key=lambda o: tour_cost(cost, o))
        return done(
            order, "fixed_order" if keep_order else "optimal", "work" if keep_order else "proof"
        )
    start = _first_tour(cost)
    if n > PROOF_MAX_NODES:
        best, cut = _improve(cost, start, effort)
        return done(best, "feasible", "time_limit" if cut else "work")
    search_share = PROOF_SEARCH_SHARE if n > FULL_GRAPH_MAX_NODES else 0.0
    best, cut = _improve(cost, start, effort.share(search_share))
    found, proven, exact_cut = _solve_exact(cost, best, effort.share(PROOF_SHARE - search_share))
    if found is not None and tour_cost(cost, found) <= tour_cost(cost, best):
        best = found
    if proven:
        return done(best, "optimal", "proof")
    best, last_cut = _improve(cost, best, effort.share(1 - PROOF_SHARE))
    cut_short: list[SearchEnd] = ["time_limit"] if cut or exact_cut or last_cut else []
    return done(best, "feasible", *cut_short, "work")


def solve_path(
    cost: NDArray[np.int64], nodes: list[int], effort: Effort, keep_order: bool = False
) -> Tour:
    """The cheapest path through ``nodes`` of ``cost`` from the first to the last, as node
    indices from first to last (the same node first and last: a round trip); its cost and
    status are the path's. A path is solved as a round trip on a matrix where the only way out
    of the last node leads back to the first at no cost."""
    first, last = nodes[0], nodes[-1]
    if first == last:
        inner = nodes[:-1]
        tour = solve_tour(cost[np.ix_(inner, inner)], effort, keep_order)
        return replace(tour, order=[inner[k] for k in tour.order])
    path = cost[np.ix_(nodes, nodes)].copy()
    end = len(nodes) - 1
    never = int(path.max()) * len(nodes) + 1
    path[end, :] = never
    path[:, 0] = never
    path[end, 0] = 0
    tour = solve_tour(path, effort, keep_order)
    return replace(tour, order=[nodes[k] for k in tour.order[:-1]])


def prepare() -> None:
    """Load the compiled searches now (about a second, once per process) — the round trip's
    local search and the charging stations' labels — not in the first request that needs them:
    what worker processes do first."""
    from core.routing import ils, stations  # Numba's import is heavy: only solvers pay it

    ils.warm_up()
    stations.warm_up()


def _improve(cost: NDArray[np.int64], start: list[int], effort: Effort) -> tuple[list[int], bool]:
    """The best of :data:`RUNS` local searches from ``start``, sharing the effort's kicks
    (each with its own seed); and whether the deadline cut them short."""
    from core.routing.ils import iterated_local_search

    best = start
    kicks = effort.kicks(cost.shape[0]) // RUNS
    for run in range(RUNS):
        found, cut = iterated_local_search(
            cost, start, kicks, effort.watch(), effort.seed + 1000 * run, STALL_KICKS
        )
        if tour_cost(cost, found) < tour_cost(cost, best):
            best = found
        if cut:
            return best, True
    return best, False


#: Time kept back from CP-SAT's budget for its own stopping and for reading the solution, a
#: fixed part and a part per arc [s].
_EXACT_STOP_MARGIN_S = 0.010
_EXACT_STOP_MARGIN_PER_ARC_S = 2.5e-6


def _solve_exact(
    cost: NDArray[np.int64],
    start: list[int],
    effort: Effort,
    keep: NDArray[np.bool_] | None = None,
) -> tuple[list[int] | None, bool, bool]:
    """CP-SAT with a circuit constraint, its LP relaxation and 2-cycle cuts, from ``start``,
    for the effort's deterministic time (one worker, seeded: deterministic), by its deadline.
    The best tour found (or None), whether it is proven optimal over the model's arcs (every
    arc, or those of ``keep`` and of ``start``), and whether the deadline stopped it."""
    n = cost.shape[0]
    keep = np.ones((n, n), dtype=bool) if keep is None else keep.copy()
    keep[start[:-1], start[1:]] = True
    np.fill_diagonal(keep, False)
    model = cp_model.CpModel()
    arcs = {
        (int(i), int(j)): model.new_bool_var("") for i, j in zip(*np.nonzero(keep), strict=True)
    }
    model.add_circuit([(i, j, var) for (i, j), var in arcs.items()])
    model.minimize(sum(int(cost[i, j]) * var for (i, j), var in arcs.items()))
    for (i, j), var in arcs.items():
        back = arcs.get((j, i))
        if i < j and back is not None:
            model.add_bool_or([var.Not(), back.Not()])
    used = set(itertools.pairwise(start))
    for arc, var in arcs.items():
        model.add_hint(var, arc in used)
    solver = cp_model.CpSolver()
    # The LP relaxation of the circuit (level 2) is what proves TSP optimality fast; presolve
    # only costs time on this model.
    solver.parameters.linearization_level = 2
    solver.parameters.cp_model_presolve = False
    margin_s = _EXACT_STOP_MARGIN_S + _EXACT_STOP_MARGIN_PER_ARC_S * len(arcs)
    # 0: no time left to start; 1: its own time limit stopped it, and a search cut by the
    # clock anywhere is no record to replay, so what it found is thrown away
    watch = effort.keeping(margin_s).watch()
    if watch.passed(0) or watch.replayed_at() == 1:
        return None, False, True
    work = effort.cpsat_deterministic_time()
    if work <= 0:
        return None, False, False
    budget_s = effort.left_s() - margin_s
    solver.parameters.max_time_in_seconds = min(budget_s, 86_400.0)  # "never" is no number
    solver.parameters.max_deterministic_time = work
    solver.parameters.num_workers = 1
    solver.parameters.random_seed = effort.seed
    result = solver.solve(model)
    if result != cp_model.OPTIMAL and solver.deterministic_time < work * 0.999:
        watch.mark(1)
        return None, False, True
    if result not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        return None, False, False
    successor = {i: j for (i, j), var in arcs.items() if solver.boolean_value(var)}
    order = [0]
    while len(order) <= n:
        order.append(successor[order[-1]])
    return order, result == cp_model.OPTIMAL, False


def _routing(cost: NDArray[np.int64]) -> tuple[pywrapcp.RoutingIndexManager, pywrapcp.RoutingModel]:
    n = cost.shape[0]
    manager = pywrapcp.RoutingIndexManager(n, 1, 0)
    routing = pywrapcp.RoutingModel(manager)
    transit = routing.RegisterTransitMatrix(cost.tolist())
    routing.SetArcCostEvaluatorOfAllVehicles(transit)
    return manager, routing


def _read(
    manager: pywrapcp.RoutingIndexManager, routing: pywrapcp.RoutingModel, solution: object
) -> list[int]:
    index = routing.Start(0)
    order = []
    while not routing.IsEnd(index):
        order.append(manager.IndexToNode(index))
        index = solution.Value(routing.NextVar(index))  # type: ignore[attr-defined]
    return [*order, 0]


def _first_tour(cost: NDArray[np.int64]) -> list[int]:
    """Christofides' tour (the routing library's first-solution strategy, without its local
    search): milliseconds even for hundreds of places."""
    manager, routing = _routing(cost)
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.CHRISTOFIDES
    params.solution_limit = 1
    return _read(manager, routing, routing.SolveWithParameters(params))
