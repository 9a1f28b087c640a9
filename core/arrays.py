"""Array helpers shared by the physics modules."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.floating[Any]]


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


def interval_fraction(
    starts_s: ArrayLike, durations_s: ArrayLike, step_end_s: FloatArray, dt_s: float
) -> FloatArray:
    """Share of each step [–] covered by at least one interval ``[start, start + duration)``.

    The covered time up to ``t`` is piecewise linear in ``t`` (slope 1 while any interval is
    under way, so overlaps count once); it is built from the sorted start and end events and
    read at the step edges with one interpolation. Its difference over a step, divided by the
    step length, is the share.

    Parameters
    ----------
    starts_s, durations_s
        The intervals [s].
    step_end_s
        End of each step [s], equally spaced by ``dt_s``.
    """
    start = np.asarray(starts_s, dtype=float)
    if start.size == 0:
        return np.zeros(step_end_s.size)
    end = start + np.asarray(durations_s, dtype=float)
    events = np.concatenate((start, end))
    order = np.argsort(events, kind="stable")
    events = events[order]
    under_way = np.cumsum(np.concatenate((np.ones(start.size), -np.ones(end.size)))[order])
    slope = (under_way > 0).astype(float)
    covered = np.concatenate(([0.0], np.cumsum(np.diff(events) * slope[:-1])))
    edges = np.concatenate(([step_end_s[0] - dt_s], step_end_s))
    return np.clip(np.diff(np.interp(edges, events, covered)) / dt_s, 0.0, 1.0)


def rate_integral(
    starts_s: ArrayLike, ends_s: ArrayLike, rates: ArrayLike, edges_s: FloatArray
) -> FloatArray:
    """Integral over each span between consecutive ``edges_s`` of a sum of boxcar rates.

    Rate ``rates[i]`` (any unit per second) runs from ``starts_s[i]`` to ``ends_s[i]``;
    overlapping boxcars add. One sort and one interpolation, no loop over intervals.

    Returns
    -------
    numpy.ndarray
        ``edges_s.size − 1`` values, in the rate's unit times seconds.
    """
    start = np.asarray(starts_s, dtype=float)
    if start.size == 0:
        return np.zeros(max(edges_s.size - 1, 0))
    rate = np.asarray(rates, dtype=float)
    events = np.concatenate((start, np.asarray(ends_s, dtype=float)))
    deltas = np.concatenate((rate, -rate))
    order = np.argsort(events, kind="stable")
    events, running = events[order], np.cumsum(deltas[order])
    integral = np.concatenate(([0.0], np.cumsum(np.diff(events) * running[:-1])))
    return np.diff(np.interp(edges_s, events, integral))
