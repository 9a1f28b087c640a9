"""Routes for several vans from one depot: delivery time windows, shifts, payload and an energy
budget per van, each van with its own costs.

The solver sees integers only; the caller rounds explicitly: seconds for time, grams for
payload, tenths of a watt-hour for energy, and the objective's own unit for the arc costs.
A stop pinned to some vans (:attr:`VehicleSpec.forbidden` of the others) is on one of theirs
or left out. A stop is left out only when no route can take it, never to save cost: OR-Tools pays a
penalty larger than any set of routes costs, PyVRP forgoes a prize larger than serving any
stop costs.

Two engines, each where it is strongest (``benchmarks/bench_fleet.py``):

1. PyVRP's iterated local search (Wouda, Lan & Kool 2024) on windows, shifts and payload: on
   Solomon's instances within a fraction of a percent of the best known routes. A stop with
   several windows is a group of alternatives, one per window. Every stop is required at
   first (its fastest search); when that finds no routes serving them all within
   :data:`REQUIRED_SHARE` of its work, the rest of the work goes to a search with every stop
   optional for a prize, so a partial plan is there. It ends when its iterations and the
   moves they evaluated make its work (:mod:`core.routing.pyvrp_run`) — seeded, so the same
   routes for the same input and effort — or, cut short, at the deadline (where it stopped is
   recorded, for a replay).
2. OR-Tools' routing library with every constraint as a dimension, the energy budget
   included, and the cost of waiting for a window: it takes over PyVRP's routes when they
   break an energy budget (less the stops that do not fit) or when waiting has a cost,
   for its work's solutions (single-threaded: deterministic).
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import pyvrp
from numpy.typing import NDArray
from ortools.constraint_solver import pywrapcp, routing_enums_pb2

from core.routing import pyvrp_run
from core.routing.effort import Effort, SearchEnd, combined

IntMatrix = NDArray[np.int64]

#: Share of PyVRP's work (and of its time) for finding routes that serve every stop before
#: it searches with stops optional.
REQUIRED_SHARE = 0.2
#: PyVRP weighs a second late (its penalties) and a second of waiting (its neighbourhoods)
#: against one unit of cost, with defaults tuned on instances whose arcs cost one per unit of
#: time (Solomon's). It is given costs in units of the square root of what a second of
#: driving costs (:func:`_cost_per_s`), measured in the same runs against PyVRP: in metres
#: against seconds (about 16 m a second) time counted too little and R1_10_1 (tight windows)
#: came 1.5 % longer; at one per second it counted too much and C201 (wide windows, the
#: payload binding) kept three long routes (+2.2 %) where PyVRP finds four shorter; the
#: root between them met PyVRP on both. Fixed costs per van keep their scale: the search
#: that empties a route needs the room. The bounds of the scale [objective units per s]:
_SCALE_BOUNDS = (0.01, 100.0)
#: The searches overshoot their limit by a few milliseconds; they get this much less [s].
_STOP_MARGIN_S = 0.01
#: Longest cap OR-Tools is given [s] (a day): a deadline that never comes is no number it takes.
MAX_CAP_S = 86_400.0


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
    max_reloads
        How often the van may come back to the depot to reload between stops (a 0 in its
        route); its payload is then back to ``payload_capacity_g``.
    reload_s
        How long a reload takes [s].
    start
        The place the van sets off from: the depot (0), or another (its position when it
        is under way; no stop's). It ends at the depot.
    initial_load_g
        What of ``payload_capacity_g`` its first trip cannot take [g] (it set off with less).
    forbidden
        Places the van may not serve (stops pinned to other vans).
    """

    arc_cost: IntMatrix
    energy: IntMatrix | None
    energy_capacity: int
    payload_capacity_g: int
    shift_s: tuple[int, int]
    fixed_cost: int = 0
    wait_cost_per_s: int = 0
    max_reloads: int = 0
    reload_s: int = 0
    start: int = 0
    initial_load_g: int = 0
    forbidden: frozenset[int] = frozenset()


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
    """Stops of each van in driving order (no depot around them; a 0 between stops is a
    return to reload); a stop in no route is left out. ``ended``: how the search stopped."""

    routes: list[list[int]]
    ended: SearchEnd = "work"


