"""Planner: round trips that look like delivery days beside LKH-3 (elkai) in the same run, TSP
quality on the reference instances (idle and with the other core busy), and end-to-end plan
latency."""

from __future__ import annotations

import csv
import datetime as dt
import time

import elkai
import numpy as np

from benchmarks.common import print_table
from core.params import Depot, Stop
from core.planning.model import PLAN_TIME_LIMIT, PlanProblem, default_work_s
from core.planning.round.planner import plan
from core.routing.effort import Effort
from core.routing.tsp import solve_tour, tour_cost
from testbed.reference import REFERENCE, euc_2d_matrix
from testbed.rounds import Round, clustered_round, uniform_round
from testbed.services import busy_core


def delivery_rounds() -> list[Round]:
    """Clustered rounds (3–8 clusters, the depot away from them) and uniform ones, 25–150
    stops, symmetric and with one-way streets."""
    rounds = []
    for k, (n, clusters) in enumerate(
        [(25, 3), (40, 3), (60, 5), (80, 4), (100, 6), (120, 8), (150, 5), (150, 8)]
    ):
        for asymmetric in (False, True):
            rounds.append(clustered_round(n, clusters, seed=100 + k, asymmetric=asymmetric))
    for k, n in enumerate((50, 100, 150)):
        for asymmetric in (False, True):
            rounds.append(uniform_round(n, seed=200 + k, asymmetric=asymmetric))
    return rounds


def lkh_cost(cost: np.ndarray) -> int:
    """LKH-3's tour (elkai, ten runs) on the same integer matrix."""
    order = elkai.DistanceMatrix(cost.tolist()).solve_tsp(runs=10)
    return tour_cost(cost, order)


def default_effort(stops: int) -> Effort:
    """A round's default search, as a request without time_limit_s or work_s gets it: the
    default limit for its stops as its cap, the default work of that limit."""
    limit_s = PLAN_TIME_LIMIT({"stops": range(stops)})
    return Effort.starting_now(default_work_s(limit_s), limit_s)


def round_quality() -> None:
    rows, gaps = [], {"clustered": [], "uniform": []}
    for case in delivery_rounds():
        started = time.perf_counter()
        theirs = lkh_cost(case.cost)
        their_s = time.perf_counter() - started
        tour = solve_tour(case.cost, default_effort(case.cost.shape[0] - 1))
        gap = (tour.cost / theirs - 1) * 100
        gaps["clustered" if case.clusters > 1 else "uniform"].append(gap)
        rows.append(
            [
                case.name,
                tour.cost,
                theirs,
                f"{gap:+.2f} %",
                tour.status,
                f"{tour.runtime_s * 1000:.0f}",
                f"{their_s * 1000:.0f}",
            ]
        )
    print_table(
        "Delivery rounds at the default limit and work for their size (as a request without "
        "time_limit_s) beside LKH-3 (elkai, 10 runs), same run",
        ["round", "ours [m]", "LKH-3 [m]", "gap", "status", "our time [ms]", "LKH time [ms]"],
        rows,
    )
    print_table(
        "Delivery rounds: gap to LKH-3",
        ["set", "rounds", "mean", "worst", "target"],
        [
            [name, len(v), f"{np.mean(v):+.2f} %", f"{max(v):+.2f} %", "≤ 0.1 % mean, ≤ 0.5 %"]
            for name, v in gaps.items()
        ],
    )


def tsp_quality(loaded: bool) -> None:
    rows, gaps = [], {"tsplib_small": [], "tsplib": [], "random": []}
    small_exact = []
    for folder, index, column in (
        ("tsplib", "optimal.csv", "optimal_length"),
        ("random", "reference.csv", "reference_length"),
    ):
        for entry in csv.DictReader((REFERENCE / folder / index).open()):
            cost = euc_2d_matrix(REFERENCE / folder / f"{entry['name']}.tsp")
            tour = solve_tour(cost, default_effort(cost.shape[0] - 1))
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
        f"TSP quality at the default work, 1 reference s ({load})",
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
            ["TSPLIB all", len(gaps["tsplib"]), f"{np.mean(gaps['tsplib']):.2f} %", "≤ 0.3 %"],
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
    round_quality()
    tsp_quality(loaded=False)
    with busy_core():
        tsp_quality(loaded=True)
    plan_latency()


if __name__ == "__main__":
    main()
