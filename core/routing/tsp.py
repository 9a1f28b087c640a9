"""The round trip: one van, start and end at the depot (paper §4), with OR-Tools.

Three tools, each where it is strongest (measured on TSPLIB and random instances,
``benchmarks/bench_planner.py``):

1. CP-SAT's circuit constraint with its LP relaxation (linearization level 2) and the 2-cycle
   cuts ``x_ij + x_ji ≤ 1``, which the circuit's LP lacks and which make it much tighter. Up to
   :data:`FULL_GRAPH_MAX_NODES` places it runs on every arc and proves the optimum in tens of
   milliseconds.
2. Beyond that, the same model on each place's :data:`NEIGHBOURS` nearest successors and
   predecessors (plus the arcs of the start tour): a tenth of the arcs, so the LP and the
   search are several times faster. Its optimum is optimal over those arcs — in every TSPLIB
   and random instance checked it is the true optimum — but it is not a proof over all arcs,
   so the status is ``feasible``.
3. When CP-SAT neither proves nor finishes, the OR-Tools routing library's guided local search
   improves its best tour for the rest of the budget (operators that apply to one route only).
   Above :data:`EXACT_MAX_NODES` it has the whole budget.

Every search is single-threaded and deterministic, so a busy second core does not change the
answer, and the time limit is a deadline: nothing runs past it. Costs are non-negative
integers: the caller rounds explicitly (metres, seconds, Wh).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from ortools.constraint_solver import pywrapcp, routing_enums_pb2
from ortools.sat.python import cp_model

from core.exceptions import InvalidParameterError

SolverStatus = Literal["optimal", "feasible", "fixed_order"]
#: Rounds up to this many nodes (depot included) are solved on the full graph (a proof).
FULL_GRAPH_MAX_NODES = 30
#: Rounds up to this many nodes go to CP-SAT; larger ones to routing alone.
EXACT_MAX_NODES = 150
#: Nearest successors and predecessors of each node kept in the sparse CP-SAT model.
NEIGHBOURS = 7
#: Share of the budget CP-SAT has before guided local search takes over its best tour.
EXACT_TIME_SHARE = 0.7


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
    """

    order: list[int]
    status: SolverStatus
    cost: int
    runtime_s: float


def tour_cost(cost: NDArray[np.int64], order: list[int]) -> int:
    """Sum of ``cost[i, j]`` along consecutive nodes of ``order``."""
    return int(cost[order[:-1], order[1:]].sum())


def solve_tour(
    cost: NDArray[np.int64], time_limit_s: float = 1.0, keep_order: bool = False
) -> Tour:
    """Shortest round trip from node 0 through every other node and back.

    Parameters
    ----------
    cost
        Square matrix of non-negative integer arc costs; may be asymmetric.
    time_limit_s
        Wall-clock budget of the search [s], > 0.
    keep_order
        Evaluate the order 0, 1, …, n−1, 0 as given instead of optimising.

    Returns
    -------
    Tour
        Deterministic for the same input when the search ends before the time limit (always
        when CP-SAT finishes; the guided local search stops only at its time limit).
    """
    cost = np.asarray(cost, dtype=np.int64)
    n = cost.shape[0]
    if cost.ndim != 2 or cost.shape != (n, n) or n < 1 or (cost < 0).any():
        raise InvalidParameterError("cost must be a square matrix of non-negative integers", "cost")
    if not time_limit_s > 0:
        raise InvalidParameterError(f"time_limit_s must be > 0, got {time_limit_s}", "time_limit_s")
    started = time.perf_counter()
    deadline = started + time_limit_s

    def done(order: list[int], status: SolverStatus) -> Tour:
        return Tour(order, status, tour_cost(cost, order), time.perf_counter() - started)

    if keep_order or n <= 3:
        order = [*range(n), 0]
        if n == 3 and not keep_order:
            order = min(([0, 1, 2, 0], [0, 2, 1, 0]), key=lambda o: tour_cost(cost, o))
        return done(order, "fixed_order" if keep_order else "optimal")
    start = _first_tour(cost)
    if n > EXACT_MAX_NODES:
        return done(_improve(cost, start, deadline), "feasible")
    full = n <= FULL_GRAPH_MAX_NODES
    exact_deadline = deadline if full else started + time_limit_s * EXACT_TIME_SHARE
    found, proven = _solve_exact(cost, start, exact_deadline, None if full else NEIGHBOURS)
    best = (
        found if found is not None and tour_cost(cost, found) <= tour_cost(cost, start) else start
    )
    if proven:
        return done(best, "optimal" if full else "feasible")
    if time.perf_counter() < deadline - _ROUTING_STOP_MARGIN_S:
        best = _improve(cost, best, deadline)
    return done(best, "feasible")