def solve_routes(
    problem: RoutingInput,
    effort: Effort,
    initial: list[list[int]] | None = None,
    polish: bool = True,
) -> RoutingOutcome | None:
    """Routes for every van; None when the search finds no solution.

    Parameters
    ----------
    problem
        Places and vans.
    effort
        The search's work (PyVRP's iterations and moves, OR-Tools' solutions), deadline and
        seed: the same routes for the same effort unless the deadline stops the search
        (``ended``).
    initial
        Routes to start from (stops per van); ignored when they break a constraint.
    polish
        Whether OR-Tools takes over PyVRP's routes that break an energy budget; else they are
        trimmed to it (a fleet that will charge: the charging search plans them again).
    """
    # OR-Tools' model has no reloads: routes that reload are PyVRP's, trimmed to the budget.
    reloads = any(v.max_reloads for v in problem.vehicles)
    waits_cost = any(v.wait_cost_per_s for v in problem.vehicles) and not reloads
    found, ended = _pyvrp_routes(problem, effort, initial)
    if found is not None and not waits_cost and not _over_energy(problem, found):
        return RoutingOutcome(found, ended)
    if found is None:
        one_trip = None if initial is None else [[n for n in r if n] for r in initial]
        polished = _ortools_routes(problem, effort, one_trip)
        return (
            None if polished is None else replace(polished, ended=combined([ended, polished.ended]))
        )
    fitting = [_within_energy(problem, v, r) for v, r in enumerate(found)]
    if reloads or not polish:
        return RoutingOutcome(fitting, ended)
    polished = _ortools_routes(problem, effort, fitting)
    # OR-Tools may find less (or reject the start and begin afresh): PyVRP's routes,
    # trimmed, hold.
    if polished is None or _served(polished.routes) < _served(fitting):
        return RoutingOutcome(fitting, ended)
    return replace(polished, ended=combined([ended, polished.ended]))


def _served(routes: list[list[int]]) -> int:
    return sum(len(route) for route in routes)


def route_energy(problem: RoutingInput, v: int, route: list[int]) -> int:
    """Van ``v``'s energy on ``route`` by the solver's matrix (0 without a budget)."""
    energy = problem.vehicles[v].energy
    if energy is None:
        return 0
    order = [problem.vehicles[v].start, *route, 0]
    return int(energy[order[:-1], order[1:]].sum())


def _over_energy(problem: RoutingInput, routes: list[list[int]]) -> bool:
    return any(
        v.energy is not None and route_energy(problem, k, r) > v.energy_capacity
        for k, (v, r) in enumerate(zip(problem.vehicles, routes, strict=True))
    )


def _within_energy(problem: RoutingInput, v: int, route: list[int]) -> list[int]:
    """``route`` less its last stops until it fits van ``v``'s energy budget."""
    capacity = problem.vehicles[v].energy_capacity
    kept = list(route)
    while (
        kept
        and route_energy(problem, v, kept) > capacity
        and problem.vehicles[v].energy is not None
    ):
        kept.pop()
    return trips_tidied(kept, problem.vehicles[v].start != 0)


def trips_of(route: Sequence[int]) -> list[list[int]]:
    """The stops of each trip of ``route`` (split at its returns to reload)."""
    trips: list[list[int]] = [[]]
    for node in route:
        if node:
            trips[-1].append(node)
        else:
            trips.append([])
    return [trip for trip in trips if trip]


def trips_tidied(route: list[int], under_way: bool = False) -> list[int]:
    """``route`` without returns to reload that have no stop after them (or before, unless
    the van is ``under_way``: it may reload before its first stop)."""
    kept: list[int] = []
    for node in route:
        if node or (kept and kept[-1]) or (under_way and not kept):
            kept.append(node)
    while kept and not kept[-1]:
        kept.pop()
    return kept


@dataclass(frozen=True)
class _PyvrpModel:
    """The problem as PyVRP's data: each client's place, and the vans of each vehicle type."""

    data: pyvrp.ProblemData
    client_node: list[int]
    node_clients: dict[int, list[int]]
    type_vans: list[list[int]]


