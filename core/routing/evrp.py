"""Vehicle routing with recharging stations and time windows, partial recharge (E-VRPTW-PR of
Schneider, Stenger & Goeke, *Transportation Science* 48 (2014) 500; Keskin & Çatay,
*Transportation Research C* 65 (2016) 111): every customer served if the fleet can, then
fewest vehicles (when asked), then least cost.

A vehicle's battery falls by the energy of each arc it drives and rises at a station by what
it charges there, at a time per unit of energy; it never falls below its floor nor rises above
its capacity. Customers are served once inside their windows (waiting allowed) within the
load capacity. The fleet is of kinds (:class:`VehicleKind`): how many, where each sets off
and when, by when it is back, its battery, the energy of each arc for it and the customers it
may not serve (pinned to others).

1. **Routes of customers**: given (a planner's routes without charging), or PyVRP's routes of
   the customers alone, with windows and load, its arc times lengthened by
   :data:`CHARGE_TIME_SHARES` of the time the arc's energy takes to charge (charging is time a
   route must find room for), and without it.
2. **Stations on a route** (:mod:`core.routing.stations`): for a fixed order of customers, the
   stations between them and how much to charge at each, by labels; a station takes no
   charge while it is closed. **Shared points**: at a station with fewer points than the
   fleet has vehicles, the routes book them in the order of their first charge there — each
   waits for a point the routes before it leave free, or charges elsewhere
   (:meth:`_Priced.booked`) —, and every solution the search keeps is booked so.
3. **Search** on work — the routes screened and evaluated, the labels' steps and the moves
   (:data:`SCREEN_S`, :data:`EVALUATION_S`, :data:`LOOK_S`, :data:`WALK_S`, :data:`MOVE_S`) —
   capped by the deadline (Numba evaluates, Python searches). A route is screened before its
   labels: its load, and its windows on the quickest ways between its places, through a
   station or not (:func:`~core.routing.stations.keeps_windows`; most routes a search tries on
   a day of tight windows fail there, at a fraction of the labels' time). The
   customers of a route that cannot be charged are inserted where they cost least (left out
   when no vehicle can take them); then, in turn, a vehicle less — the route with the fewest
   customers emptied into the others through an ejection pool (Nagata & Bräysy 2009: a
   customer that fits nowhere goes in by taking out the customer of that route that failed
   least often, which goes back into the pool; a ruin-and-recreate move after each; undone
   when the attempt's work runs out) — and the cost: ruin and recreate (a few nearby
   customers out, or strings of consecutive customers out of nearby routes as in SISR,
   Christiaens & Vanden Berghe 2020; each back where it costs least in one of SISR's orders,
   only into routes that hold one of its :data:`NEIGHBOURS` nearest; the customers left out
   tried again), kept when at most a falling threshold worse (a route it empties is a
   vehicle less too). Last, the routes polished: a stretch turned round
   (2-opt), two routes' ends exchanged (2-opt*), while that is cheaper. The
   :data:`SEARCHED_STARTS` best starts are each searched so, the better kept.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np
import pyvrp
from numpy.typing import NDArray

from core.arrays import FloatArray
from core.routing import pyvrp_run
from core.routing.effort import Effort, SearchEnd
from core.routing.points import Closed, Span, full_spans
from core.routing.pyvrp_run import above_routes
from core.routing.stations import (
    NO_ROUTE,
    Charged,
    RouteFacts,
    Visit,
    keeps_windows,
    quickest_durations,
    route_with_stations,
    station_candidates,
)

#: Shares of the charging time of an arc's energy that step 1 adds to the arc's time: routes
#: found with part of it leave room for charging where windows are tight; routes found without
#: it are the shortest where the day has room to charge anyway (each a start of its own).
CHARGE_TIME_SHARES = (0.5, 0.0)
#: Share of the work for step 1.
ROUTING_SHARE = 0.15
#: The search's work [reference s]: this much per route screened (its load and windows), per
#: route evaluated (with its stations), per station its labels look at and per place they walk
#: past (a label drives on through the places of the route its battery reaches, to each of
#: their stations, walking the windows from the label's place to each: long routes with few
#: charges cost more per evaluation than their size says), and per ruin-and-recreate move
#: beyond those (its insertions' bounds and the remembered routes, which cost little but are
#: not free: a small instance whose routes are all remembered still ends). Fitted by least
#: squares on the time of each phase (the searches, the polish) of ten of Schneider et al.'s
#: instances (c101, c108, c201, r102, r110, r201, r211, rc103, rc201, rc208) and the Vienna
#: day with chargers (2 routes of 40 stops) on the reference machine, twice each: 0.7–1.3 s a
#: second of work, the run-to-run noise of the same work on it (±30 %).
SCREEN_S = 6e-6
EVALUATION_S = 1.8e-5
LOOK_S = 5.8e-8
WALK_S = 3.5e-9
MOVE_S = 9e-4
#: PyVRP's integers: costs and times this many per unit.
_SCALE = 1000
#: Customers taken out and put back by one ruin-and-recreate move: at most (nearest to a
#: customer), or strings of consecutive customers out of nearby routes (:data:`STRING_SHARE` of
#: the moves; on average :data:`STRING_MEAN` out, strings at most :data:`STRING_MOST` long).
RUIN_SIZE = 14
STRING_SHARE = 0.5
STRING_MEAN = 10
STRING_MOST = 10
#: Share of the moves that ruin the routes around a customer left out, when one is (it goes
#: back first, into the room made; put back only where its neighbours were, a customer the
#: starting routes left out could stay out: E-VRPTW's rc108, C19, whose round alone needs a
#: charge the day has no time for).
LEFT_SEED_SHARE = 0.5
#: How often the customers go back at random, the largest demand first, the farthest from the
#: depot first, the nearest first (SISR's weights 4, 4, 2, 1).
RECREATE_ORDERS = (4 / 11, 4 / 11, 2 / 11, 1 / 11)
#: A customer is inserted only into routes that hold one of its this many nearest customers
#: (a granular neighbourhood, Toth & Vigo 2003).
NEIGHBOURS = 15
#: Route evaluations remembered (then forgotten all at once).
MEMO_SIZE = 1_000_000
#: Emptying a route into the others: the share of the work left one attempt may take, and
#: the most of the search's work all attempts may take together (a fleet that cannot lose a
#: vehicle leaves the rest to the cost). From 0.1 and 0.2 (and lateness penalised instead of
#: an ejection pool) to these: E-VRPTW r1 at a 60 s request's work from 1.22 vans over the
#: best known on average to 0.78 (docs/benchmarks.md).
ELIMINATION_SHARE = 0.25
ELIMINATION_BUDGET = 0.5
#: Ruin-and-recreate moves on the cost between two attempts to empty a route; the most a
#: move may worsen the cost at first [share]; rounds between attempts at a vehicle less once
#: every route has had its turn.
DISTANCE_MOVES = 100
START_THRESHOLD = 0.02
#: Share of the search's work for the last step, the routes' polish (2-opt and 2-opt*).
POLISH_SHARE = 0.05
#: The best starts searched, each with its share of the work, the better kept: which local
#: optimum one search ends in swings with its start (the Vienna day of the benchmark at 60 s,
#: seeds 0–5: 430–453 km searching the best start alone, 430–435 km searching two).
SEARCHED_STARTS = 2
ELIMINATION_EVERY = 10


@dataclass(frozen=True)
class VehicleKind:
    """Vehicles alike: how many, the energy each arc takes them, their battery (the most it
    holds above its floor, and what it holds at departure), their load capacity, the place
    they set off from, their earliest departure and latest return to the depot; what their
    first trip may deliver (less when they set off loaded in part), and for vehicles that come
    back to reload, the place that return is (the depot's row, its service the reload's time)
    and their most trips; the time to charge one unit of energy at each place for them (their
    charging curve; None: the instance's); the customers they may not serve (pinned to other
    vehicles)."""

    count: int
    energy: FloatArray
    battery: float
    initial: float
    capacity: float
    start: int = 0
    ready: float = 0.0
    due: float = math.inf
    aboard: float = math.inf
    reload: int = -1
    max_trips: int = 1
    charge_time: FloatArray | None = None
    forbidden: frozenset[int] = frozenset()

    def trips_carried(self, demand: FloatArray, route: Sequence[int]) -> bool:
        """Whether ``route`` (customers, :attr:`reload` between trips) keeps to the trips and
        each trip's load."""
        limit, load, trips = min(self.aboard, self.capacity), 0.0, 1
        for place in route:
            if place == self.reload:
                limit, load, trips = self.capacity, 0.0, trips + 1
            else:
                load += float(demand[place])
                if load > limit + 1e-9:
                    return False
        return trips <= self.max_trips

    def tidied(self, route: list[int]) -> list[int]:
        """``route`` without returns to reload that end it, follow another or begin it (a
        vehicle under way may come back to reload first)."""
        if self.reload < 0 or self.reload not in route:
            return route
        out: list[int] = []
        for place in route:
            if place == self.reload and (out[-1:] == [self.reload] or (not out and not self.start)):
                continue
            out.append(place)
        while out and out[-1] == self.reload:
            out.pop()
        return out


