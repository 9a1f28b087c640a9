"""Fleet planning: Solomon's instances beside PyVRP at the same budget, and a battery-limited day
where a plan without the energy constraint sends vans out that the simulation says run flat."""

from __future__ import annotations

import datetime as dt
import math
import resource
import time
from multiprocessing import Queue, get_context

import numpy as np

from benchmarks.common import print_table
from core.params import PRESETS, BatteryParams, Depot, Stop, TimeWindow, Weather
from core.planning.fleet.planner import plan_fleet
from core.planning.model import FleetProblem, FleetResult, FleetVehicle, PlanProblem
from core.planning.round.planner import plan
from testbed.fleets import SOLOMON, pyvrp_solomon, solomon, solomon_problem, vienna_grid


def solomon_table(budgets: tuple[float, ...] = (10.0, 60.0)) -> None:
    rows = []
    gaps: dict[tuple[float, bool], list[float]] = {}
    for name, (best_distance, (best_vans, best_vans_distance)) in SOLOMON.items():
        instance = solomon(name)
        for budget in budgets:
            for minimize in (False, True):
                theirs, their_vans = pyvrp_solomon(instance, budget, minimize)
                started = time.perf_counter()
                ours = plan_fleet(solomon_problem(instance, budget, minimize))
                elapsed = time.perf_counter() - started
                distance = ours.distance_m / (instance.km_per_unit * 1000.0)
                gap = (distance / theirs - 1) * 100
                gaps.setdefault((budget, minimize), []).append(gap)
                best = f"{best_vans}, {best_vans_distance}" if minimize else f"{best_distance}"
                rows.append(
                    [
                        name,
                        f"{budget:.0f} s",
                        "vans, then distance" if minimize else "distance",
                        f"{distance:.1f}",
                        ours.vehicles_used,
                        len(ours.unassigned),
                        f"{theirs:.1f}",
                        their_vans,
                        f"{gap:+.2f} %",
                        best,
                        f"{elapsed:.1f}",
                        ours.stopped_by,
                    ]
                )
    print_table(
        "Solomon VRPTW (100 customers, 25 vans): coldroute given time_limit_s alone (the work "
        "its default share) vs PyVRP 0.14 at the same time on the same instance, same run",
        [
            "instance",
            "budget",
            "objective",
            "ours",
            "vans",
            "unserved",
            "PyVRP",
            "vans",
            "ours vs PyVRP",
            "best known (vans, distance)",
            "our wall time [s]",
            "stopped_by",
        ],
        rows,
    )
    print_table(
        "Solomon: ours vs PyVRP's distance",
        ["budget", "objective", "mean", "worst"],
        [
            [
                f"{budget:.0f} s",
                "vans, then distance" if minimize else "distance",
                f"{np.mean(values):+.2f} %",
                f"{max(values):+.2f} %",
            ]
            for (budget, minimize), values in gaps.items()
        ],
    )


def city_problem(battery_kwh: float) -> FleetProblem:
    """About 60 stops around Vienna, 4 vans of 40 kWh, a 31 °C day, shops' morning windows."""
    rng = np.random.default_rng(7)
    stops = []
    for k in range(60):
        radius_km, angle = 3 + 14 * math.sqrt(rng.random()), rng.uniform(0, 2 * math.pi)
        opens = int(rng.integers(6, 12))
        stops.append(
            Stop(
                id=f"s{k:02d}",
                lat=48.2082 + radius_km * math.sin(angle) / 111,
                lon=16.3738 + radius_km * math.cos(angle) / 74,
                service_time_s=float(rng.integers(240, 600)),
                door_open_s=float(rng.integers(60, 240)),
                delivery_kg=float(rng.integers(5, 30)),
                time_windows=(
                    [TimeWindow(start=f"{opens:02d}:00", end=f"{opens + 3:02d}:00")]
                    if rng.random() < 0.5
                    else []
                ),
            )
        )
    van = (
        PRESETS["paper-generic"]
        .van()
        .model_copy(
            update={"battery": BatteryParams(usable_capacity_kwh=battery_kwh, min_soc=0.15)}
        )
    )
    return FleetProblem(
        date=dt.date(2026, 7, 15),
        timezone="Europe/Vienna",
        depot=Depot(id="depot", lat=48.1703, lon=16.4207),
        vehicles=[
            FleetVehicle(id=f"van-{k}", van=van, shift_start="06:00", shift_end="20:00")
            for k in range(4)
        ],
        stops=stops,
        weather=Weather(t_min_c=20, t_max_c=31),
        objective="distance",
        time_limit_s=10,
    )