def _kind(vehicle: VehicleSpec) -> tuple[object, ...]:
    return (
        id(vehicle.arc_cost),
        vehicle.payload_capacity_g,
        vehicle.shift_s,
        vehicle.max_reloads,
        vehicle.reload_s,
        vehicle.start,
        vehicle.initial_load_g,
        vehicle.forbidden,
    )


def _pyvrp_model(problem: RoutingInput, required: bool) -> _PyvrpModel:
    """Vans alike but for their order share a vehicle type (the search breaks the symmetry
    itself; the first-listed vans get the routes); a place with several windows is a group of
    clients, one per window, of which the route visits one. Every stop ``required``, or
    optional for a prize (:func:`_prize`)."""
    n = problem.travel_s.shape[0]
    large_fixed = max((v.fixed_cost for v in problem.vehicles), default=0) > len(problem.vehicles)
    scale = _cost_scale(problem, large_fixed)

    def above_routes(cost: int) -> int:
        # a cost above any set of routes stays above them once each arc's is rounded
        return math.ceil(cost / scale) + n + len(problem.vehicles)

    prize = _prize(problem, scale, large_fixed)

    locations = [pyvrp.Location(0.0, 0.0) for _ in range(n)]
    clients, client_node, node_clients, groups = _pyvrp_clients(problem, required, prize)
    # A large fixed cost keeps vans home; the small steps between the vans' fixed costs only
    # say the first-listed drive first, which the order of a type's vans says as well. One
    # type for vans alike but for those steps: 25 types of one van each found a van more on
    # Solomon's RC101 than one type of 25 (PyVRP's route operators work within a type).
    kinds: dict[tuple[object, ...], list[int]] = {}
    for v, vehicle in enumerate(problem.vehicles):
        kinds.setdefault(_kind(vehicle), []).append(v)
    # a profile per cost matrix and set of places a van may not serve: those are driven to
    # past the horizon, which no route that keeps its windows does
    travel = np.asarray(problem.travel_s, dtype=np.int64)
    matrices: dict[tuple[int, frozenset[int]], int] = {}
    distance_matrices: list[IntMatrix] = []
    duration_matrices: list[IntMatrix] = []
    vehicle_types = []
    depots, start_depot, reload_depot = _pyvrp_depots(problem)
    for vans in kinds.values():
        vehicle = problem.vehicles[vans[0]]
        key = (id(vehicle.arc_cost), vehicle.forbidden)
        if key not in matrices:
            matrices[key] = len(distance_matrices)
            distance_matrices.append(np.rint(vehicle.arc_cost / scale).astype(np.int64))
            duration = travel.copy()
            duration[:, sorted(vehicle.forbidden)] = problem.horizon_s + 1
            np.fill_diagonal(duration, np.diag(travel))
            duration_matrices.append(duration)
        first, last = (int(t) for t in vehicle.shift_s)
        vehicle_types.append(
            pyvrp.VehicleType(
                num_available=len(vans),
                capacity=[int(vehicle.payload_capacity_g)],
                fixed_cost=above_routes(vehicle.fixed_cost) if large_fixed else 0,
                tw_early=first,
                tw_late=last,
                profile=matrices[key],
                reload_depots=[reload_depot[vehicle.reload_s]] if vehicle.max_reloads else [],
                max_reloads=vehicle.max_reloads,
                start_depot=start_depot[vehicle.start],
                initial_load=[int(vehicle.initial_load_g)],
            )
        )
    data = pyvrp.ProblemData(
        locations,
        clients,
        depots,
        vehicle_types,
        distance_matrices,  # type: ignore[arg-type]  # PyVRP's stubs name ndarray[int]
        duration_matrices,  # type: ignore[arg-type]
        groups,
    )
    return _PyvrpModel(data, client_node, node_clients, list(kinds.values()))


