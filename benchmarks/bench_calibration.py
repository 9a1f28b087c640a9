"""Calibration: parameters recovered from trips simulated with known ones plus noise, and the
time to fit ten trips of one hour at 1 Hz (goal ≤ 5 s)."""

from __future__ import annotations

import datetime as dt
import time

import numpy as np

from benchmarks.common import REFERENCE, print_table
from core.calibration.fit import CHANNELS, MeasuredTrip, calibrate
from core.params import PRESETS, Location, VanParams
from core.physics.cycles import load_cycle_csv
from core.physics.simulate import simulate

TRIPS = 10
NOISE_W = 300.0
VIENNA = Location(lat=48.2, lon=16.37)


def hour_trips(truth: VanParams) -> list[MeasuredTrip]:
    """Ten trips of an hour each: the four cycles in turn until 3600 s, each trip starting
    with another, battery power as logged plus noise."""
    names = ["wltc_3b", "udds", "hwfet", "us06"]
    cycles = [load_cycle_csv(REFERENCE / "cycles" / f"{name}.csv").speed_mps for name in names]
    rng = np.random.default_rng(5)
    trips = []
    for k in range(TRIPS):
        parts, n = [], 0
        while n < 3601:
            part = cycles[(k + len(parts)) % len(cycles)]
            parts.append(part if not parts else part[1:])
            n += parts[-1].size
        speed = np.concatenate(parts)[:3601]
        start = dt.datetime(2026, 7, 15, 6 + k, tzinfo=dt.UTC)
        result = simulate(speed, 1.0, start, VIENNA, truth)
        power = np.sum([result.power_w[c] for c in CHANNELS["battery_power_w"]], axis=0)
        logged = np.concatenate([[power[0]], power])[: speed.size]
        trips.append(
            MeasuredTrip(
                id=f"hour-{k}",
                start=start,
                location=VIENNA,
                time_s=np.arange(speed.size, dtype=float),
                speed_mps=speed,
                measured_w={"battery_power_w": logged + rng.normal(0, NOISE_W, speed.size)},
                role="validation" if k >= TRIPS - 2 else None,
            )
        )
    return trips


def main() -> None:
    truth = PRESETS["ev-van-3.5t-reefer"].van()
    vehicle = truth.vehicle
    start = truth.model_copy(
        update={
            "vehicle": vehicle.model_copy(
                update={
                    "drag_coefficient": vehicle.drag_coefficient * 1.2,
                    "rolling_resistance_coefficient": vehicle.rolling_resistance_coefficient * 0.8,
                    "drivetrain_efficiency": vehicle.drivetrain_efficiency * 0.9,
                    "regen_efficiency": vehicle.regen_efficiency * 0.75,
                    "auxiliaries_power_w": vehicle.auxiliaries_power_w * 1.3,
                }
            )
        }
    )
    trips = hour_trips(truth)
    began = time.perf_counter()
    fit = calibrate(start, trips, [])
    fit_s = time.perf_counter() - began
    rows = [
        [
            p.name,
            f"{getattr(truth.vehicle, p.name):.5g}",
            f"{p.initial:.5g}",
            f"{p.value:.5g}",
            f"{p.ci95[0]:.5g} … {p.ci95[1]:.5g}",
            f"{(p.value / getattr(truth.vehicle, p.name) - 1) * 100:+.2f} %",
            "yes" if p.identifiable else "no",
        ]
        for p in fit.parameters
    ]
    print_table(
        f"Calibration: {TRIPS - 2} fitted + 2 validation trips of 1 h at 1 Hz, "
        f"{NOISE_W:.0f} W noise (real 3.5 t reefer)",
        ["parameter", "truth", "start", "fitted", "95 % interval", "error", "identifiable"],
        rows,
    )
    validation = fit.validation
    print_table(
        "Calibration: fit time and validation",
        ["fit [s]", "goal [s]", "validation RMSE [W]", "validation energy error"],
        [
            [
                f"{fit_s:.2f}",
                "5",
                " / ".join(f"{t.rmse_w:.0f}" for t in validation),
                " / ".join(f"{t.energy_error_pct:+.2f} %" for t in validation),
            ]
        ],
    )


if __name__ == "__main__":
    main()