@dataclass(frozen=True)
class EvrpInstance:
    """The places (index 0 the depot, then any others: customers, stations, the vehicles'
    positions) and the fleet.

    Attributes
    ----------
    distance, duration
        Cost (the objective) and travel time of each arc.
    ready, due, service, demand
        Each place's window, service time (at a station: the time to plug in and out) and
        demand (0 at the depot and the stations).
    customers, stations
        The customers' and the stations' indices.
    charge_time
        Time to charge one unit of energy at each place (finite; read at the stations), for
        the kinds that do not say their own.
    kinds
        The fleet.
    fewest_vehicles
        Fewest vehicles before the least cost.
    points
        The stations where fewer vehicles than the fleet's can charge at once: how many.
    closed
        When stations take no charge (by station; none: always open).
    """

    distance: FloatArray
    duration: FloatArray
    ready: FloatArray
    due: FloatArray
    service: FloatArray
    demand: FloatArray
    customers: list[int]
    stations: list[int]
    charge_time: FloatArray
    kinds: list[VehicleKind]
    fewest_vehicles: bool = True
    points: dict[int, int] = field(default_factory=dict)
    closed: dict[int, list[Span]] = field(default_factory=dict)

    def charge_time_of(self, kind: int) -> FloatArray:
        """Time to charge one unit of energy at each place for vehicles of ``kind``."""
        own = self.kinds[kind].charge_time
        return self.charge_time if own is None else own