def _pyvrp_clients(
    problem: RoutingInput, required: bool, prize: int
) -> tuple[list[pyvrp.Client], list[int], dict[int, list[int]], list[pyvrp.ClientGroup]]:
    """PyVRP's clients: one per window of each place a van can serve (a group of them when it
    has several, of which a route visits one), required or for ``prize``; the place of each,
    and the clients of each place."""
    horizon = int(problem.horizon_s)
    never = horizon + 1
    clients: list[pyvrp.Client] = []
    client_node: list[int] = []
    node_clients: dict[int, list[int]] = {}
    groups: list[pyvrp.ClientGroup] = []
    for node in range(1, problem.travel_s.shape[0]):
        windows = problem.windows_s[node] or [(0, horizon)]
        if windows[0][0] >= never:  # no van can ever serve it (or a van sets off there)
            continue
        members = []
        for opens, closes in windows:
            members.append(len(clients))
            clients.append(
                pyvrp.Client(
                    location=node,
                    delivery=[int(problem.demand_g[node])],
                    service_duration=int(problem.service_s[node]),
                    tw_early=int(opens),
                    tw_late=int(closes),
                    prize=0 if required else prize,
                    required=required and len(windows) == 1,
                    group=len(groups) if len(windows) > 1 else None,
                )
            )
            client_node.append(node)
        if len(windows) > 1:
            groups.append(pyvrp.ClientGroup(members, required=required))
        node_clients[node] = members
    return clients, client_node, node_clients, groups


def _pyvrp_depots(
    problem: RoutingInput,
) -> tuple[list[pyvrp.Depot], dict[int, int], dict[int, int]]:
    """The depot to start and end at, the vans' positions under way, then one at the depot's
    place per reload time (its service); the depot each start place and reload time is."""
    horizon = int(problem.horizon_s)
    depots = [pyvrp.Depot(location=0, tw_early=0, tw_late=horizon)]
    start_depot: dict[int, int] = {0: 0}
    for vehicle in problem.vehicles:
        if vehicle.start not in start_depot:
            start_depot[vehicle.start] = len(depots)
            depots.append(pyvrp.Depot(location=vehicle.start, tw_early=0, tw_late=horizon))
    reload_depot: dict[int, int] = {}
    for vehicle in problem.vehicles:
        if vehicle.max_reloads and vehicle.reload_s not in reload_depot:
            reload_depot[vehicle.reload_s] = len(depots)
            depots.append(
                pyvrp.Depot(
                    location=0, tw_early=0, tw_late=horizon, service_duration=vehicle.reload_s
                )
            )
    return depots, start_depot, reload_depot


def _cost_per_s(problem: RoutingInput) -> float:
    """What the arcs cost per second of driving, on average over the arcs that exist and the
    vans' cost matrices, within :data:`_SCALE_BOUNDS`."""
    exists = problem.travel_s <= problem.horizon_s
    driving = float(problem.travel_s[exists].mean()) if exists.any() else 0.0
    costs = {id(v.arc_cost): v.arc_cost for v in problem.vehicles}.values()
    cost = float(np.mean([matrix[exists].mean() for matrix in costs])) if costs else 0.0
    if driving <= 0 or cost <= 0:
        return 1.0
    return float(np.clip(cost / driving, *_SCALE_BOUNDS))


def _prize(problem: RoutingInput, scale: float, large_fixed: bool) -> int:
    """Every stop's prize when stops are optional, in PyVRP's costs: more than serving any
    stop can add to a route (the dearest arcs in and out of a place), and than a van when vans
    have a fixed cost — so a stop is left out only where serving it breaks a rule, and the
    same for every stop, so the most are served. A prize above every route
    (:attr:`RoutingInput.drop_penalty`) would be worth more than any penalty PyVRP reaches
    for breaking a rule, and its search would never leave a stop out."""
    exists = problem.travel_s <= problem.horizon_s
    costs = {id(v.arc_cost): np.where(exists, v.arc_cost, 0) for v in problem.vehicles}
    dearest = max(int((m.max(axis=0) + m.max(axis=1)).max()) for m in costs.values())
    fixed = max(v.fixed_cost for v in problem.vehicles) if large_fixed else 0
    return math.ceil((dearest + fixed) / scale) + 2


