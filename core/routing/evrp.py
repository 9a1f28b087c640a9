"""Vehicle routing with recharging stations and time windows, partial recharge (E-VRPTW-PR of
Schneider, Stenger & Goeke, *Transportation Science* 48 (2014) 500; Keskin & Çatay,
*Transportation Research C* 65 (2016) 111): fewest vehicles, then distance.

A vehicle's battery falls by the energy of each arc it drives and rises at a station by what
it charges there, at a time per unit of energy; it never falls below empty nor rises above
its capacity. Customers are served once inside their windows (waiting allowed) within the
load capacity.

1. **Routes of customers.** PyVRP solves the routing problem of the customers alone, with
   windows and load, its arc times lengthened by :data:`CHARGE_TIME_SHARE` of the time the
   arc's energy takes to charge (charging is time a route must find room for).
2. **Stations on a route** (:func:`route_with_stations`, Numba): for a fixed order of
   customers, the stations between them and how much to charge at each, by labels over the
   route's gaps: at most one station per gap among the :data:`STATIONS_PER_GAP` with the
   least detour; a charge gives what the way to the next station (or the depot) takes — the
   least, so the least time; labels of cost, time and battery on arrival, kept when no other
   is as good on all three (at most :data:`LABELS_PER_NODE`). The least distance that keeps
   every window and the battery wins — or, with a penalty per unit of time late, the least
   distance plus the penalised lateness (Vidal et al.'s time warp, *Computers & OR* 40
   (2013) 475).
3. **Search** until the deadline (Numba evaluates, Python searches): the customers of a route
   that cannot be charged are inserted where they cost least; then, in turn, a vehicle
   less — the route with the fewest customers emptied into the others, late where it must
   be, then ruin and recreate around the late customers on distance plus
   :data:`LATE_PENALTY` per unit late until none is (else undone) — and the distance: ruin
   and recreate (a few nearby customers out, each back where it costs least, only into
   routes that hold one of its :data:`NEIGHBOURS` nearest), kept when no worse (a route it
   empties is a vehicle less too).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import pyvrp
from numba import njit
from numpy.typing import NDArray
from pyvrp.stop import MaxRuntime

from core.arrays import FloatArray

#: Share of the charging time of an arc's energy that step 1 adds to the arc's time.
CHARGE_TIME_SHARE = 0.5
#: Stations considered on each gap between two places of a route, least detour first.
STATIONS_PER_GAP = 4
#: Labels kept at each station (or the start) of a route.
LABELS_PER_NODE = 6
#: Share of the budget for step 1.
ROUTING_SHARE = 0.15
#: PyVRP's integers: distances and times this many per unit.
_SCALE = 1000
#: Customers taken out and put back by one ruin-and-recreate move.
RUIN_SIZE = 14
#: A customer is inserted only into routes that hold one of its this many nearest customers
#: (a granular neighbourhood, Toth & Vigo 2003).
NEIGHBOURS = 15
#: Route evaluations remembered (then forgotten all at once).
MEMO_SIZE = 1_000_000
#: Emptying a route into the others: the penalty per unit of time late (lateness first, then
#: distance), and the share of the time left one attempt may take.
LATE_PENALTY = 1000.0
ELIMINATION_SHARE = 0.1
#: The most of the search's time all attempts to empty a route may take together: a fleet
#: that cannot lose a van leaves the rest to the distance.
ELIMINATION_BUDGET = 0.2
#: Ruin-and-recreate moves on the distance between two attempts to empty a route; the most
#: a move may worsen the distance at first [share]; rounds between attempts at a vehicle less
#: once every route has had its turn.
DISTANCE_MOVES = 100
START_THRESHOLD = 0.02
ELIMINATION_EVERY = 10


@dataclass(frozen=True)
class EvrpInstance:
    """The places (index 0 the depot, then the customers, then the stations) and the fleet.

    Attributes
    ----------
    distance, duration
        Distance and travel time of each arc.
    ready, due, service, demand
        Each place's window, service time and demand (0 at the depot and the stations).
    customers, stations
        The customers' and the stations' indices.
    capacity
        Load capacity of a vehicle.
    battery
        Battery capacity (energy).
    energy_per_distance
        Energy an arc takes per unit of its distance.
    time_per_energy
        Time to charge one unit of energy.
    """

    distance: FloatArray
    duration: FloatArray
    ready: FloatArray
    due: FloatArray
    service: FloatArray
    demand: FloatArray
    customers: list[int]
    stations: list[int]
    capacity: float
    battery: float
    energy_per_distance: float
    time_per_energy: float


@dataclass(frozen=True)
class Visit:
    """A place of a route and the energy charged there (0 but at stations)."""

    place: int
    charge: float


@dataclass(frozen=True)
class EvrpSolution:
    """The routes (depot first and last, stations included) and their total distance."""

    routes: list[list[Visit]]
    distance: float

    @property
    def vehicles(self) -> int:
        return len(self.routes)


def solve_evrptw(instance: EvrpInstance, time_limit_s: float, seed: int = 0) -> EvrpSolution:
    """Fewest vehicles, then least distance, within ``time_limit_s`` [s]."""
    deadline = time.perf_counter() + time_limit_s
    search = _Search(instance, np.random.default_rng(seed))
    routes = _customer_routes(instance, time_limit_s * ROUTING_SHARE)
    search.start(routes)
    search.improve(deadline)
    return search.solution()


def _customer_routes(instance: EvrpInstance, time_limit_s: float) -> list[list[int]]:
    """Step 1: PyVRP's routes of the customers, charging time partly in the arcs."""
    customers = instance.customers
    nodes = [0, *customers]
    n = len(nodes)
    distance = np.rint(instance.distance[np.ix_(nodes, nodes)] * _SCALE).astype(np.int64)
    charge = instance.energy_per_distance * instance.time_per_energy * CHARGE_TIME_SHARE
    arc_time = (
        instance.duration[np.ix_(nodes, nodes)] + charge * instance.distance[np.ix_(nodes, nodes)]
    )
    duration = np.rint(arc_time * _SCALE).astype(np.int64)
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
    horizon = round(instance.due[0] * _SCALE)
    data = pyvrp.ProblemData(
        [pyvrp.Location(0.0, 0.0) for _ in range(n)],
        clients,
        [pyvrp.Depot(location=0, tw_early=0, tw_late=horizon)],
        [
            pyvrp.VehicleType(
                num_available=len(customers),
                capacity=[round(instance.capacity)],
                fixed_cost=int(distance.sum()),
                tw_early=0,
                tw_late=horizon,
            )
        ],
        [distance],  # type: ignore[list-item]  # PyVRP's stubs name ndarray[int]
        [duration],
    )
    result = pyvrp.solve(data, stop=MaxRuntime(max(time_limit_s, 0.1)), seed=0, display=False)
    return [
        [customers[visit.idx] for visit in route.schedule() if visit.is_client()]
        for route in result.best.routes()
    ]