Routes = list[tuple[int, list[int]]]


@dataclass(frozen=True)
class EvrpRoute:
    """A vehicle of kind ``kind`` driving ``visits`` (start first, depot last, stations with
    their charges)."""

    kind: int
    visits: list[Visit]


@dataclass(frozen=True)
class EvrpSolution:
    """The routes, their total cost, the customers no vehicle could take, how the search
    ended, and the routes as the search holds them (kind, customers and returns to reload:
    a start to search on from)."""

    routes: list[EvrpRoute]
    distance: float
    left_out: list[int]
    ended: SearchEnd = "work"
    searched: Routes = field(default_factory=list)

    @property
    def vehicles(self) -> int:
        return len(self.routes)


def solve_evrptw(
    instance: EvrpInstance, effort: Effort, initial: Routes | None = None, own: bool = True
) -> EvrpSolution:
    """Every customer served if the fleet can, then fewest vehicles (``fewest_vehicles``),
    then the least cost, in ``effort``'s work: from the :data:`SEARCHED_STARTS` best starts
    of ``initial`` routes (kind, customers) and, with ``own``, PyVRP's (step 1, when every
    vehicle sets off from the depot: it sees part of the charging time, routes found without
    may not), each searched with its share of the work, the better kept and polished."""
    starts = [] if initial is None else [initial]
    routing = own and all(kind.start == 0 for kind in instance.kinds)
    if routing:
        share = ROUTING_SHARE / len(CHARGE_TIME_SHARES)
        starts += [_customer_routes(instance, effort.share(share), c) for c in CHARGE_TIME_SHARES]
    if not starts:
        raise ValueError("routes of customers for vehicles under way must be given")
    searches = []
    for routes in starts:
        searches.append(_Search(instance, np.random.default_rng(effort.seed)))
        searches[-1].start(routes)
    searched = sorted(searches, key=lambda s: s.total())[:SEARCHED_STARTS]
    routing_share = ROUTING_SHARE if routing else 0.0
    work_s = effort.work_s * (1.0 - routing_share - POLISH_SHARE) / len(searched)
    ended: SearchEnd = "work"
    for search in searched:
        ended = search.improve(work_s, effort)
        search.restore_best()
        if ended == "time_limit":
            break
    search = min(searched, key=lambda s: s.total())
    if ended == "work":
        ended = search.polish(effort.work_s * POLISH_SHARE, effort)
    return search.solution(ended)


def _customer_routes(instance: EvrpInstance, effort: Effort, charge_share: float) -> Routes:
    """Step 1: PyVRP's routes of the customers, ``charge_share`` of the charging time in the
    arcs (the first kind's energy), every kind a vehicle type of its own."""
    customers = instance.customers
    nodes = [0, *customers]
    arcs = np.ix_(nodes, nodes)
    distance = np.rint(instance.distance[arcs] * _SCALE).astype(np.int64)
    stations = instance.stations or [0]
    charge = float(np.mean(instance.charge_time[stations])) * charge_share
    arc_time = instance.duration[arcs] + charge * instance.kinds[0].energy[arcs]
    duration = np.rint(arc_time * _SCALE).astype(np.int64)
    for matrix in (distance, duration):  # staying put: an energy per arc may count a stop's
        np.fill_diagonal(matrix, 0)  # service on every arc out of it, the way back to itself too
    horizon = float(instance.due[0])
    durations = []  # each kind's: driving to a customer it may not serve takes past the horizon
    for kind in instance.kinds:
        own = duration.copy()
        own[:, [k for k, c in enumerate(customers, start=1) if c in kind.forbidden]] = round(
            (horizon + 1) * _SCALE
        )
        np.fill_diagonal(own, 0)
        durations.append(own)
    clients = [
        pyvrp.Client(
            location=k,
            delivery=[round(instance.demand[c])],
            service_duration=round(instance.service[c] * _SCALE),
            tw_early=round(instance.ready[c] * _SCALE),
            tw_late=round(instance.due[c] * _SCALE),
        )
        for k, c in enumerate(customers, start=1)
    ]
    types = [
        pyvrp.VehicleType(
            num_available=min(kind.count, len(customers)),
            capacity=[math.floor(kind.capacity)],
            fixed_cost=above_routes(distance, len(customers)) if instance.fewest_vehicles else 0,
            tw_early=round(kind.ready * _SCALE),
            tw_late=round(min(kind.due, horizon) * _SCALE),
            profile=k,
        )
        for k, kind in enumerate(instance.kinds)
    ]
    data = pyvrp.ProblemData(
        [pyvrp.Location(0.0, 0.0) for _ in nodes],
        clients,
        [pyvrp.Depot(location=0, tw_early=0, tw_late=round(horizon * _SCALE))],
        types,
        [distance] * len(durations),  # type: ignore[list-item]  # PyVRP's stubs: ndarray[int]
        durations,
    )
    result, _ = pyvrp_run.solve(data, effort)
    return [
        (route.vehicle_type(), [customers[v.idx] for v in route.schedule() if v.is_client()])
        for route in result.best.routes()
    ]