def _cost_scale(problem: RoutingInput, large_fixed: bool) -> float:
    """What PyVRP's costs are divided by: see :data:`_SCALE_BOUNDS`."""
    return 1.0 if large_fixed else math.sqrt(_cost_per_s(problem))


def _pyvrp_routes(
    problem: RoutingInput, effort: Effort, initial: list[list[int]] | None
) -> tuple[list[list[int]] | None, SearchEnd]:
    """PyVRP's best feasible routes per van after the effort's work; None when it has
    none; and how it stopped. Every stop required first; optional after
    :data:`REQUIRED_SHARE` of the work or of the time left without routes that serve them
    all."""
    if effort.watch().passed(0):
        return None, "time_limit"
    model = _pyvrp_model(problem, required=True)
    if not model.client_node:
        return [[] for _ in problem.vehicles], "work"
    give_up = (REQUIRED_SHARE, effort.within(REQUIRED_SHARE))
    start = _pyvrp_start(model, initial)
    result, stop = pyvrp_run.solve(model.data, effort, initial=start, give_up=give_up)
    if stop.gave_up:
        model = _pyvrp_model(problem, required=False)
        rest = effort.share(stop.left_share())
        start = _pyvrp_start(model, initial)
        result, stop = pyvrp_run.solve(model.data, rest, optional=True, initial=start)
    routes: list[list[int]] = [[] for _ in problem.vehicles]
    taken = [0] * len(model.type_vans)
    for route in result.best.routes():
        kind = route.vehicle_type()
        van = model.type_vans[kind][taken[kind]]
        taken[kind] += 1
        visits = route.schedule()[1:-1]
        routes[van] = [model.client_node[a.idx] if a.is_client() else 0 for a in visits]
    if not result.is_feasible():  # the best it found, less the stops that break a rule
        routes = [_kept(problem, v, route) for v, route in enumerate(routes)]
    return routes, stop.ended


def _kept(problem: RoutingInput, v: int, route: list[int]) -> list[int]:
    """Van ``v``'s ``route`` with only the stops it serves in order within their windows and
    its payload, back by the end of its shift and within its energy budget: a partial route
    from an infeasible one."""
    vehicle = problem.vehicles[v]
    first, last = vehicle.shift_s
    clock, place = float(first), vehicle.start
    load = vehicle.initial_load_g
    kept: list[int] = []
    for node in route:
        arrive = clock + problem.service_s[place] + problem.travel_s[place, node]
        if not node:  # back to reload: its time is the reload's
            clock, place, load = arrive + vehicle.reload_s, 0, 0
            kept.append(0)
            continue
        opens = _opening(problem.windows_s[node], arrive)
        too_heavy = load + problem.demand_g[node] > vehicle.payload_capacity_g
        if opens is None or too_heavy or node in vehicle.forbidden:
            continue
        clock, place, load = max(arrive, opens), node, load + int(problem.demand_g[node])
        kept.append(node)
    kept = trips_tidied(kept, vehicle.start != 0)
    while kept and _back_s(problem, v, kept) > last:
        kept = trips_tidied(kept[:-1], vehicle.start != 0)
    return _within_energy(problem, v, kept)


def _opening(windows: list[tuple[int, int]], arrive: float) -> float | None:
    """When service may start at a place reached at ``arrive`` [s]; None when every window
    has closed (no window: at once)."""
    if not windows:
        return arrive
    return next((max(arrive, a) for a, b in windows if arrive <= b), None)


def _back_s(problem: RoutingInput, v: int, route: list[int]) -> float:
    """When van ``v`` is back at the depot after ``route`` [s], waiting for every window."""
    vehicle = problem.vehicles[v]
    clock, place = float(vehicle.shift_s[0]), vehicle.start
    for node in route:
        clock += problem.service_s[place] + problem.travel_s[place, node]
        if node:
            opens = _opening(problem.windows_s[node], clock)
            clock = math.inf if opens is None else opens
        else:
            clock += vehicle.reload_s
        place = node
    return clock + problem.service_s[place] + problem.travel_s[place, 0]