class _Search:
    """The routes of customers and what each costs with its stations (memoised), at the
    current ``penalty`` per unit of time late (infinite: routes must keep their windows)."""

    def __init__(self, instance: EvrpInstance, rng: np.random.Generator) -> None:
        self.instance = instance
        self.rng = rng
        self.routes: list[list[int]] = []
        self.penalty = math.inf
        self.best: tuple[tuple[int, float], list[list[int]]] | None = None
        self.memo: dict[tuple[float, tuple[int, ...]], Charged] = {}
        inst = instance
        stations = np.array(inst.stations, dtype=np.int64)
        self.candidates = _station_candidates(inst.distance, stations)
        self.nearest = np.argsort(inst.distance[np.ix_(inst.customers, inst.customers)], axis=1)
        self.near = {
            c: {inst.customers[k] for k in self.nearest[n][1 : NEIGHBOURS + 1]}
            for n, c in enumerate(inst.customers)
        }

    def charged(self, route: list[int]) -> Charged:
        key = (self.penalty, tuple(route))
        if key not in self.memo:
            if len(self.memo) > MEMO_SIZE:
                self.memo.clear()
            self.memo[key] = route_with_stations(
                self.instance, route, self.candidates, self.penalty
            )
        return self.memo[key]

    def cost(self, route: list[int]) -> float:
        """The route's distance with its stations and its penalised lateness; infinite when
        it cannot hold."""
        return self.charged(route).cost(self.penalty)

    def late(self) -> float:
        return sum(self.charged(r).warp for r in self.routes)

    def total(self) -> tuple[int, float]:
        return len(self.routes), sum(self.cost(r) for r in self.routes)

    def start(self, routes: list[list[int]]) -> None:
        """The routes that hold; the customers of those that do not, inserted where best."""
        left: list[int] = []
        for route in routes:
            route = list(route)
            while route and math.isinf(self.cost(route)):
                # the customer whose leaving makes the route hold at the least distance, else
                # the one farthest out
                shorter = [(self.cost([x for x in route if x != c]), c) for c in route]
                fits = [sc for sc in shorter if math.isfinite(sc[0])]
                if fits:
                    worst = min(fits)[1]
                else:
                    worst = max(route, key=lambda c: self.instance.distance[0, c])
                route.remove(worst)
                left.append(worst)
            if route:
                self.routes.append(route)
        for customer in left:
            self.insert(customer)

    def insert(self, customer: int, allow_new: bool = True) -> bool:
        """Put ``customer`` where it adds the least cost (a new route when none takes it and
        ``allow_new``).

        Positions are tried by a lower bound on what they add — the detour of the customer
        alone less what the route's stations and lateness cost now (a route with the customer
        drives at least its plain distance) — and the search stops at the first bound no
        better than the best found: the same answer as trying them all, at a fraction of the
        route evaluations."""
        dist = self.instance.distance
        demand = self.instance.demand[customer]
        near = self.near[customer]
        bounds: list[tuple[float, int, int]] = []
        for r, route in enumerate(self.routes):
            if self.charged(route).load + demand > self.instance.capacity:
                continue
            if not near.intersection(route):
                continue  # no neighbour of it there: it would cost more than where they are
            seq = np.array([0, *route, 0])
            arcs = dist[seq[:-1], seq[1:]]
            detour = dist[seq[:-1], customer] + dist[customer, seq[1:]] - arcs
            spare = self.cost(route) - float(arcs.sum())  # stations and lateness
            bounds.extend((float(d) - spare, r, k) for k, d in enumerate(detour))
        bounds.sort()
        best: tuple[float, list[int]] | None = None
        at = -1
        for bound, r, k in bounds:
            if best is not None and bound >= best[0] - 1e-9:
                break
            route = self.routes[r]
            longer = [*route[:k], customer, *route[k:]]
            extra = self.cost(longer) - self.cost(route)
            if best is None or extra < best[0]:
                best, at = (extra, longer), r
        if best is not None and math.isfinite(best[0]):
            self.routes[at] = best[1]
            return True
        if allow_new:
            self.routes.append([customer])
            return True
        return False

    def improve(self, deadline: float) -> None:
        """Step 3 until ``deadline``: :data:`DISTANCE_MOVES` ruin-and-recreate moves, each
        kept when it is at most a threshold worse (falling from :data:`START_THRESHOLD` to
        nothing as the time runs out: threshold accepting, Dueck & Scheuer 1990), then an
        attempt at a vehicle less (in at most :data:`ELIMINATION_SHARE` of the time left; the
        next smallest route after each that fails, and once every routes' turn is over, only
        every :data:`ELIMINATION_EVERY` rounds; all in at most :data:`ELIMINATION_BUDGET` of the
        time), and again. The best routes seen are kept."""
        began = time.perf_counter()
        self.keep_if_best()
        nth = rounds = 0
        eliminating_s = 0.0
        while time.perf_counter() < deadline:
            rounds += 1
            for _ in range(DISTANCE_MOVES):
                now = time.perf_counter()
                if now >= deadline:
                    return
                share = (deadline - now) / max(deadline - began, 1e-9)
                self._ruin_and_recreate(START_THRESHOLD * share)
                self.keep_if_best()
            if nth >= len(self.routes) and rounds % ELIMINATION_EVERY:
                continue
            now = time.perf_counter()
            budget_s = ELIMINATION_BUDGET * (deadline - began) - eliminating_s
            if budget_s <= 0:
                continue
            until = now + min((deadline - now) * ELIMINATION_SHARE, budget_s)
            eliminated = self._eliminate(until, nth)
            eliminating_s += time.perf_counter() - now
            if eliminated:
                nth = 0
                self.keep_if_best()
            else:
                nth += 1

    def keep_if_best(self) -> None:
        total = self.total()
        if self.best is None or total < self.best[0]:
            self.best = (total, [list(r) for r in self.routes])

    def _eliminate(self, until: float, nth: int) -> bool:
        """Empty the ``nth`` smallest route into the others, late at first, and search on the
        penalised lateness until none is late or ``until``; False (and nothing changed) when
        lateness is left."""
        if len(self.routes) < 2:
            return False
        saved = [list(r) for r in self.routes]
        order = sorted(range(len(self.routes)), key=lambda r: len(self.routes[r]))
        out = self.routes.pop(order[nth % len(order)])
        self.penalty = LATE_PENALTY
        if not all(self.insert(c, allow_new=False) for c in out):
            self.routes, self.penalty = saved, math.inf
            return False
        while self.late() > 1e-9 and time.perf_counter() < until:
            self._ruin_and_recreate(0.0, late_first=True)
        holds = self.late() <= 1e-9
        self.penalty = math.inf
        if not holds or any(math.isinf(self.cost(r)) for r in self.routes):
            self.routes = saved
            return False
        return True

    def _ruin_and_recreate(self, threshold: float, late_first: bool = False) -> None:
        """A few nearby customers out (around a late one with ``late_first``), each back
        where it costs least; kept with no vehicle more and a cost at most ``threshold``
        (a share) worse."""
        saved = [list(r) for r in self.routes]
        before = self.total()
        customers = self.instance.customers
        seed = int(self.rng.integers(len(customers)))
        if late_first:
            late = [r for r in self.routes if self.charged(r).warp > 0]
            if late:
                pick = late[int(self.rng.integers(len(late)))]
                seed = customers.index(pick[int(self.rng.integers(len(pick)))])
        size = int(self.rng.integers(2, RUIN_SIZE + 1))
        taken = {customers[k] for k in self.nearest[seed][:size]}
        self.routes = [[c for c in r if c not in taken] for r in self.routes]
        self.routes = [r for r in self.routes if r]
        placed = all(
            self.insert(int(c), allow_new=not late_first)
            for c in self.rng.permutation(sorted(taken))
        )
        after = self.total()
        worse = after[0] > before[0] or (
            after[0] == before[0] and after[1] > before[1] * (1.0 + threshold) + 1e-9
        )
        if not placed or worse or any(math.isinf(self.cost(r)) for r in self.routes):
            self.routes = saved

    def solution(self) -> EvrpSolution:
        self.penalty = math.inf
        if self.best is not None and self.best[0] < self.total():
            self.routes = self.best[1]
        routes = [self.charged(r).visits for r in self.routes]
        return EvrpSolution(routes, sum(self.charged(r).distance for r in self.routes))