class _Priced:
    """What each route (kind, customers) costs with its stations, memoised, with the
    stations closed when they are (:meth:`booked`: the points the others take too); the routes
    screened and evaluated, and the evaluations' sizes, the work they stand for."""

    def __init__(self, instance: EvrpInstance) -> None:
        self.instance = instance
        self.evaluations = 0
        self.steps = np.zeros(2, dtype=np.int64)  # stations looked at, places walked
        self.screened = 0
        self.memo: dict[tuple[object, ...], Charged] = {}
        self.facts = [_facts(instance, k) for k in range(len(instance.kinds))]
        stations = np.array(instance.stations, np.int64)
        self.candidates = station_candidates(instance.distance, stations)
        self.quickest = quickest_durations(instance.duration, self.candidates)
        self.size = len(instance.distance)
        self.closed = Closed.of(instance.closed, self.size)

    def charged(self, kind: int, route: list[int], closed: Closed | None = None) -> Charged:
        closed = closed or self.closed
        key = (kind, tuple(route), closed.key)
        if key not in self.memo:
            if len(self.memo) > MEMO_SIZE:
                self.memo.clear()
            self.memo[key] = self._evaluated(kind, route, closed)
        return self.memo[key]

    def booked(self, routes: Routes) -> list[Charged]:
        """Each of ``routes`` with its stations, the points of the stations with few shared:
        in the order of their first charge at one, each route charges where and when the
        routes before it leave a point free (waiting for one, or at another station)."""
        free = [self.charged(k, r) for k, r in routes]
        shared = self.instance.points
        if not shared:
            return free
        firsts = {r: c.plugged_at(shared) for r, c in enumerate(free)}
        using = sorted((min(t for _, t, _ in f), r) for r, f in firsts.items() if f)
        if len(using) < 2:
            return free
        taken: dict[int, list[Span]] = {s: [] for s in shared}
        out = list(free)
        for _, r in using:
            full = {s: full_spans(spans, shared[s]) for s, spans in taken.items()}
            if any(full.values()):
                for s, spans in self.instance.closed.items():
                    full[s] = full.get(s, []) + spans
                out[r] = self.charged(*routes[r], Closed.of(full, self.size))
            for s, a, b in out[r].plugged_at(shared):
                taken[s].append((a, b))
        return out

    def _evaluated(self, kind: int, route: list[int], closed: Closed) -> Charged:
        vehicle = self.instance.kinds[kind]
        route = vehicle.tidied(route)
        seq = np.array([vehicle.start, *route, 0], dtype=np.int64)
        self.screened += 1
        carried = vehicle.trips_carried(self.instance.demand, route)
        if not carried or not vehicle.forbidden.isdisjoint(route):
            return NO_ROUTE
        f = self.facts[kind]
        if not keeps_windows(seq, self.quickest, f.ready, f.due, f.service, f.start_time):
            return NO_ROUTE
        self.evaluations += 1
        load = float(self.instance.demand[seq].sum())
        cost, gaps, charges, plugged = route_with_stations(
            f, seq, self.candidates, closed, self.steps
        )
        if not math.isfinite(cost):
            return NO_ROUTE
        return Charged(float(cost), load, seq, gaps, charges, plugged)

    def cost(self, kind: int, route: list[int]) -> float:
        """The route's cost with its stations; infinite when it cannot hold."""
        return self.charged(kind, route).distance


@dataclass(frozen=True)
class _Shape:
    """A route as :meth:`_Solution._bounds` sees it: its places, load, the ends of its arcs
    (start to depot), their lengths, and what its stations add to them."""

    members: frozenset[int]
    load: float
    head: NDArray[np.int64]
    tail: NDArray[np.int64]
    arcs: FloatArray
    spare: float


