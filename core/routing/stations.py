"""The charging stations of one route with a fixed order of customers: which stations between
them and how much to charge at each (partial recharge), at the least cost, by labels over the
route's gaps (Numba).

At most one station per gap, among the :data:`STATIONS_PER_GAP` with the least detour. A
charge gives what the way to the next station (or the depot) takes — the least, so the least
time. A station closed, or with every point taken by other vehicles, when a charge would
start makes the vehicle wait for the first span with room for the whole charge
(:class:`core.routing.points.Closed`). Labels of cost, time and battery on arrival are kept
when no other is as good on all three (at most :data:`LABELS_PER_NODE`). The least cost that
keeps every window, the battery and the latest return wins. The labelling follows Keskin &
Çatay, *Transportation Research C* 65 (2016) 111 (partial recharge) and Schneider, Stenger &
Goeke, *Transportation Science* 48 (2014) 500.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numba import njit
from numpy.typing import NDArray

from core.arrays import FloatArray
from core.routing.points import Closed

#: Stations considered on each gap between two places of a route, least detour first.
STATIONS_PER_GAP = 4
#: Labels kept at each station (or the start) of a route.
LABELS_PER_NODE = 6
#: A label's fields: cost, time and battery on arrival, the label it came from (node and slot)
#: and what that one charged.
_C, _T, _B, _PREV, _PREV_L, _X = range(6)
_FIELDS = 6
_EPS = 1e-9


@dataclass(frozen=True)
class Visit:
    """A place of a route and the energy charged there (0 but at stations)."""

    place: int
    charge: float


@dataclass(frozen=True)
class RouteFacts:
    """What one kind of vehicle's routes are evaluated on (places by index).

    Attributes
    ----------
    cost, duration, energy
        Each arc's cost (the objective), travel time and energy.
    ready, due, service
        Each place's window and service time (at a station: the time to plug in and out); the
        depot's ``due`` is the latest return.
    charge_time
        Time to charge one unit of energy at each place (used at the stations).
    battery, initial
        The most energy the battery holds above its floor, and what it holds at departure
        (a vehicle charges only at stations).
    start_time
        The departure from the route's first place.
    """

    cost: FloatArray
    duration: FloatArray
    energy: FloatArray
    ready: FloatArray
    due: FloatArray
    service: FloatArray
    charge_time: FloatArray
    battery: float
    initial: float
    start_time: float


@dataclass(frozen=True)
class Charged:
    """A route with its stations: its cost, its load, and per gap between two places of
    ``seq`` (start, customers, depot) the station visited (−1: none), the energy charged there
    and when the vehicle is plugged in there (from after any wait to its departure; NaN where
    none)."""

    distance: float
    load: float = 0.0
    seq: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    gaps: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    charges: FloatArray = field(default_factory=lambda: np.zeros(0))
    plugged: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))

    @property
    def visits(self) -> list[Visit]:
        """The places in order, start first and depot last, stations included (built only
        for the answer: the search compares costs)."""
        visits = [Visit(int(self.seq[0]), 0.0)] if self.seq.size else []
        for p in range(self.seq.size - 1):
            if self.gaps[p] >= 0:
                visits.append(Visit(int(self.gaps[p]), float(self.charges[p])))
            visits.append(Visit(int(self.seq[p + 1]), 0.0))
        return visits

    def plugged_at(self, stations: Mapping[int, int]) -> list[tuple[int, float, float]]:
        """When the vehicle is plugged in at each of ``stations`` it charges at: (station,
        from, to)."""
        return [
            (int(s), float(self.plugged[p, 0]), float(self.plugged[p, 1]))
            for p, s in enumerate(self.gaps)
            if s in stations
        ]


NO_ROUTE = Charged(math.inf)


def station_candidates(cost: FloatArray, stations: NDArray[np.int64]) -> NDArray[np.int64]:
    """For each arc, the :data:`STATIONS_PER_GAP` stations of least detour (by cost)."""
    if stations.size == 0:
        return np.zeros((*cost.shape, 0), dtype=np.int64)
    detour = cost[:, stations][:, None, :] + cost[stations, :].T[None, :, :]
    best = np.argsort(detour, axis=2, kind="stable")[:, :, :STATIONS_PER_GAP]
    return stations[best]


def quickest_durations(duration: FloatArray, candidates: NDArray[np.int64]) -> FloatArray:
    """Each arc's least time between its two places whatever a route charges on it: straight,
    or through one of its candidate stations (a gap holds at most one; plugging in, charging
    and waiting only add to it) [the duration's unit] — a lower bound for
    :func:`keeps_windows`."""
    if candidates.shape[2] == 0:
        return duration
    size = duration.shape[0]
    rows = np.arange(size)[:, None, None]
    cols = np.arange(size)[None, :, None]
    through = duration[rows, candidates] + duration[candidates, cols]
    return np.minimum(duration, through.min(axis=2))


@njit(cache=True)
def keeps_windows(
    seq: NDArray[np.int64],
    quickest: FloatArray,
    ready: FloatArray,
    due: FloatArray,
    service: FloatArray,
    start_time: float,
) -> bool:
    """Whether ``seq`` can keep its windows at all: driven on the ``quickest`` times
    (:func:`quickest_durations`), charging nothing, it reaches no place after its window.
    False is a proof that no stations and charges keep them (most of the routes a search
    tries on a day of tight windows fail so, in a fraction of the labels' time)."""
    clock = start_time
    for p in range(1, seq.size):
        clock += quickest[seq[p - 1], seq[p]]
        if clock > due[seq[p]] + _EPS:
            return False
        clock = max(clock, ready[seq[p]]) + service[seq[p]]
    return True


def route_with_stations(
    facts: RouteFacts,
    seq: NDArray[np.int64],
    candidates: NDArray[np.int64],
    closed: Closed,
    steps: NDArray[np.int64] | None = None,
) -> tuple[float, NDArray[np.int64], FloatArray, FloatArray]:
    """``seq`` (start, customers in order, depot) with the stations and charges it needs at
    the least cost within every window, a charge only where and when ``closed`` has room for
    it: its cost, and per gap the station (−1: none), the energy charged there and when
    plugged in (from, to). Infinite cost when no choice keeps the battery and the windows.
    ``steps`` (when given) counts the labels' work: the stations looked at, the places walked."""
    f = facts
    lab = np.zeros((1 + (seq.size - 1) * candidates.shape[2], LABELS_PER_NODE, _FIELDS))
    return _labels(
        seq,
        f.cost,
        f.duration,
        f.energy,
        f.ready,
        f.due,
        f.service,
        f.charge_time,
        candidates,
        f.battery,
        f.initial,
        f.start_time,
        (closed.ptr, closed.start, closed.end),
        lab,
        np.zeros(2, dtype=np.int64) if steps is None else steps,
    )


def warm_up() -> None:
    """Load (or, once per installation, compile) the compiled station search, as
    :func:`core.routing.ils.warm_up` does the round trip's: loaded in a request's first
    charging search instead, it took its time limit (a 40-stop round's, 2 s) before its first
    look at the clock."""
    size = 4  # the depot, two customers, a station
    cost = np.ones((size, size)) - np.eye(size)
    facts = RouteFacts(
        cost, cost, cost, np.zeros(size), np.full(size, 100.0), np.zeros(size),
        np.full(size, 0.1), 1.5, 1.5, 0.0,
    )  # fmt: skip
    candidates = station_candidates(cost, np.array([3]))
    seq = np.array([0, 1, 2, 0])
    route_with_stations(facts, seq, candidates, Closed.of({3: [(0.0, 1.0)]}, 4))
    keeps_windows(seq, cost, facts.ready, facts.due, facts.service, 0.0)


@njit(cache=True)
def _labels(
    seq: NDArray[np.int64],
    cost: FloatArray,
    dur: FloatArray,
    energy: FloatArray,
    ready: FloatArray,
    due: FloatArray,
    service: FloatArray,
    charge_time: FloatArray,
    cand: NDArray[np.int64],
    battery: float,
    initial: float,
    start_time: float,
    closed: tuple[NDArray[np.int64], FloatArray, FloatArray],
    lab: FloatArray,
    steps: NDArray[np.int64],
) -> tuple[float, NDArray[np.int64], FloatArray, FloatArray]:
    """Labels over the route's charge points — the start (node 0), then station k of gap p
    (between ``seq[p]`` and ``seq[p + 1]``, node ``1 + p·K + k``), each extended in turn
    (:func:`_extend`); the best that reaches the depot, traced back (:func:`_traced`)."""
    m = seq.size - 1
    nodes = lab.shape[0]
    count = np.zeros(nodes, dtype=np.int64)
    lab[0, 0, _T] = start_time
    lab[0, 0, _B] = initial
    lab[0, 0, _PREV] = -1.0
    count[0] = 1
    _first_stations(seq, cost, dur, energy, due, cand, lab, count)
    best = np.array([np.inf, -1.0, -1.0, 0.0])  # cost, node, slot, charge
    for u in range(nodes):
        for li in range(count[u]):
            _extend(
                u, li, seq, cost, dur, energy, ready, due, service, charge_time, cand,
                battery, closed, lab, count, best, steps,
            )  # fmt: skip
    gaps = np.full(m, -1, dtype=np.int64)
    charges = np.zeros(m)
    plugged = np.full((m, 2), np.nan)
    if best[1] < 0:
        return np.inf, gaps, charges, plugged
    _traced(best, lab, seq, cand, (service, charge_time, closed), (gaps, charges, plugged))
    return best[0], gaps, charges, plugged


@njit(cache=True)
def _first_stations(
    seq: NDArray[np.int64],
    cost: FloatArray,
    dur: FloatArray,
    energy: FloatArray,
    due: FloatArray,
    cand: NDArray[np.int64],
    lab: FloatArray,
    count: NDArray[np.int64],
) -> None:
    """The start's label driven to each station straight from it (before the first customer;
    it charges nothing there)."""
    here, end, t0, b0 = seq[0], seq[seq.size - 1], lab[0, 0, _T], lab[0, 0, _B]
    for k in range(cand.shape[2]):
        s = cand[seq[0], seq[1], k]
        arrive = t0 + dur[here, s]
        if energy[here, s] <= b0 + _EPS and arrive <= due[end]:
            _add_label(lab, count, 1 + k, cost[here, s], arrive, b0 - energy[here, s], 0, 0, 0.0)


@njit(cache=True)
def _extend(
    u: int,
    li: int,
    seq: NDArray[np.int64],
    cost: FloatArray,
    dur: FloatArray,
    energy: FloatArray,
    ready: FloatArray,
    due: FloatArray,
    service: FloatArray,
    charge_time: FloatArray,
    cand: NDArray[np.int64],
    battery: float,
    closed: tuple[NDArray[np.int64], FloatArray, FloatArray],
    lab: FloatArray,
    count: NDArray[np.int64],
    best: FloatArray,
    steps: NDArray[np.int64],
) -> None:
    """Label ``li`` of node ``u`` driven on: to each candidate station of each later gap it
    reaches, charging at ``u`` what the way there takes beyond its battery (a new label), and
    to the depot (the best so far). The start charges nothing. ``steps`` counts the stations
    looked at and the places walked (their time)."""
    m = seq.size - 1
    k_max = cand.shape[2]
    end = seq[m]
    d0, t0, b0 = lab[u, li, _C], lab[u, li, _T], lab[u, li, _B]
    if u == 0:
        here, first, limit, plug = seq[0], 1, b0, 0.0
    else:
        gap = (u - 1) // k_max
        here, first, limit = cand[seq[gap], seq[gap + 1], (u - 1) % k_max], gap + 1, battery
        plug = service[here]
    used, path, prev = 0.0, 0.0, here
    for p in range(first, m + 1):
        node = seq[p]
        used += energy[prev, node]
        path += cost[prev, node]
        prev = node
        if used > limit + _EPS:
            return
        if p == m:  # back at the depot
            x = max(0.0, used - b0)
            leave = _plugged(u, here, t0, plug + charge_time[here] * x, closed)[1]
            if not np.isfinite(leave):
                return
            steps[1] += m - first + 1
            _, late = _walk(seq, first, m, here, leave, dur, ready, due, service)
            if late > 0.0:
                return
            if d0 + path < best[0]:
                best[0], best[1], best[2], best[3] = d0 + path, u, li, x
            return
        for k in range(k_max):
            steps[0] += 1
            s = cand[node, seq[p + 1], k]
            to_s = used + energy[node, s]
            if to_s > limit + _EPS:
                continue
            x = max(0.0, to_s - b0)
            leave = _plugged(u, here, t0, plug + charge_time[here] * x, closed)[1]
            if not np.isfinite(leave):
                continue
            steps[1] += p - first + 1
            leave, late = _walk(seq, first, p, here, leave, dur, ready, due, service)
            arrive = leave + dur[node, s]
            if late > 0.0 or arrive > due[end]:
                continue
            _add_label(
                lab, count, 1 + p * k_max + k, d0 + path + cost[node, s], arrive,
                b0 + x - to_s, u, li, x,
            )  # fmt: skip


@njit(cache=True)
def _plugged(
    u: int,
    here: int,
    arrive: float,
    length: float,
    closed: tuple[NDArray[np.int64], FloatArray, FloatArray],
) -> tuple[float, float]:
    """Plugged in at ``here`` (label node ``u``; the start, 0, charges nothing) for
    ``length``, arriving at ``arrive``: from the first moment with room for it in ``closed``
    to then plus ``length`` (infinite when none)."""
    start = arrive
    if u > 0:
        ptr, shut, opens = closed
        for i in range(ptr[here], ptr[here + 1]):
            if opens[i] <= start:
                continue
            if shut[i] >= start + length:
                break
            start = opens[i]  # closed (or full) before the charge is done: after it
    return start, start + length


@njit(cache=True)
def _traced(
    best: FloatArray,
    lab: FloatArray,
    seq: NDArray[np.int64],
    cand: NDArray[np.int64],
    at: tuple[FloatArray, FloatArray, tuple[NDArray[np.int64], FloatArray, FloatArray]],
    out: tuple[NDArray[np.int64], FloatArray, FloatArray],
) -> None:
    """The stations, charges and when plugged in (``at`` the stations' plug-in times, charge
    times per unit and closed spans) of the best label's path, gap by gap (into ``out``)."""
    service, charge_time, closed = at
    gaps, charges, plugged = out
    k_max = cand.shape[2]
    u, li, x = int(best[1]), int(best[2]), best[3]
    while u > 0:
        gap = (u - 1) // k_max
        here = cand[seq[gap], seq[gap + 1], (u - 1) % k_max]
        gaps[gap] = here
        charges[gap] = x
        length = service[here] + charge_time[here] * x
        plugged[gap, 0], plugged[gap, 1] = _plugged(u, here, lab[u, li, _T], length, closed)
        x = lab[u, li, _X]
        u, li = int(lab[u, li, _PREV]), int(lab[u, li, _PREV_L])


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
    lab: FloatArray,
    count: NDArray[np.int64],
    v: int,
    c: float,
    t: float,
    b: float,
    u: int,
    li: int,
    x: float,
) -> None:
    """Keep the label at node ``v`` unless one there is as good on cost, time and battery;
    drop those it is as good as; at most the labels' room (the costliest goes)."""
    n = count[v]
    for i in range(n):
        if lab[v, i, _C] <= c + _EPS and lab[v, i, _T] <= t + _EPS and lab[v, i, _B] >= b - _EPS:
            return
    keep = 0
    for i in range(n):
        dominated = c <= lab[v, i, _C] + _EPS and t <= lab[v, i, _T] + _EPS
        if not (dominated and b >= lab[v, i, _B] - _EPS):
            lab[v, keep, :] = lab[v, i, :]
            keep += 1
    slot = keep
    if keep >= lab.shape[1]:
        worst = 0
        for i in range(keep):
            if lab[v, i, _C] > lab[v, worst, _C]:
                worst = i
        if lab[v, worst, _C] <= c:
            count[v] = keep
            return
        slot = worst
    else:
        keep += 1
    lab[v, slot, _C] = c
    lab[v, slot, _T] = t
    lab[v, slot, _B] = b
    lab[v, slot, _PREV] = u
    lab[v, slot, _PREV_L] = li
    lab[v, slot, _X] = x
    count[v] = keep
