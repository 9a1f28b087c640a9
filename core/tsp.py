"""The round trip: one van, start and end at the depot (paper §4), with OR-Tools.

Everyday rounds are solved exactly with CP-SAT's circuit constraint and its LP relaxation
(linearization level 2, which proves 20-node rounds in about 10 ms and 50–75-node rounds within
a second on this machine; benchmarks/). From 30 nodes on, the OR-Tools routing library first
spends a quarter of the budget on a good tour — a Christofides start, then guided local search
with the multi-armed-bandit operator schedule and only the operators that apply to one route —
and hands it to CP-SAT as a hint. Above ``EXACT_MAX_NODES`` routing alone uses the budget.
Costs are non-negative integers: the caller rounds explicitly (metres, seconds, Wh).
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
#: Rounds up to this many nodes (depot included) go to CP-SAT, which can prove optimality.
EXACT_MAX_NODES = 150
#: From this many nodes on, routing first finds a hint for CP-SAT...
HINT_MIN_NODES = 30
#: ...with this share of the time limit.
HINT_TIME_SHARE = 0.25


@dataclass(frozen=True)
class Tour:
    """A solved round trip.

    Attributes
    ----------
    order
        Node indices, starting and ending at the depot 0.
    status
        ``optimal`` (proven), ``feasible`` (time limit or heuristic stop) or ``fixed_order``.
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
        for exact solves; routing stops at a fixed number of solutions).
    """
    cost = np.asarray(cost, dtype=np.int64)
    n = cost.shape[0]
    if cost.ndim != 2 or cost.shape != (n, n) or n < 1 or (cost < 0).any():
        raise InvalidParameterError("cost must be a square matrix of non-negative integers", "cost")
    if not time_limit_s > 0:
        raise InvalidParameterError(f"time_limit_s must be > 0, got {time_limit_s}", "time_limit_s")
    started = time.perf_counter()
    if keep_order or n <= 2:
        order = [*range(n), 0]
        status: SolverStatus = "fixed_order" if keep_order else "optimal"
        return Tour(order, status, tour_cost(cost, order), time.perf_counter() - started)
    if n > EXACT_MAX_NODES:
        order = _solve_routing(cost, started + time_limit_s)
        return Tour(order, "feasible", tour_cost(cost, order), time.perf_counter() - started)
    hint = (
        _solve_routing(cost, started + time_limit_s * HINT_TIME_SHARE)
        if n >= HINT_MIN_NODES
        else None
    )
    exact = _solve_exact(cost, started + time_limit_s, hint)
    candidates = [t for t in (exact, hint) if t is not None]
    if not candidates:  # neither finished in time: the visiting order as given
        candidates = [[*range(n), 0]]
    if exact is not None and exact.status == "optimal":
        best, status = exact.order, "optimal"
    else:
        best = min(
            (c.order if isinstance(c, Tour) else c for c in candidates),
            key=lambda order: tour_cost(cost, order),
        )
        status = "feasible"
    return Tour(best, status, tour_cost(cost, best), time.perf_counter() - started)


#: Time kept back from CP-SAT's budget for its own stopping and for reading the solution, a
#: fixed part and a part per arc [s] (measured: about 45 ms at 150 nodes).
_EXACT_STOP_MARGIN_S = 0.010
_EXACT_STOP_MARGIN_PER_ARC_S = 2.5e-6


def _solve_exact(
    cost: NDArray[np.int64], deadline: float, hint: list[int] | None = None
) -> Tour | None:
    """CP-SAT with a circuit constraint and its LP relaxation, to finish by ``deadline``
    (a ``time.perf_counter`` value); one worker, so the search is deterministic. ``hint`` is a
    tour to start from."""
    n = cost.shape[0]
    model = cp_model.CpModel()
    arcs = {(i, j): model.new_bool_var(f"x{i}_{j}") for i in range(n) for j in range(n) if i != j}
    model.add_circuit([(i, j, var) for (i, j), var in arcs.items()])
    model.minimize(sum(int(cost[i, j]) * var for (i, j), var in arcs.items()))
    if hint is not None:
        used = set(itertools.pairwise(hint))
        for arc, var in arcs.items():
            model.add_hint(var, arc in used)
    solver = cp_model.CpSolver()
    # The LP relaxation of the circuit (level 2) is what proves TSP optimality fast; presolve
    # only costs time on this model.
    solver.parameters.linearization_level = 2
    solver.parameters.cp_model_presolve = False
    # The budget is what is left once the model is built.
    margin_s = _EXACT_STOP_MARGIN_S + _EXACT_STOP_MARGIN_PER_ARC_S * len(arcs)
    budget_s = deadline - time.perf_counter() - margin_s
    if budget_s <= 0:
        return None
    solver.parameters.max_time_in_seconds = budget_s
    solver.parameters.num_workers = 1
    solver.parameters.random_seed = 0
    result = solver.solve(model)
    if result not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        return None
    successor = {i: j for (i, j), var in arcs.items() if solver.boolean_value(var)}
    order = [0]
    while len(order) <= n:
        order.append(successor[order[-1]])
    status: SolverStatus = "optimal" if result == cp_model.OPTIMAL else "feasible"
    return Tour(order, status, tour_cost(cost, order), solver.wall_time)


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


def _solve_routing(cost: NDArray[np.int64], deadline: float) -> list[int]:
    """OR-Tools routing: Christofides start, guided local search, done by ``deadline`` (a
    ``time.perf_counter`` value; at least the first solution is always built)."""
    n = cost.shape[0]
    manager = pywrapcp.RoutingIndexManager(n, 1, 0)
    routing = pywrapcp.RoutingModel(manager)
    transit = routing.RegisterTransitMatrix(cost.tolist())
    routing.SetArcCostEvaluatorOfAllVehicles(transit)
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.CHRISTOFIDES
    params.use_multi_armed_bandit_concatenate_operators = True
    for operator in _IDLE_OPERATORS:
        setattr(params.local_search_operators, operator, _BOOL_FALSE)
    params.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    budget_s = deadline - time.perf_counter() - _ROUTING_STOP_MARGIN_S
    params.time_limit.FromMilliseconds(max(int(budget_s * 1000), 1))
    solution = routing.SolveWithParameters(params)
    index = routing.Start(0)
    order = []
    while not routing.IsEnd(index):
        order.append(manager.IndexToNode(index))
        index = solution.Value(routing.NextVar(index))
    return [*order, 0]
