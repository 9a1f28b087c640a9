"""Iterated local search for the round trip, compiled with Numba: 2-opt and Or-opt on each
place's nearest neighbours with don't-look bits, kicked by a local double bridge.

The local search (Bentley 1992) tries, for each place whose bit is set, the moves that give it
an arc to one of its :data:`NEIGHBOURS` nearest places:

- 2-opt: two arcs out, two in, the path between them reversed;
- Or-opt: a segment of up to :data:`SEGMENT_MAX` places moved elsewhere, as it is or reversed.

Both are priced exactly on asymmetric costs (a reversed path costs its arcs backwards, from
prefix sums of the tour's arcs each way). Each kick, a double bridge (Martin, Otto & Felten
1991), swaps two neighbouring segments of at most :data:`KICK_SEGMENT_MAX` places, which keeps
their direction (so it suits one-way streets too); the local search repairs the six places it
touched, and the result is kept when it is no longer than before. Tens of thousands of kicks
per second on delivery rounds, where Python would manage a few hundred. Numba compiles it once
per installation (about 10 s, cached beside the module or in the user's cache) and loads it in
about a second per process: :func:`warm_up`.

The depot stays at position 0: every move leaves it there.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray
from scipy.sparse.csgraph import minimum_spanning_tree

from core.routing.effort import Watch

IntArray = NDArray[np.int64]

#: Nearest places each place's moves try as its new neighbour.
NEIGHBOURS = 10
#: Longest segment Or-opt moves [places].
SEGMENT_MAX = 3
#: Longest segment a kick swaps [places].
KICK_SEGMENT_MAX = 50
#: Kicks in each call of the compiled search: the clock (the deadline) is looked at between
#: calls, and each call's seed follows from the ones before, so the calls are the same however
#: fast they run.
CALL_KICKS = 100


def neighbours(cost: IntArray, count: int = NEIGHBOURS) -> IntArray:
    """Each place's candidates: its ``count`` nearest places (by the cheaper direction of the
    two arcs), then its neighbours in the minimum spanning tree, which hold the short links
    between clusters that no nearest-neighbour list has; rows padded with the last nearest."""
    n = cost.shape[0]
    closeness = np.minimum(cost, cost.T).astype(np.float64)
    np.fill_diagonal(closeness, np.inf)
    count = min(count, n - 1)
    nearest = np.argsort(closeness, axis=1, kind="stable")[:, :count]
    tree = minimum_spanning_tree(np.where(np.isfinite(closeness), closeness + 1.0, 0.0))
    tree = (tree + tree.T).tocsr()
    extra = [
        [int(j) for j in tree.indices[tree.indptr[i] : tree.indptr[i + 1]] if j not in nearest[i]]
        for i in range(n)
    ]
    width = count + max(len(e) for e in extra)
    table = np.empty((n, width), dtype=np.int64)
    for i in range(n):
        row = [*nearest[i], *extra[i]]
        table[i] = row + [row[-1]] * (width - len(row))
    return table


def iterated_local_search(
    cost: IntArray,
    order: list[int],
    kicks: int,
    watch: Watch,
    seed: int = 0,
    stall_kicks: int = 0,
) -> tuple[list[int], bool]:
    """The best tour from ``order`` (depot first and last) after ``kicks`` kicks, or once
    ``stall_kicks`` kicks in a row brought nothing (0: no such stop), or when ``watch`` says
    (between calls of :data:`CALL_KICKS`, counted) if that comes first; and whether it did.
    Seeded: the same answer for the same calls."""
    n = cost.shape[0]
    if n < 5:
        return order, False
    near = neighbours(cost)
    tour = np.asarray(order[:-1], dtype=np.int64)
    tour = _local_search_all(cost, tour, near)
    stalled, call, done = 0, 0, 0
    while done < kicks and not (stall_kicks and stalled >= stall_kicks):
        if watch.passed(call):
            return [*(int(x) for x in tour), 0], True
        batch = min(CALL_KICKS, kicks - done)
        tour, improved = _kicks(cost, tour, near, batch, seed + call)
        stalled = 0 if improved else stalled + batch
        done += batch
        call += 1
    return [*(int(x) for x in tour), 0], False


@njit(cache=True)
def _length(cost: IntArray, tour: IntArray) -> int:
    n = tour.shape[0]
    total = 0
    for k in range(n):
        total += cost[tour[k], tour[(k + 1) % n]]
    return total


@njit(cache=True)
def _sums(cost: IntArray, tour: IntArray, fwd: IntArray, rev: IntArray, pos: IntArray) -> None:
    """Prefix sums of the tour's arcs forwards and backwards, and each place's position."""
    n = tour.shape[0]
    fwd[0] = 0
    rev[0] = 0
    for k in range(n):
        a, b = tour[k], tour[(k + 1) % n]
        fwd[k + 1] = fwd[k] + cost[a, b]
        rev[k + 1] = rev[k] + cost[b, a]
        pos[a] = k


@njit(cache=True)
def _two_opt_delta(
    cost: IntArray, tour: IntArray, fwd: IntArray, rev: IntArray, i: int, j: int
) -> int:
    """Arcs i→i+1 and j→j+1 out (0 ≤ i, i + 2 ≤ j ≤ n − 1), i→j and i+1→j+1 in, the path
    i+1…j reversed."""
    n = tour.shape[0]
    a, b, c, d = tour[i], tour[i + 1], tour[j], tour[(j + 1) % n]
    return (
        cost[a, c]
        + cost[b, d]
        - cost[a, b]
        - cost[c, d]
        + (rev[j] - rev[i + 1])
        - (fwd[j] - fwd[i + 1])
    )


@njit(cache=True)
def _or_opt_delta(
    cost: IntArray,
    tour: IntArray,
    fwd: IntArray,
    rev: IntArray,
    s: int,
    length: int,
    r: int,
    reverse: bool,
) -> int:
    """The segment at positions s…s+length−1 (1 ≤ s, s+length−1 ≤ n−1) moved between
    positions r and r+1 (r outside s−1…s+length−1), reversed if ``reverse``."""
    n = tour.shape[0]
    e = s + length - 1
    before, after = tour[s - 1], tour[(e + 1) % n]
    first, last = tour[s], tour[e]
    x, y = tour[r], tour[(r + 1) % n]
    removed = cost[before, first] + cost[last, after] - cost[before, after]
    if reverse:
        added = cost[x, last] + cost[first, y] + (rev[e] - rev[s]) - (fwd[e] - fwd[s])
    else:
        added = cost[x, first] + cost[last, y]
    return added - cost[x, y] - removed


@njit(cache=True)
def _apply_two_opt(tour: IntArray, i: int, j: int) -> None:
    lo, hi = i + 1, j
    while lo < hi:
        tour[lo], tour[hi] = tour[hi], tour[lo]
        lo += 1
        hi -= 1


@njit(cache=True)
def _apply_or_opt(tour: IntArray, s: int, length: int, r: int, reverse: bool) -> None:
    n = tour.shape[0]
    segment = tour[s : s + length].copy()
    if reverse:
        segment = segment[::-1].copy()
    rest = np.empty(n - length, dtype=np.int64)
    rest[:s] = tour[:s]
    rest[s:] = tour[s + length :]
    at = r + 1 if r < s else r + 1 - length
    tour[:at] = rest[:at]
    tour[at : at + length] = segment
    tour[at + length :] = rest[at:]


@njit(cache=True)
def _improve_place(
    cost: IntArray,
    tour: IntArray,
    near: IntArray,
    fwd: IntArray,
    rev: IntArray,
    pos: IntArray,
    active: NDArray[np.bool_],
    a: int,
) -> bool:
    """Apply the first improving move that gives place ``a`` an arc to a near place."""
    n = tour.shape[0]
    p = pos[a]
    for k in range(near.shape[1]):
        c = near[a, k]
        q = pos[c]
        # 2-opt with a→c or c→a as one of the new arcs
        for i0, j0 in ((p, q), ((p - 1) % n, (q - 1) % n)):
            i, j = min(i0, j0), max(i0, j0)
            if (
                j >= i + 2
                and not (i == 0 and j == n - 1)
                and _two_opt_delta(cost, tour, fwd, rev, i, j) < 0
            ):
                for m in (i, i + 1, j, (j + 1) % n):
                    active[tour[m]] = True
                _apply_two_opt(tour, i, j)
                return True
        # Or-opt: a segment that starts or ends at a, put next to c
        for length in range(1, SEGMENT_MAX + 1):
            for s in (p, p - length + 1):
                if s < 1 or s + length - 1 > n - 1:
                    continue
                e = s + length - 1
                for r in (q, (q - 1) % n):
                    if s - 1 <= r <= e:
                        continue
                    for reverse in (False, True):
                        if _or_opt_delta(cost, tour, fwd, rev, s, length, r, reverse) < 0:
                            for m in (s - 1, s, e, (e + 1) % n, r, (r + 1) % n):
                                active[tour[m]] = True
                            _apply_or_opt(tour, s, length, r, reverse)
                            return True
    return False


@njit(cache=True)
def _descend(cost: IntArray, tour: IntArray, near: IntArray, active: NDArray[np.bool_]) -> None:
    """Local search until no place with its bit set has an improving move."""
    n = tour.shape[0]
    fwd = np.empty(n + 1, dtype=np.int64)
    rev = np.empty(n + 1, dtype=np.int64)
    pos = np.empty(n, dtype=np.int64)
    _sums(cost, tour, fwd, rev, pos)
    busy = True
    while busy:
        busy = False
        for a in range(n):
            if not active[a]:
                continue
            if _improve_place(cost, tour, near, fwd, rev, pos, active, a):
                _sums(cost, tour, fwd, rev, pos)
                busy = True
            else:
                active[a] = False


@njit(cache=True)
def _local_search_all(cost: IntArray, tour: IntArray, near: IntArray) -> IntArray:
    result = tour.copy()
    active = np.ones(tour.shape[0], dtype=np.bool_)
    _descend(cost, result, near, active)
    return result


@njit(cache=True)
def _kicks(
    cost: IntArray, tour: IntArray, near: IntArray, kicks: int, seed: int
) -> tuple[IntArray, bool]:
    """``kicks`` kicks from ``tour``, each kept when the repaired tour is no longer; the
    tour after them, and whether any shortened it."""
    # Numba's compiled code has NumPy's legacy generator, seeded per call.
    np.random.seed(seed)  # noqa: NPY002
    n = tour.shape[0]
    current = tour.copy()
    length = _length(cost, current)
    active = np.zeros(n, dtype=np.bool_)
    improved = False
    span = min(KICK_SEGMENT_MAX, (n - 1) // 3)
    for _ in range(kicks):
        # Two neighbouring segments of at most ``span`` places each swap places.
        p1 = np.random.randint(1, n - 2 * span) if n - 2 * span > 1 else 1  # noqa: NPY002
        p2 = p1 + np.random.randint(1, span + 1)  # noqa: NPY002
        p3 = min(p2 + np.random.randint(1, span + 1), n)  # noqa: NPY002
        if p3 <= p2:
            continue
        trial = np.empty(n, dtype=np.int64)
        trial[:p1] = current[:p1]
        trial[p1 : p1 + p3 - p2] = current[p2:p3]
        trial[p1 + p3 - p2 : p3] = current[p1:p2]
        trial[p3:] = current[p3:]
        for m in (p1 - 1, p1, p1 + p3 - p2 - 1, p1 + p3 - p2, p3 - 1, p3 % n):
            active[trial[m]] = True
        _descend(cost, trial, near, active)
        trial_length = _length(cost, trial)
        if trial_length <= length:
            if trial_length < length:
                improved = True
            current, length = trial, trial_length
    return current, improved


def warm_up() -> None:
    """Load (or, once per installation, compile) the compiled search: about a second with
    Numba's import, so a process that will solve does it before its first time limit."""
    rng = np.random.default_rng(0)
    cost = rng.integers(1, 100, size=(8, 8)).astype(np.int64)
    near = neighbours(cost)
    tour = _local_search_all(cost, np.arange(8, dtype=np.int64), near)
    _kicks(cost, tour, near, 1, 0)
    _length(cost, tour)