def _station_candidates(distance: FloatArray, stations: NDArray[np.int64]) -> NDArray[np.int64]:
    """For each arc, the :data:`STATIONS_PER_GAP` stations of least detour."""
    detour = distance[:, stations][:, None, :] + distance[stations, :].T[None, :, :]
    best = np.argsort(detour, axis=2)[:, :, :STATIONS_PER_GAP]
    return stations[best]


@dataclass(frozen=True)
class Charged:
    """A route with its stations: its distance, the time it is late in all (``warp``, only
    with a finite penalty), its load, and per gap between two places of ``seq`` (depot,
    customers, depot) the station visited (−1: none) and the energy charged there."""

    distance: float
    warp: float
    load: float = 0.0
    seq: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    gaps: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    charges: FloatArray = field(default_factory=lambda: np.zeros(0))

    def cost(self, penalty: float) -> float:
        return self.distance + (penalty * self.warp if self.warp > 0 else 0.0)

    @property
    def visits(self) -> list[Visit]:
        """The places in order, depot first and last, stations included (built only for
        the answer: the search compares costs)."""
        visits = [Visit(int(self.seq[0]), 0.0)] if self.seq.size else []
        for p in range(self.seq.size - 1):
            if self.gaps[p] >= 0:
                visits.append(Visit(int(self.gaps[p]), float(self.charges[p])))
            visits.append(Visit(int(self.seq[p + 1]), 0.0))
        return visits


