"""Studies: a speed sweep of 11 speeds and a 3×3×3 scenario grid on an 8-stop round."""

from __future__ import annotations

import datetime as dt
from zoneinfo import ZoneInfo

import numpy as np

from benchmarks.common import best_time_s, print_table
from core.params import Depot, Location, Stop, VanParams, Weather
from core.planning.model import PlanProblem
from core.planning.studies import GridAxes, Season, SweepTrips, scenario_grid, speed_sweep


def main() -> None:
    noon = dt.datetime(2026, 7, 15, 12, tzinfo=ZoneInfo("Europe/Vienna"))
    vienna = Location(lat=48.21, lon=16.37)
    speeds = [float(v) for v in range(20, 121, 10)]
    sweep_s = best_time_s(
        lambda: speed_sweep(
            speeds, SweepTrips(20_000), noon, vienna, VanParams(), Weather(t_min_c=20, t_max_c=32)
        )
    )
    rng = np.random.default_rng(8)
    stops = [
        Stop(
            id=f"S{i}",
            lat=48.21 + rng.uniform(-0.04, 0.04),
            lon=16.37 + rng.uniform(-0.06, 0.06),
            delivery_kg=40,
            door_open_s=120,
        )
        for i in range(8)
    ]
    problem = PlanProblem(
        date=dt.date(2026, 7, 15),
        start_time=dt.time(9),
        timezone="Europe/Vienna",
        depot=Depot(lat=48.21, lon=16.37),
        stops=stops,
    )
    seasons = [
        Season(name=name, date=dt.date(2026, month, 15))
        for name, month in (("winter", 1), ("spring", 4), ("summer", 7))
    ]
    grid_s = best_time_s(
        lambda: scenario_grid(problem, GridAxes(seasons, [0.2, 0.5, 1.0], [0.2, 0.5, 0.8])),
        repeat=3,
    )
    print_table(
        "Studies (core, one process)",
        ["study", "size", "time [ms]", "target"],
        [
            ["speed sweep, 20 km trips", "11 speeds", f"{sweep_s * 1000:.0f}", "well under 1 s"],
            [
                "scenario grid, 8-stop round",
                "3 × 3 × 3 cells",
                f"{grid_s * 1000:.0f}",
                "well under 1 s",
            ],
        ],
    )


if __name__ == "__main__":
    main()