def lowest_charges_as_driven(result: FleetResult, problem: FleetProblem) -> list[float]:
    """Each route's lowest state of charge in its own simulation with the real 40 kWh battery."""
    stops = {s.id: s for s in problem.stops}
    van = (
        PRESETS["paper-generic"]
        .van()
        .model_copy(update={"battery": BatteryParams(usable_capacity_kwh=40.0, min_soc=0.15)})
    )
    return [
        plan(
            PlanProblem(
                date=problem.date,
                timezone=problem.timezone,
                start_time=route.plan.legs[0].depart.time(),
                depot=problem.depot,
                stops=[stops[s.id] for s in route.plan.stops],
                van=van,
                weather=problem.weather,
                keep_order=True,
            )
        ).battery.min_soc
        for route in result.routes
    ]


def battery_table() -> None:
    rows = []
    for label, battery in (("without the energy constraint", 2000.0), ("coldroute", 40.0)):
        problem = city_problem(battery)
        started = time.perf_counter()
        result = plan_fleet(problem)
        elapsed = time.perf_counter() - started
        charges = lowest_charges_as_driven(result, problem)
        rows.append(
            [
                label,
                result.vehicles_used,
                len(result.routes),
                sum(charge < 0.15 - 1e-12 for charge in charges),
                len(result.unassigned),
                f"{result.distance_m / 1000:.0f}",
                f"{result.energy_kwh['total']:.1f}",
                f"{min(charges, default=1.0):.0%}",
                result.verification_rounds,
                f"{elapsed:.1f}",
            ]
        )
    print_table(
        "Battery-limited day: 60 stops around Vienna, 4 paper vans of 40 kWh (reserve 15 %), "
        "31 °C, 10 s",
        [
            "plan",
            "vans",
            "routes",
            "routes that run below the reserve (simulated, 40 kWh)",
            "unserved",
            "km",
            "kWh",
            "lowest charge (simulated, 40 kWh)",
            "verifications",
            "time [s]",
        ],
        rows,
    )


def _scale_case(n_stops: int, n_vans: int, time_limit_s: float, out: Queue) -> None:
    started = time.perf_counter()
    result = plan_fleet(vienna_grid(n_stops, n_vans, time_limit_s))
    elapsed = time.perf_counter() - started
    reasons = sorted({u.reason for u in result.unassigned})
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    served = sum(len(r.plan.stops) for r in result.routes)
    out.put(
        [
            n_stops,
            n_vans,
            f"{time_limit_s:.0f} s",
            served,
            result.vehicles_used,
            ", ".join(reasons) or "—",
            f"{elapsed:.1f}",
            f"{peak_mb:.0f}",
        ]
    )


def scale_table() -> None:
    """Each case in a fresh process, so its peak memory is its own."""
    rows = []
    context = get_context("spawn")
    for n_stops, n_vans, limit in ((200, 3, 10.0), (200, 100, 10.0), (1000, 50, 60.0)):
        out = context.Queue()
        process = context.Process(target=_scale_case, args=(n_stops, n_vans, limit, out))
        process.start()
        rows.append(out.get())
        process.join()
    print_table(
        "Fleets at scale: stops of 1 kg on a grid in central Vienna, paper vans (40 kWh, 400 kg), "
        "shifts 06:30–16:30",
        [
            "stops",
            "vans",
            "time limit",
            "served",
            "vans used",
            "unassigned reasons",
            "wall time [s]",
            "peak memory [MB]",
        ],
        rows,
    )


def main() -> None:
    solomon_table()
    scale_table()
    battery_table()


if __name__ == "__main__":
    main()