NO_ROUTE = Charged(math.inf, 0.0)


def route_with_stations(
    instance: EvrpInstance,
    route: list[int],
    candidates: NDArray[np.int64],
    penalty: float = math.inf,
) -> Charged:
    """``route`` (customers in order) with the stations and charges it needs at the least
    distance, plus ``penalty`` per unit of time late (a place reached after its window is
    served at its close, the lateness counted: Vidal et al.'s time warp; infinite: never
    late); :data:`NO_ROUTE` when no choice keeps the load and the battery (and the windows)."""
    inst = instance
    seq = np.array([0, *route, 0], dtype=np.int64)
    load = float(inst.demand[seq].sum())
    if load > inst.capacity + 1e-9:
        return NO_ROUTE
    distance, warp, gaps, charges = _labels(
        seq,
        inst.distance,
        inst.duration,
        inst.ready,
        inst.due,
        inst.service,
        candidates,
        inst.battery,
        inst.energy_per_distance,
        inst.time_per_energy,
        penalty,
    )
    if not math.isfinite(distance):
        return NO_ROUTE
    return Charged(float(distance), float(warp), load, seq, gaps, charges)


@njit(cache=True)
def _labels(
    seq: NDArray[np.int64],
    dist: FloatArray,
    dur: FloatArray,
    ready: FloatArray,
    due: FloatArray,
    service: FloatArray,
    cand: NDArray[np.int64],
    battery: float,
    rate: float,
    time_per_energy: float,
    penalty: float,
) -> tuple[float, float, NDArray[np.int64], FloatArray]:
    """Labels over the route's charge points — the start (node 0), then station k of gap p
    (between ``seq[p]`` and ``seq[p + 1]``, node ``1 + p·K + k``): the least distance (plus
    the penalised lateness) to the end, its lateness and, per gap, the station (−1: none) and
    what it charges. A label's charge is decided by the next charge point: what the way there
    takes beyond the battery on arrival."""
    m = seq.size - 1
    k_max = cand.shape[2]
    nodes = 1 + m * k_max
    cap = LABELS_PER_NODE
    lab_c = np.full((nodes, cap), np.inf)  # distance + penalty × warp
    lab_d = np.zeros((nodes, cap))
    lab_w = np.zeros((nodes, cap))
    lab_t = np.zeros((nodes, cap))
    lab_b = np.zeros((nodes, cap))
    lab_prev = np.full((nodes, cap), -1, dtype=np.int64)
    lab_prev_l = np.full((nodes, cap), -1, dtype=np.int64)
    lab_x = np.zeros((nodes, cap))
    count = np.zeros(nodes, dtype=np.int64)
    lab_c[0, 0] = 0.0
    lab_t[0, 0] = ready[seq[0]]
    lab_b[0, 0] = battery
    count[0] = 1
    hard = not np.isfinite(penalty)
    best_c, best_d, best_w, best_u, best_l, best_x = np.inf, 0.0, 0.0, -1, -1, 0.0
    for u in range(nodes):
        if count[u] == 0:
            continue
        if u == 0:
            here, first = seq[0], 1
        else:
            gap = (u - 1) // k_max
            here, first = cand[seq[gap], seq[gap + 1], (u - 1) % k_max], gap + 1
        for li in range(count[u]):
            d0, w0, t0, b0 = lab_d[u, li], lab_w[u, li], lab_t[u, li], lab_b[u, li]
            if u == 0:  # a station straight from the depot, before the first customer
                for k in range(k_max):
                    s = cand[seq[0], seq[1], k]
                    to_s = rate * dist[here, s]
                    arrive = t0 + dur[here, s]
                    late = max(arrive - due[seq[0]], 0.0)
                    if to_s <= b0 + 1e-9 and not (hard and late > 1e-9):
                        _add_label(
                            1 + k,
                            dist[here, s],
                            late,
                            min(arrive, due[seq[0]]),
                            b0 - to_s,
                            penalty,
                            u,
                            li,
                            0.0,
                            lab_c,
                            lab_d,
                            lab_w,
                            lab_t,
                            lab_b,
                            lab_prev,
                            lab_prev_l,
                            lab_x,
                            count,
                            cap,
                        )
            energy, path, prev = 0.0, 0.0, here
            for p in range(first, m + 1):
                node = seq[p]
                energy += rate * dist[prev, node]
                path += dist[prev, node]
                prev = node
                if energy > battery + 1e-9:
                    break
                if p == m:  # back at the depot
                    x = max(0.0, energy - b0)
                    _, late = _walk(
                        seq, first, m, here, t0 + time_per_energy * x, dur, ready, due, service
                    )
                    if hard and late > 1e-9:
                        break
                    cost = d0 + path + (penalty * (w0 + late) if w0 + late > 0 else 0.0)
                    if cost < best_c:
                        best_c, best_d, best_w = cost, d0 + path, w0 + late
                        best_u, best_l, best_x = u, li, x
                    break
                for k in range(k_max):
                    s = cand[node, seq[p + 1], k]
                    to_s = energy + rate * dist[node, s]
                    if to_s > battery + 1e-9:
                        continue
                    x = max(0.0, to_s - b0)
                    leave, late = _walk(
                        seq, first, p, here, t0 + time_per_energy * x, dur, ready, due, service
                    )
                    arrive = leave + dur[node, s]
                    late += max(arrive - due[seq[0]], 0.0)
                    if hard and late > 1e-9:
                        continue
                    _add_label(
                        1 + p * k_max + k,
                        d0 + path + dist[node, s],
                        w0 + late,
                        min(arrive, due[seq[0]]),
                        b0 + x - to_s,
                        penalty,
                        u,
                        li,
                        x,
                        lab_c,
                        lab_d,
                        lab_w,
                        lab_t,
                        lab_b,
                        lab_prev,
                        lab_prev_l,
                        lab_x,
                        count,
                        cap,
                    )
    gaps = np.full(m, -1, dtype=np.int64)
    charges = np.zeros(m)
    if best_u < 0:
        return np.inf, 0.0, gaps, charges
    u, li, x = best_u, best_l, best_x
    while u > 0:
        gap = (u - 1) // k_max
        gaps[gap] = cand[seq[gap], seq[gap + 1], (u - 1) % k_max]
        charges[gap] = x
        x = lab_x[u, li]
        u, li = lab_prev[u, li], lab_prev_l[u, li]
    return best_d, best_w, gaps, charges


