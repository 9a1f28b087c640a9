"""When a charging station takes no charge — closed, or every point taken by other vehicles —
as spans of time a charge must fit between (a vehicle waits for the next that has room)."""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from core.arrays import FloatArray

T = TypeVar("T", float, dt.datetime)

Span = tuple[float, float]


def full_spans(spans: Sequence[tuple[T, T]], points: int) -> list[tuple[T, T]]:
    """When at least ``points`` of ``spans`` (from, to) overlap: a station of ``points`` with
    vehicles charging over ``spans`` has none free."""
    events = sorted([(a, 1) for a, _ in spans] + [(b, -1) for _, b in spans])  # ends first
    full: list[tuple[T, T]] = []
    taken, since = 0, None
    for moment, step in events:
        taken += step
        if taken >= points and since is None:
            since = moment
        elif taken < points and since is not None:
            if moment > since:
                full.append((since, moment))
            since = None
    return full


def outside(windows: Sequence[Span]) -> list[Span]:
    """The time outside sorted, non-overlapping ``windows`` (none: always open)."""
    if not windows:
        return []
    edges = [-math.inf, *(t for window in windows for t in window), math.inf]
    return [(edges[k], edges[k + 1]) for k in range(0, len(edges), 2) if edges[k] < edges[k + 1]]


@dataclass(frozen=True)
class Closed:
    """Per place, the sorted spans that do not overlap when it takes no charge, in one array
    (place ``p``'s are ``start[ptr[p]:ptr[p + 1]]``, ``end[...]``); :attr:`key` names them."""

    ptr: NDArray[np.int64]
    start: FloatArray
    end: FloatArray
    key: tuple[tuple[int, float, float], ...]

    @classmethod
    def of(cls, spans: Mapping[int, Sequence[Span]], size: int) -> Closed:
        """``spans`` by place (any order, overlapping or not) for ``size`` places."""
        merged = {p: _merged(s) for p, s in spans.items()}
        counts = np.zeros(size + 1, dtype=np.int64)
        for p, s in merged.items():
            counts[p + 1] = len(s)
        ptr = np.cumsum(counts)
        flat = [span for p in sorted(merged) for span in merged[p]]
        key = tuple((p, a, b) for p in sorted(merged) for a, b in merged[p])
        start = np.array([a for a, _ in flat], dtype=float)
        end = np.array([b for _, b in flat], dtype=float)
        return cls(ptr, start, end, key)

    def spans(self) -> dict[int, list[Span]]:
        """The spans by place."""
        out: dict[int, list[Span]] = {}
        for p, a, b in self.key:
            out.setdefault(p, []).append((a, b))
        return out


def _merged(spans: Sequence[Span]) -> list[Span]:
    out: list[Span] = []
    for a, b in sorted(spans):
        if b <= a:
            continue
        if out and a <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out
