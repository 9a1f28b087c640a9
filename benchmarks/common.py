"""The benchmarks' own helpers: best wall times and tables (what they share with the tests is
in :mod:`testbed`)."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence


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
