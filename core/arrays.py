"""Array helpers shared by the physics modules."""

from __future__ import annotations

import ctypes
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.floating[Any]]

#: Freed memory a process keeps at the top of its heap with :func:`keep_heap` [B].
HEAP_KEEP_BYTES = 64 << 20
#: ``M_TRIM_THRESHOLD`` of glibc's ``mallopt`` (malloc.h).
_M_TRIM_THRESHOLD = -1


def keep_heap(keep_bytes: int = HEAP_KEEP_BYTES) -> bool:
    """Have the C library keep up to ``keep_bytes`` of freed memory at the top of the heap.

    glibc gives the top of the heap back to the system as soon as 128 kB lie free there, so
    each of a simulation's per-second arrays (115 kB for a 4 h round at 1 Hz) is faulted in
    anew every time numpy allocates one: about 40 % of a simulation's time (``make bench``;
    numpy/numpy#8783 describes the effect). The service's worker processes call this at
    start; a program that runs many simulations in its own process may too. The core itself
    never calls it (it changes the whole process).

    Returns
    -------
    bool
        Whether the allocator took the setting (False where the C library is not glibc).
    """
    try:
        mallopt = ctypes.CDLL(None).mallopt  # the C library the interpreter runs on
    except AttributeError:
        return False
    return bool(mallopt(_M_TRIM_THRESHOLD, keep_bytes))


def reflected_cumsum(increments: ArrayLike, initial: float = 0.0) -> FloatArray:
    """Running sum held at or above zero: ``w_k = max(0, w_{k-1} + x_k)``, ``w_0 = initial``.

    Vectorised through Lindley's identity ``w_k = S_k − min(−w_0, min_{j≤k} S_j)`` with
    ``S_k = x_1 + … + x_k`` (Lindley 1952), so no Python loop per step. Used for the heat stored
    in a cargo box above its set-point and for a battery that cannot charge beyond full.

    Parameters
    ----------
    increments
        x_1 … x_n, in any unit, along the last axis (leading axes are independent runs).
    initial
        w_0 >= 0, in the same unit.

    Returns
    -------
    numpy.ndarray
        w_1 … w_n.
    """
    s = np.cumsum(np.asarray(increments, dtype=float), axis=-1)
    return s - np.minimum(np.minimum.accumulate(s, axis=-1), -initial) if s.size else s


def interval_rates(
    starts_s: ArrayLike,
    ends_s: ArrayLike,
    n_steps: int,
    dt_s: float,
    rates: ArrayLike | None = None,
    overlap: str = "max",
) -> FloatArray:
    """Mean rate over each step of a set of boxcars; step ``k`` spans ``[k·dt, (k+1)·dt)``.

    Boxcar ``i`` runs at ``rates[i]`` (1 if None) from ``starts_s[i]`` to ``ends_s[i]``; a step
    it covers in part gets the covered share. Where boxcars overlap, ``overlap="max"`` keeps
    the larger (a door open twice is open once), ``"add"`` sums them. One slice per boxcar,
    so the cost grows with the number of boxcars, not of steps.

    Returns
    -------
    numpy.ndarray
        ``n_steps`` values, in the rate's unit.
    """
    out = np.zeros(n_steps)
    start = np.asarray(starts_s, dtype=float) / dt_s
    end = np.asarray(ends_s, dtype=float) / dt_s
    rate = np.ones(start.size) if rates is None else np.asarray(rates, dtype=float)
    for a, b, r in zip(start.tolist(), end.tolist(), rate.tolist(), strict=True):
        first, last = max(math.floor(a), 0), min(math.ceil(b), n_steps)
        if b <= a or first >= last:
            continue
        cover = np.full(last - first, r)
        cover[0] = r * (min(b, first + 1) - max(a, first))
        if last - first > 1:
            cover[-1] = r * (min(b, last) - max(a, last - 1))
        span = out[first:last]
        if overlap == "add":
            span += cover
        else:
            np.maximum(span, cover, out=span)
    return out


def uniform_interp(values: ArrayLike, per_interval: int, n: int) -> FloatArray:
    """Linear interpolation of values on a uniform coarse grid to ``n`` points spaced
    ``1/per_interval`` of its step, the first on the first value (no search: the points fall
    at known positions)."""
    coarse = np.asarray(values, dtype=float)
    if coarse.size == 1:
        return np.full(n, coarse[0])
    fraction = np.arange(per_interval) / per_interval
    filled = (coarse[:-1, None] + np.diff(coarse)[:, None] * fraction[None, :]).ravel()
    if filled.size >= n:
        return filled[:n]
    return np.concatenate((filled, np.full(n - filled.size, coarse[-1])))


class Blocks:
    """``n`` steps in consecutive blocks of ``per_block`` (the last may be shorter): where each
    begins, how many steps each holds, and a quantity's mean over each."""

    def __init__(self, n: int, per_block: int) -> None:
        self.edges = np.arange(0, n, max(per_block, 1))
        self.counts = np.diff(np.append(self.edges, n))

    def mean(self, values: ArrayLike) -> FloatArray:
        """Each block's mean of ``values`` (one per step)."""
        if not self.edges.size:
            return np.zeros(0)
        return np.add.reduceat(np.asarray(values, dtype=float), self.edges) / self.counts
