"""Helpers shared by the benchmarks: reference data location and table printing."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

REFERENCE = Path(__file__).resolve().parents[1].parent / "shared" / "reference"


def best_time_s(run: Callable[[], object], repeat: int = 5, number: int = 1) -> float:
    """Best wall-clock time of ``number`` calls, over ``repeat`` rounds [s per call]."""
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            run()
        best = min(best, (time.perf_counter() - start) / number)
    return best


def print_table(title: str, header: Sequence[str], rows: Sequence[Sequence[object]]) -> None:
    """Print a Markdown table with a title."""
    print(f"\n### {title}\n")
    print("| " + " | ".join(header) + " |")
    print("|" + "|".join("---" for _ in header) + "|")
    for row in rows:
        print("| " + " | ".join(str(cell) for cell in row) + " |")


def euc_2d_matrix(path: Path) -> np.ndarray:
    """Integer distance matrix of a TSPLIB EUC_2D instance: nint(euclidean distance)."""
    lines = path.read_text().splitlines()
    start = lines.index("NODE_COORD_SECTION") + 1
    points = []
    for line in lines[start:]:
        if line.strip() in ("EOF", ""):
            break
        _, x, y = line.split()[:3]
        points.append((float(x), float(y)))
    xy = np.array(points)
    distance = np.sqrt(((xy[:, None, :] - xy[None, :, :]) ** 2).sum(axis=-1))
    return np.floor(distance + 0.5).astype(np.int64)