@njit(cache=True)
def _walk(
    seq: NDArray[np.int64],
    first: int,
    last: int,
    here: int,
    depart: float,
    dur: FloatArray,
    ready: FloatArray,
    due: FloatArray,
    service: FloatArray,
) -> tuple[float, float]:
    """Leave ``here`` at ``depart`` and serve ``seq[first..last]``: the departure from
    ``seq[last]`` (the arrival when it is the depot at the end) and the time late in all (a
    place reached after its window is served at its close)."""
    clock = depart
    prev = here
    late = 0.0
    for p in range(first, last + 1):
        node = seq[p]
        clock += dur[prev, node]
        if clock > due[node]:
            late += clock - due[node]
            clock = due[node]
        if p == seq.size - 1:
            return clock, late
        clock = max(clock, ready[node]) + service[node]
        prev = node
    return clock, late


@njit(cache=True)
def _add_label(
    v: int,
    d: float,
    w: float,
    t: float,
    b: float,
    penalty: float,
    u: int,
    li: int,
    x: float,
    lab_c: FloatArray,
    lab_d: FloatArray,
    lab_w: FloatArray,
    lab_t: FloatArray,
    lab_b: FloatArray,
    lab_prev: NDArray[np.int64],
    lab_prev_l: NDArray[np.int64],
    lab_x: FloatArray,
    count: NDArray[np.int64],
    cap: int,
) -> None:
    """Keep the label unless one at ``v`` is as good on cost, time and battery; drop those
    it is as good as; at most ``cap`` (the costliest goes)."""
    c = d + (penalty * w if w > 0 else 0.0)
    n = count[v]
    for i in range(n):
        if lab_c[v, i] <= c + 1e-9 and lab_t[v, i] <= t + 1e-9 and lab_b[v, i] >= b - 1e-9:
            return
    keep = 0
    for i in range(n):
        if not (c <= lab_c[v, i] + 1e-9 and t <= lab_t[v, i] + 1e-9 and b >= lab_b[v, i] - 1e-9):
            lab_c[v, keep] = lab_c[v, i]
            lab_d[v, keep] = lab_d[v, i]
            lab_w[v, keep] = lab_w[v, i]
            lab_t[v, keep] = lab_t[v, i]
            lab_b[v, keep] = lab_b[v, i]
            lab_prev[v, keep] = lab_prev[v, i]
            lab_prev_l[v, keep] = lab_prev_l[v, i]
            lab_x[v, keep] = lab_x[v, i]
            keep += 1
    slot = keep
    if keep >= cap:
        worst = 0
        for i in range(keep):
            if lab_c[v, i] > lab_c[v, worst]:
                worst = i
        if lab_c[v, worst] <= c:
            count[v] = keep
            return
        slot = worst
    else:
        keep += 1
    lab_c[v, slot] = c
    lab_d[v, slot] = d
    lab_w[v, slot] = w
    lab_t[v, slot] = t
    lab_b[v, slot] = b
    lab_prev[v, slot] = u
    lab_prev_l[v, slot] = li
    lab_x[v, slot] = x
    count[v] = keep