#: Time kept back from CP-SAT's budget for its own stopping and for reading the solution, a
#: fixed part and a part per arc [s].
_EXACT_STOP_MARGIN_S = 0.010
_EXACT_STOP_MARGIN_PER_ARC_S = 2.5e-6


def _arcs(cost: NDArray[np.int64], start: list[int], neighbours: int | None) -> NDArray[np.bool_]:
    """Which arcs the CP-SAT model has: all, or each node's nearest successors and
    predecessors plus the start tour's arcs."""
    n = cost.shape[0]
    if neighbours is None or neighbours >= n - 1:
        keep = np.ones((n, n), dtype=bool)
    else:
        ranked = cost.astype(float)
        np.fill_diagonal(ranked, np.inf)
        keep = np.zeros((n, n), dtype=bool)
        rows = np.arange(n)
        keep[rows[:, None], np.argsort(ranked, axis=1)[:, :neighbours]] = True
        keep[np.argsort(ranked, axis=0)[:neighbours, :], rows[None, :]] = True
        keep[start[:-1], start[1:]] = True
    np.fill_diagonal(keep, False)
    return keep


def _solve_exact(
    cost: NDArray[np.int64], start: list[int], deadline: float, neighbours: int | None
) -> tuple[list[int] | None, bool]:
    """CP-SAT with a circuit constraint, its LP relaxation and 2-cycle cuts, from ``start``,
    to finish by ``deadline`` (a ``time.perf_counter`` value); one worker, so the search is
    deterministic. The best tour found (or None) and whether it is proven optimal over the
    model's arcs."""
    n = cost.shape[0]
    keep = _arcs(cost, start, neighbours)
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
    budget_s = deadline - time.perf_counter() - margin_s
    if budget_s <= 0:
        return None, False
    solver.parameters.max_time_in_seconds = budget_s
    solver.parameters.num_workers = 1
    solver.parameters.random_seed = 0
    result = solver.solve(model)
    if result not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        return None, False
    successor = {i: j for (i, j), var in arcs.items() if solver.boolean_value(var)}
    order = [0]
    while len(order) <= n:
        order.append(successor[order[-1]])
    return order, result == cp_model.OPTIMAL


# Routing operators that only act on optional visits, pickup-delivery pairs or several routes:
# useless for one van visiting every stop, and they cost search time.
_IDLE_OPERATORS = (
    "use_relocate_pair",
    "use_make_active",
    "use_make_inactive",
    "use_make_chain_inactive",
    "use_swap_active",
    "use_exchange_pair",
    "use_light_relocate_pair",
    "use_relocate_subtrip",
    "use_exchange_subtrip",
    "use_relocate_path_global_cheapest_insertion_insert_unperformed",
    "use_shortest_path_swap_active",
    "use_swap_active_chain",
    "use_global_cheapest_insertion_visit_types_lns",
    "use_local_cheapest_insertion_visit_types_lns",
)
_BOOL_FALSE = 2  # ortools.util.optional_boolean_pb2.BOOL_FALSE
#: Time kept back from the routing search for stopping and reading the tour [s].
_ROUTING_STOP_MARGIN_S = 0.010


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


def _improve(cost: NDArray[np.int64], start: list[int], deadline: float) -> list[int]:
    """Guided local search from ``start`` until ``deadline`` (a ``time.perf_counter`` value),
    with the multi-armed-bandit operator schedule; the better of start and result."""
    manager, routing = _routing(cost)
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.use_multi_armed_bandit_concatenate_operators = True
    for operator in _IDLE_OPERATORS:
        setattr(params.local_search_operators, operator, _BOOL_FALSE)
    params.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    budget_s = deadline - time.perf_counter() - _ROUTING_STOP_MARGIN_S
    params.time_limit.FromMilliseconds(max(int(budget_s * 1000), 1))
    routing.CloseModelWithParameters(params)
    initial = routing.ReadAssignmentFromRoutes([start[1:-1]], True)
    solution = routing.SolveFromAssignmentWithParameters(initial, params)
    if solution is None:
        return start
    improved = _read(manager, routing, solution)
    return min((improved, start), key=lambda order: tour_cost(cost, order))
