"""Routes for several vans from one depot with OR-Tools' routing library: delivery time windows,
shifts, payload and an energy budget per van (the dimensions), each van with its own costs.

The solver sees integers only; the caller rounds explicitly: seconds for time, grams for
payload, tenths of a watt-hour for energy, and the objective's own unit for the arc costs.
A stop that no route can take is dropped for a penalty larger than any set of routes costs,
so stops are dropped only when they cannot be served, never to save cost.

The search is the routing library's: a first solution by the cheapest arc, then guided local
search until the time limit, or until :data:`SOLUTIONS_PER_STOP` improving solutions per stop
when that comes first (small fleets then end early, and deterministically).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from ortools.constraint_solver import pywrapcp, routing_enums_pb2

IntMatrix = NDArray[np.int64]

#: Solutions per stop after which guided local search ends before its time limit.
SOLUTIONS_PER_STOP = 40
#: The routing library overshoots its limit by a few milliseconds; it gets this much less [s].
_STOP_MARGIN_S = 0.01


@dataclass(frozen=True)
class VehicleSpec:
    """One van as the solver sees it.

    Attributes
    ----------
    arc_cost
        Objective cost of each arc, in the objective's integer unit.
    energy
        Energy each arc takes, with the service at its origin [0.1 Wh]; None: no budget.
    energy_capacity
        Energy the van may use on its route [0.1 Wh].
    payload_capacity_g
        Most the van's stops may take [g].
    shift_s
        Earliest departure and latest return [s after the day's reference].
    fixed_cost
        Cost of using the van at all (fewer vans first when large).
    wait_cost_per_s
        Cost of each second spent waiting for a window (the objective's unit per second).
    """

    arc_cost: IntMatrix
    energy: IntMatrix | None
    energy_capacity: int
    payload_capacity_g: int
    shift_s: tuple[int, int]
    fixed_cost: int = 0
    wait_cost_per_s: int = 0


@dataclass(frozen=True)
class RoutingInput:
    """Places (depot 0, then stops) and the vans.

    Attributes
    ----------
    travel_s
        Driving time of each arc [s]; an arc that does not exist is longer than the horizon.
    service_s
        Time spent at each place [s] (0 at the depot).
    windows_s
        Each place's windows [s after the day's reference]; empty: any time in the horizon.
    demand_g
        What each place takes [g].
    vehicles
        The vans.
    horizon_s
        The latest moment of the day [s after the reference].
    drop_penalty
        Cost of leaving a stop out.
    """

    travel_s: IntMatrix
    service_s: NDArray[np.int64]
    windows_s: list[list[tuple[int, int]]]
    demand_g: NDArray[np.int64]
    vehicles: list[VehicleSpec]
    horizon_s: int
    drop_penalty: int


@dataclass(frozen=True)
class RoutingOutcome:
    """Stops of each van in driving order (no depot); a stop in no route is left out."""

    routes: list[list[int]]


def solve_routes(
    problem: RoutingInput, time_limit_s: float, initial: list[list[int]] | None = None
) -> RoutingOutcome | None:
    """Routes for every van; None when the search finds no solution within the limit.

    Parameters
    ----------
    problem
        Places and vans.
    time_limit_s
        Search budget [s]; a deadline.
    initial
        Routes to start from (stops per van); ignored when they break a constraint.
    """
    started = time.perf_counter()
    manager, routing = _model(problem)
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
    params.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    params.solution_limit = SOLUTIONS_PER_STOP * max(problem.travel_s.shape[0] - 1, 1)
    budget_s = time_limit_s - (time.perf_counter() - started) - _STOP_MARGIN_S
    params.time_limit.FromMilliseconds(max(int(budget_s * 1000), 1))
    routing.CloseModelWithParameters(params)
    solution = None
    if initial is not None:
        start = routing.ReadAssignmentFromRoutes(
            [[manager.NodeToIndex(node) for node in route] for route in initial], True
        )
        if start is not None:
            solution = routing.SolveFromAssignmentWithParameters(start, params)
    if solution is None:
        solution = routing.SolveWithParameters(params)
    if solution is None:
        return None
    routes: list[list[int]] = []
    for v in range(len(problem.vehicles)):
        index = solution.Value(routing.NextVar(routing.Start(v)))
        route = []
        while not routing.IsEnd(index):
            route.append(manager.IndexToNode(index))
            index = solution.Value(routing.NextVar(index))
        routes.append(route)
    return RoutingOutcome(routes)


def _model(problem: RoutingInput) -> tuple[pywrapcp.RoutingIndexManager, pywrapcp.RoutingModel]:
    """The routing model: each van's arc costs and fixed cost; the time, payload and energy
    dimensions; a disjunction per stop."""
    n = problem.travel_s.shape[0]
    manager = pywrapcp.RoutingIndexManager(n, len(problem.vehicles), 0)
    routing = pywrapcp.RoutingModel(manager)
    callbacks: dict[int, int] = {}

    def matrix_callback(matrix: IntMatrix) -> int:
        # Vans of one kind share their matrices, and so their callbacks.
        key = id(matrix)
        if key not in callbacks:
            callbacks[key] = routing.RegisterTransitMatrix(matrix.tolist())
        return callbacks[key]

    for v, vehicle in enumerate(problem.vehicles):
        routing.SetArcCostEvaluatorOfVehicle(matrix_callback(vehicle.arc_cost), v)
        routing.SetFixedCostOfVehicle(int(vehicle.fixed_cost), v)
    horizon = int(problem.horizon_s)
    time_matrix = np.minimum(problem.travel_s + problem.service_s[:, None], horizon + 1)
    routing.AddDimension(matrix_callback(time_matrix), horizon, horizon + 1, False, "time")
    clock = routing.GetDimensionOrDie("time")
    for node in range(1, n):
        windows = problem.windows_s[node]
        if not windows:
            continue
        cumul = clock.CumulVar(manager.NodeToIndex(node))
        cumul.SetRange(int(windows[0][0]), int(windows[-1][1]))
        for (_, closes), (opens, _) in itertools.pairwise(windows):
            if opens > closes + 1:
                cumul.RemoveInterval(int(closes) + 1, int(opens) - 1)
    for v, vehicle in enumerate(problem.vehicles):
        first, last = (int(t) for t in vehicle.shift_s)
        clock.CumulVar(routing.Start(v)).SetRange(first, last)
        clock.CumulVar(routing.End(v)).SetRange(first, last)
        clock.SetSlackCostCoefficientForVehicle(int(vehicle.wait_cost_per_s), v)
    demand = routing.RegisterUnaryTransitVector(problem.demand_g.tolist())
    routing.AddDimensionWithVehicleCapacity(
        demand, 0, [int(v.payload_capacity_g) for v in problem.vehicles], True, "payload"
    )
    if any(v.energy is not None for v in problem.vehicles):
        zero = np.zeros((n, n), dtype=np.int64)
        routing.AddDimensionWithVehicleTransitAndCapacity(
            [matrix_callback(v.energy if v.energy is not None else zero) for v in problem.vehicles],
            0,
            [int(v.energy_capacity) for v in problem.vehicles],
            True,
            "energy",
        )
    for node in range(1, n):
        routing.AddDisjunction([manager.NodeToIndex(node)], int(problem.drop_penalty))
    return manager, routing