def _pyvrp_start(model: _PyvrpModel, initial: list[list[int]] | None) -> pyvrp.Solution | None:
    """``initial`` as a PyVRP solution (each stop in its first window); None without it."""
    if initial is None:
        return None
    van_type = {van: kind for kind, vans in enumerate(model.type_vans) for van in vans}
    routes = []
    for v, route in enumerate(initial):
        kind = van_type[v]
        reload = model.data.vehicle_type(kind).reload_depots
        nodes = [n for n in route if n in model.node_clients or (not n and reload)]
        under_way = model.data.vehicle_type(kind).start_depot != 0
        activities = [
            pyvrp.Activity(pyvrp.ActivityType.CLIENT, model.node_clients[node][0])
            if node
            else pyvrp.Activity(pyvrp.ActivityType.DEPOT, reload[0])
            for node in trips_tidied(nodes, under_way)
        ]
        if activities:
            routes.append(pyvrp.Route(model.data, activities, kind))
    return pyvrp.Solution(model.data, routes)


def _ortools_routes(
    problem: RoutingInput, effort: Effort, initial: list[list[int]] | None
) -> RoutingOutcome | None:
    """OR-Tools' guided local search with every dimension, from ``initial`` when it holds; its
    work the effort's solutions (single-threaded: deterministic), the effort's deadline the
    cap."""
    manager, routing = _model(problem)
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
    params.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    # its own time limit stops it; the solutions it found by then are the record to replay
    watch = effort.keeping(_STOP_MARGIN_S).watch()
    if watch.passed(0):
        return None
    replayed = watch.replayed_at()
    if replayed == 0:  # cut before its first solution
        return None
    limit = effort.ortools_solutions(problem.travel_s.shape[0])
    params.solution_limit = limit if replayed is None else replayed
    budget_s = min(effort.left_s() - _STOP_MARGIN_S, MAX_CAP_S)
    params.time_limit.FromMilliseconds(max(int(budget_s * 1000), 1))
    routing.CloseModelWithParameters(params)
    found, started = [0], time.perf_counter()
    routing.AddAtSolutionCallback(lambda: found.__setitem__(0, found[0] + 1))
    solution = None
    if initial is not None:
        start = routing.ReadAssignmentFromRoutes(
            [[manager.NodeToIndex(node) for node in route] for route in initial], True
        )
        if start is not None:
            solution = routing.SolveFromAssignmentWithParameters(start, params)
    if solution is None:
        found[0] = 0
        solution = routing.SolveWithParameters(params)
    # fewer solutions than its limit, and (near enough) all its time: its time limit cut it
    if found[0] < params.solution_limit and time.perf_counter() - started >= budget_s * 0.9:
        watch.mark(found[0])
    ended: SearchEnd = "time_limit" if watch.passed(found[0]) else "work"
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
    return RoutingOutcome(routes, ended)


def _model(problem: RoutingInput) -> tuple[pywrapcp.RoutingIndexManager, pywrapcp.RoutingModel]:
    """The routing model: each van's arc costs and fixed cost; the time, payload and energy
    dimensions; a disjunction per stop, and the vans a stop pinned to some may have."""
    n = problem.travel_s.shape[0]
    starts = [v.start for v in problem.vehicles]
    manager = pywrapcp.RoutingIndexManager(n, len(problem.vehicles), starts, [0] * len(starts))
    stops = [node for node in range(1, n) if node not in starts]
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
    for node in stops:
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
        demand,
        0,
        [int(v.payload_capacity_g - v.initial_load_g) for v in problem.vehicles],
        True,
        "payload",
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
    for node in stops:
        routing.AddDisjunction([manager.NodeToIndex(node)], int(problem.drop_penalty))
        allowed = [v for v, vehicle in enumerate(problem.vehicles) if node not in vehicle.forbidden]
        if len(allowed) < len(problem.vehicles):  # -1: left out (SetAllowedVehiclesForIndex's
            # binding takes no Python list in OR-Tools 9.15)
            routing.VehicleVar(manager.NodeToIndex(node)).SetValues([-1, *allowed])
    return manager, routing