class _Solution:
    """The routes (kind, customers) and the customers left out, on their prices
    (:class:`_Priced`): what they cost together, and where a customer goes in."""

    def __init__(self, instance: EvrpInstance) -> None:
        self.instance = instance
        self.routes: Routes = []
        self.left: list[int] = []
        self.priced = _Priced(instance)
        self.is_customer = frozenset(instance.customers)
        self.charged = self.priced.charged
        self.cost = self.priced.cost
        self._booked: tuple[object, list[Charged]] = (None, [])
        self._shapes: dict[tuple[int, tuple[int, ...]], _Shape] = {}
        inst = instance
        self.nearest = np.argsort(
            inst.distance[np.ix_(inst.customers, inst.customers)], axis=1, kind="stable"
        )
        self.near = {
            c: {inst.customers[k] for k in self.nearest[n][1 : NEIGHBOURS + 1]}
            for n, c in enumerate(inst.customers)
        }
        self.position = {c: n for n, c in enumerate(inst.customers)}
        # a customer pinned to a few vehicles joins their routes, neighbours there or not
        self.pinned = frozenset().union(*(kind.forbidden for kind in inst.kinds))

    def booked(self) -> list[Charged]:
        """The routes with their stations, the shared points booked (:meth:`_Priced.booked`;
        remembered for the last routes)."""
        key = tuple((k, tuple(r)) for k, r in self.routes)
        if self._booked[0] != key:
            self._booked = (key, self.priced.booked(self.routes))
        return self._booked[1]

    def holds(self) -> bool:
        return all(math.isfinite(c.distance) for c in self.booked())

    def total(self) -> tuple[int, int, float]:
        """Customers left out, vehicles (when they count), cost."""
        vehicles = len(self.routes) if self.instance.fewest_vehicles else 0
        return len(self.left), vehicles, sum(c.distance for c in self.booked())

    def _customers(self, route: list[int]) -> list[int]:
        """The customers of ``route`` (not its returns to reload)."""
        return [c for c in route if c in self.is_customer]

    def spare(self, kind: int) -> bool:
        """Whether a vehicle of ``kind`` is not driving yet."""
        used = sum(1 for k, _ in self.routes if k == kind)
        return used < self.instance.kinds[kind].count

    def start(self, routes: Routes) -> None:
        """The routes that hold (within each kind's count; together, on the shared points:
        else customers out of the first that does not, the farthest first); the customers of
        those that do not, inserted where best."""
        left: list[int] = []
        for kind, customers in routes:
            route = list(customers)
            if not self.spare(kind):
                left.extend(route)
                continue
            while self._customers(route) and math.isinf(self.cost(kind, route)):
                # the customer whose leaving makes the route hold at the least cost, else
                # the one farthest out
                within = self._customers(route)
                shorter = [(self.cost(kind, [x for x in route if x != c]), c) for c in within]
                fits = [sc for sc in shorter if math.isfinite(sc[0])]
                if fits:
                    worst = min(fits)[1]
                else:
                    worst = max(within, key=lambda c: self.instance.distance[0, c])
                route.remove(worst)
                left.append(worst)
            if self._customers(route):
                self.routes.append((kind, route))
        while not self.holds():
            r = next(r for r, c in enumerate(self.booked()) if math.isinf(c.distance))
            kind, route = self.routes[r]
            worst = max(self._customers(route), key=lambda c: self.instance.distance[0, c])
            self.routes[r] = (kind, [c for c in route if c != worst])
            self.routes = [(k, r) for k, r in self.routes if self._customers(r)]
            left.append(worst)
        served = {c for _, r in self.routes for c in r} | set(left)
        left += [c for c in self.instance.customers if c not in served]
        self.left = [c for c in left if not self._inserted_holding(c)]

    def _inserted_holding(self, customer: int) -> bool:
        """:meth:`insert` kept only when the routes hold together."""
        saved = self._saved()
        if self.insert(customer, anywhere=True) and self.holds():
            return True
        self.routes, self.left = saved
        return False

    def insert(self, customer: int, allow_new: bool = True, anywhere: bool = False) -> bool:
        """Put ``customer`` where it adds the least cost (a new route of a spare vehicle when
        none takes it and ``allow_new``) — in a route that holds one of its neighbours, or
        ``anywhere``; False when nowhere.

        Positions are tried by a lower bound on what they add — the detour of the customer
        alone less what the route's stations add now (a route with the customer
        drives at least its plain cost) — and the search stops at the first bound no better
        than the best found: the same answer as trying them all, at a fraction of the route
        evaluations."""
        best: tuple[float, list[int]] | None = None
        at = -1
        for bound, r, k, trip in self._bounds(customer, anywhere):
            if best is not None and bound >= best[0] - 1e-9:
                break
            kind, route = self.routes[r]
            added = [self.instance.kinds[kind].reload, customer] if trip else [customer]
            longer = [*route[:k], *added, *route[k:]]
            extra = self.cost(kind, longer) - self.cost(kind, route)
            if best is None or extra < best[0]:
                best, at = (extra, longer), r
        if best is not None and math.isfinite(best[0]):
            self.routes[at] = (self.routes[at][0], best[1])
            return True
        if not allow_new:
            return False
        alone = [  # a vehicle under way may come back to reload first
            (self.cost(kind, route), kind, route)
            for kind, vehicle in enumerate(self.instance.kinds)
            if self.spare(kind)
            for route in ([customer], [vehicle.reload, customer])[: 1 + (vehicle.reload >= 0)]
        ]
        fits = [ck for ck in alone if math.isfinite(ck[0])]
        if not fits:
            return False
        _, kind, route = min(fits)
        self.routes.append((kind, route))
        return True

    def _bounds(self, customer: int, anywhere: bool) -> Iterator[tuple[float, int, int, bool]]:
        """Each place in the routes ``customer`` may join (load; a neighbour there unless
        ``anywhere``) with a
        lower bound on what it adds, least first; for a vehicle with trips to spare, also on
        a trip of its own there (a return to reload before it: no shorter, the distances
        being metric)."""
        inst = self.instance
        demand = inst.demand[customer]
        near = self.near[customer]
        bounds, routes, places, trips = [], [], [], []
        for r, (kind, route) in enumerate(self.routes):
            vehicle = inst.kinds[kind]
            if customer in vehicle.forbidden:
                continue
            shape = self._shape(kind, route)
            one_trip = vehicle.reload < 0  # else each trip's load: evaluated
            if one_trip and shape.load + demand > vehicle.capacity:
                continue
            if not anywhere and customer not in self.pinned and near.isdisjoint(shape.members):
                continue  # no neighbour of it there: it would cost more than where they are
            detour = inst.distance[shape.head, customer] + inst.distance[customer, shape.tail]
            bound = (detour - shape.arcs) - shape.spare
            own_trips = not one_trip and route.count(vehicle.reload) < vehicle.max_trips - 1
            for trip in (False, True)[: 1 + own_trips]:
                bounds.append(bound)
                routes.append(np.full(bound.size, r))
                places.append(np.arange(bound.size))
                trips.append(np.full(bound.size, trip))
        if not bounds:
            return
        columns = [np.concatenate(c) for c in (bounds, routes, places, trips)]
        for i in np.lexsort(columns[::-1]):
            yield float(columns[0][i]), int(columns[1][i]), int(columns[2][i]), bool(columns[3][i])

    def _shape(self, kind: int, route: list[int]) -> _Shape:
        """What :meth:`_bounds` needs of a route, remembered."""
        key = (kind, tuple(route))
        shape = self._shapes.get(key)
        if shape is None:
            if len(self._shapes) > MEMO_SIZE:
                self._shapes.clear()
            seq = np.array([self.instance.kinds[kind].start, *route, 0])
            arcs = self.instance.distance[seq[:-1], seq[1:]]
            charged = self.charged(kind, route)
            spare = charged.distance - float(arcs.sum())  # the stations' detours
            shape = _Shape(frozenset(route), charged.load, seq[:-1], seq[1:], arcs, spare)
            self._shapes[key] = shape
        return shape

    def _saved(self) -> tuple[Routes, list[int]]:
        return [(k, list(r)) for k, r in self.routes], list(self.left)


