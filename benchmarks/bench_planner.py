"""Planner: TSP quality on the reference instances (idle and with the other core busy), and
end-to-end plan latency."""

from __future__ import annotations

import csv
import datetime as dt
import time

import numpy as np

from benchmarks.common import REFERENCE, busy_core, euc_2d_matrix, print_table
from core.params import Depot, Stop
from core.planning.model import PlanProblem
from core.planning.round import plan
from core.routing.tsp import solve_tour


def tsp_quality(loaded: bool) -> None:
    rows, gaps = [], {"tsplib_small": [], "tsplib": [], "random": []}
    small_exact = []
    for folder, index, column in (
        ("tsplib", "optimal.csv", "optimal_length"),
        ("random", "reference.csv", "reference_length"),
    ):
        for entry in csv.DictReader((REFERENCE / folder / index).open()):
            cost = euc_2d_matrix(REFERENCE / folder / f"{entry['name']}.tsp")
            tour = solve_tour(cost, time_limit_s=1.0)
            reference = int(entry[column])
            gap = (tour.cost / reference - 1) * 100
            n = int(entry["n"])
            gaps[folder].append(gap)
            if folder == "tsplib" and n <= 105:
                gaps["tsplib_small"].append(gap)
            if n <= 21:
                small_exact.append((tour.status == "optimal", tour.runtime_s))
            rows.append(
                [
                    entry["name"],
                    n,
                    tour.cost,
                    reference,
                    f"{gap:.2f} %",
                    tour.status,
                    f"{tour.runtime_s * 1000:.0f}",
                ]
            )
    load = "with the other core busy" if loaded else "idle machine"
    print_table(
        f"TSP quality at the default 1 s budget ({load})",
        ["instance", "nodes", "length", "reference", "gap", "status", "time [ms]"],
        rows,
    )
    print_table(
        f"TSP summary ({load})",
        ["set", "instances", "mean gap", "target"],
        [
            [
                "TSPLIB ≤ 105 nodes",
                len(gaps["tsplib_small"]),
                f"{np.mean(gaps['tsplib_small']):.2f} %",
                "≤ 0.3 %",
            ],
            ["TSPLIB all", len(gaps["tsplib"]), f"{np.mean(gaps['tsplib']):.2f} %", "≤ 1.0 %"],
            ["random all", len(gaps["random"]), f"{np.mean(gaps['random']):.2f} %", "—"],
            [
                "≤ 20 stops proven optimal",
                len(small_exact),
                f"{sum(ok for ok, _ in small_exact)}/{len(small_exact)}, max "
                f"{max(t for _, t in small_exact) * 1000:.0f} ms",
                "all, < 50 ms",
            ],
        ],
    )


def plan_latency() -> None:
    rows = []
    for n in (8, 25, 50, 100):
        rng = np.random.default_rng(n)
        stops = [
            Stop(
                id=f"S{i}",
                lat=48.21 + rng.uniform(-0.05, 0.05),
                lon=16.37 + rng.uniform(-0.08, 0.08),
                delivery_kg=400 / n,
                door_open_s=90,
            )
            for i in range(n)
        ]
        problem = PlanProblem(
            date=dt.date(2026, 7, 15),
            timezone="Europe/Vienna",
            depot=Depot(lat=48.21, lon=16.37),
            stops=stops,
        )
        result = plan(problem)
        seconds = []
        for _ in range(7):
            started = time.perf_counter()
            plan(problem)
            seconds.append(time.perf_counter() - started)
        rows.append(
            [
                n,
                f"{np.percentile(seconds, 50) * 1000:.0f}",
                f"{result.solved.runtime_s * 1000:.0f}",
                result.solved.status,
                f"{result.duration_s / 3600:.1f}",
                f"{result.energy_kwh['total']:.1f}",
            ]
        )
    print_table(
        "Plan latency end to end, in-process (tour + full simulation), objective distance, "
        "p50 of 7 runs (target: 50 stops ≤ 150 ms)",
        ["stops", "p50 [ms]", "solver [ms]", "status", "round [h]", "energy [kWh]"],
        rows,
    )


def main() -> None:
    tsp_quality(loaded=False)
    with busy_core():
        tsp_quality(loaded=True)
    plan_latency()


if __name__ == "__main__":
    main()