class _Search(_Solution):
    """The search over a :class:`_Solution` (step 3), on work; the best routes seen."""

    def __init__(self, instance: EvrpInstance, rng: np.random.Generator) -> None:
        super().__init__(instance)
        self.rng = rng
        self.moves = 0
        self.best: tuple[tuple[int, int, float], Routes, list[int]] | None = None
        self.failures: dict[int, int] = {}

    @property
    def spent_s(self) -> float:
        """The work done [reference s]: routes screened and evaluated, the labels' steps,
        and moves."""
        priced = self.priced
        looked, walked = priced.steps.tolist()
        labels = EVALUATION_S * priced.evaluations + LOOK_S * looked + WALK_S * walked
        return labels + SCREEN_S * priced.screened + MOVE_S * self.moves

    def improve(self, work_s: float, effort: Effort) -> SearchEnd:
        """Step 3 for ``work_s`` [reference s], capped by ``effort``'s deadline:
        :data:`DISTANCE_MOVES` ruin-and-recreate moves, each kept when it is at most a
        threshold worse (falling from :data:`START_THRESHOLD` to nothing as the work runs
        out: threshold accepting, Dueck & Scheuer 1990), then an attempt at a vehicle less (in
        at most :data:`ELIMINATION_SHARE` of the work left; the next smallest route after
        each that fails, and once every route's turn is over, only every
        :data:`ELIMINATION_EVERY` rounds; all in at most :data:`ELIMINATION_BUDGET` of the
        work), and again. The best routes seen are kept."""
        self.keep_if_best()
        end = self.spent_s + work_s
        nth = rounds = 0
        eliminating = 0.0
        watch = effort.watch()
        while self.spent_s < end:
            rounds += 1
            for _ in range(DISTANCE_MOVES):
                if self.spent_s >= end:
                    return "work"
                if watch.passed(self.moves):
                    return "time_limit"
                self._ruin_and_recreate(START_THRESHOLD * (end - self.spent_s) / work_s)
                self.keep_if_best()
            if not self.instance.fewest_vehicles:
                continue
            if nth >= len(self.routes) and rounds % ELIMINATION_EVERY:
                continue
            room = min(
                (end - self.spent_s) * ELIMINATION_SHARE, ELIMINATION_BUDGET * work_s - eliminating
            )
            if room <= 0:
                continue
            before = self.spent_s
            eliminated = self._eliminate(self.spent_s + room, nth, effort)
            eliminating += self.spent_s - before
            if eliminated:
                nth = 0
                self.keep_if_best()
            else:
                nth += 1
        return "work"

    def keep_if_best(self) -> None:
        total = self.total()
        if self.best is None or total < self.best[0]:
            self.best = (total, [(k, list(r)) for k, r in self.routes], list(self.left))

    def _eliminate(self, until: float, nth: int, effort: Effort) -> bool:
        """Empty the ``nth`` smallest route into the others through an ejection pool
        (Nagata & Bräysy 2009): each customer of the pool inserted where it costs least, else
        inserted by taking out the customer of that route that has failed least often
        (back into the pool); False (nothing changed) when the work ``until`` is done first or a
        customer fits nowhere even so."""
        if len(self.routes) < 2:
            return False
        saved = self._saved()
        order = sorted(range(len(self.routes)), key=lambda r: len(self.routes[r][1]))
        _, out = self.routes.pop(order[nth % len(order)])
        pool = self._customers(out)
        watch = effort.watch()
        steps = 0
        while pool:
            steps += 1
            if self.spent_s >= until or watch.passed(steps):
                self.routes, self.left = saved
                return False
            customer = pool.pop()
            if self.insert(customer, allow_new=False):
                continue
            ejected = self._inserted_ejecting(customer)
            if ejected is None:
                self.routes, self.left = saved
                return False
            self.failures[customer] = self.failures.get(customer, 0) + 1
            pool.append(ejected)
            self._ruin_and_recreate(0.0, new_routes=False, out=pool)
        if not self.holds():
            self.routes, self.left = saved
            return False
        return True

    def _inserted_ejecting(self, customer: int) -> int | None:
        """``customer`` put into a route that holds one of its neighbours, that route's
        customer failed least often (then cheapest) taken out for it; the one taken out, or
        None when no such exchange holds."""
        inst = self.instance
        near = self.near[customer]
        best: tuple[int, float, int, list[int], int] | None = None
        for r, (kind, route) in enumerate(self.routes):
            if customer in inst.kinds[kind].forbidden:
                continue
            if customer not in self.pinned and not near.intersection(route):
                continue
            for k in range(len(route) + 1):
                longer = [*route[:k], customer, *route[k:]]
                for w in self._customers(route):
                    count = self.failures.get(w, 0)
                    if best is not None and count > best[0]:
                        continue
                    shorter = [c for c in longer if c != w]
                    cost = self.cost(kind, shorter)
                    if math.isfinite(cost) and (best is None or (count, cost) < best[:2]):
                        best = (count, cost, r, shorter, w)
        if best is None:
            return None
        _, _, r, shorter, w = best
        self.routes[r] = (self.routes[r][0], shorter)
        return w

    def _ruin_and_recreate(
        self, threshold: float, new_routes: bool = True, out: Collection[int] = ()
    ) -> None:
        """A few nearby customers out — near one left out, :data:`LEFT_SEED_SHARE` of the
        moves when any is and ``new_routes`` —, those left out put in first (anywhere), then
        each taken out back where it costs least (in a new route of a spare vehicle only with
        ``new_routes``); kept with no more left out, no vehicle more and a cost at most
        ``threshold`` (a share) worse. The customers ``out`` (not in the routes) stay out."""
        self.moves += 1
        saved = self._saved()
        before = self.total()
        seed = int(self.rng.integers(len(self.instance.customers)))
        if self.left and new_routes and self.rng.random() < LEFT_SEED_SHARE:
            seed = self.position[self.left[int(self.rng.integers(len(self.left)))]]
        if self.rng.random() < STRING_SHARE:
            taken = self._strings(seed)
        else:
            size = int(self.rng.integers(2, RUIN_SIZE + 1))
            taken = {self.instance.customers[k] for k in self.nearest[seed][:size]}
        taken -= set(self.left) | set(out)
        self.routes = [(k, [c for c in r if c not in taken]) for k, r in self.routes]
        self.routes = [(k, r) for k, r in self.routes if self._customers(r)]
        if new_routes:  # those left out first, into the room made
            self.left = [c for c in self.left if not self.insert(c, anywhere=True)]
        placed = all(self.insert(c, allow_new=new_routes) for c in self._recreate_order(taken))
        after = self.total()
        worse = after[:2] > before[:2] or (
            after[:2] == before[:2] and after[2] > before[2] * (1.0 + threshold) + 1e-9
        )
        if not placed or worse or not self.holds():
            self.routes, self.left = saved

    def _strings(self, seed: int) -> set[int]:
        """Strings of customers out of routes near the ``seed``-th customer (Christiaens &
        Vanden Berghe 2020, SISR): the routes of its nearest customers in turn, from each a
        string of consecutive customers through that customer, until the drawn number of
        routes is ruined; :data:`STRING_MEAN` customers out on average, strings at most
        :data:`STRING_MOST` long (or the routes' mean length)."""
        routes = [self._customers(r) for _, r in self.routes]
        where = {c: r for r, route in enumerate(routes) for c in route}
        if not routes:
            return set()
        longest = min(STRING_MOST, sum(map(len, routes)) / len(routes))
        most_strings = 4.0 * STRING_MEAN / (1.0 + longest) - 1.0
        strings = int(self.rng.uniform(1.0, most_strings + 1.0))
        taken: set[int] = set()
        ruined: set[int] = set()
        for k in self.nearest[seed]:
            if len(ruined) >= strings:
                break
            r = where.get(self.instance.customers[k])
            if r is None or r in ruined:
                continue
            route = routes[r]
            length = int(self.rng.integers(1, int(min(len(route), longest)) + 1))
            at = route.index(self.instance.customers[k])
            first = int(
                self.rng.integers(max(at - length + 1, 0), min(at, len(route) - length) + 1)
            )
            taken.update(route[first : first + length])
            ruined.add(r)
        return taken

    def _recreate_order(self, taken: set[int]) -> list[int]:
        """The order the customers ``taken`` go back in (SISR's): at random, the largest
        demand first, the farthest from the depot first or the nearest first, drawn
        :data:`RECREATE_ORDERS`."""
        inst = self.instance
        shuffled = [int(c) for c in self.rng.permutation(sorted(taken))]
        how = self.rng.choice(len(RECREATE_ORDERS), p=RECREATE_ORDERS)
        keys = (
            None,
            lambda c: -inst.demand[c],
            lambda c: -inst.distance[0, c],
            lambda c: inst.distance[0, c],
        )
        key = keys[how]
        return shuffled if key is None else sorted(shuffled, key=key)

    def restore_best(self) -> None:
        """The best routes seen."""
        if self.best is not None and self.best[0] < self.total():
            _, self.routes, self.left = self.best

    def polish(self, work_s: float, effort: Effort) -> SearchEnd:
        """The last step, for at most ``work_s`` [reference s]: the first change that makes the
        routes cheaper and keeps them holding together, until none does — a route's stretch of
        customers turned round (2-opt), or two routes' ends exchanged (2-opt*: what ruin and
        recreate, moving customers one by one, does not do: a van's last stretch, charges
        and all, handed to another). The work and the deadline are looked at before each
        change tried: one pass over two long routes' ends takes seconds (the last pass, which
        finds nothing, took four times the polish's work on E-VRPTW's r2). A pass either cuts
        has changed nothing, so a replay stopping before that pass ends the same."""
        end = self.spent_s + work_s
        watch = effort.watch()
        while True:
            for changed, now in self._changes():
                if self.spent_s >= end:
                    return "work"
                if watch.passed(self.moves):
                    return "time_limit"
                if self._kept(changed, now):
                    self.moves += 1
                    break
            else:
                return "work"

    def _changes(self) -> Iterator[tuple[list[tuple[int, list[int]]], float]]:
        """Each change :meth:`polish` tries, in order, with what the routes it changes cost
        now: every route's stretches turned round, then every two routes' ends exchanged."""
        for r, (kind, route) in enumerate(self.routes):
            now = self.cost(kind, route)
            for i in range(len(route) - 1):
                for j in range(i + 2, len(route) + 1):
                    yield [(r, [*route[:i], *route[i:j][::-1], *route[j:]])], now
        for a in range(len(self.routes)):
            for b in range(a + 1, len(self.routes)):
                (ka, ra), (kb, rb) = self.routes[a], self.routes[b]
                now = self.cost(ka, ra) + self.cost(kb, rb)
                for i in range(len(ra) + 1):
                    for j in range(len(rb) + 1):
                        if (i, j) in ((0, 0), (len(ra), len(rb))):
                            continue  # the same routes
                        yield [(a, [*ra[:i], *rb[j:]]), (b, [*rb[:j], *ra[i:]])], now

    def _kept(self, changed: list[tuple[int, list[int]]], now: float) -> bool:
        """The routes ``changed`` (index, new customers) kept when they cost less than ``now``
        together and every route still holds; a route left without customers is a vehicle
        less."""
        cost = sum(
            self.cost(self.routes[r][0], route) for r, route in changed if self._customers(route)
        )
        if cost >= now - 1e-9:
            return False
        saved = self._saved()
        for r, route in changed:
            self.routes[r] = (self.routes[r][0], route)
        self.routes = [(k, r) for k, r in self.routes if self._customers(r)]
        if self.holds():
            return True
        self.routes, self.left = saved
        return False

    def solution(self, ended: SearchEnd) -> EvrpSolution:
        self.restore_best()
        booked = self.booked()
        routes = [EvrpRoute(k, c.visits) for (k, _), c in zip(self.routes, booked, strict=True)]
        distance = sum(c.distance for c in booked)
        searched = [(k, list(r)) for k, r in self.routes]
        return EvrpSolution(routes, distance, sorted(self.left), ended, searched)


def _facts(instance: EvrpInstance, k: int) -> RouteFacts:
    """What routes of kind ``k`` are evaluated on: its energies, battery and charge times,
    its departure, its latest return as the depot's close."""
    kind = instance.kinds[k]
    due = instance.due.copy()
    due[0] = min(due[0], kind.due)
    return RouteFacts(
        cost=instance.distance,
        duration=instance.duration,
        energy=kind.energy,
        ready=instance.ready,
        due=due,
        service=instance.service,
        charge_time=instance.charge_time_of(k),
        battery=kind.battery,
        initial=kind.initial,
        start_time=kind.ready,
    )
