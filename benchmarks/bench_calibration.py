"""Calibration: parameters recovered from trips simulated with known ones plus noise, the time
to fit ten trips of one hour at 1 Hz (goal ≤ 5 s), and how often the 95 % intervals cover the
truth over 200 fits under noise as telematics log it (goal 90–98 %)."""

from __future__ import annotations

import datetime as dt
import time

import numpy as np

from benchmarks.common import print_table
from core.calibration.fit import CHANNELS, FitParameter, MeasuredTrip, calibrate
from core.params import PRESETS, Location, VanParams, Weather
from core.physics.cycles import load_cycle_csv
from core.physics.simulate import simulate
from testbed.reference import REFERENCE

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
        outside_c = 16.0 + k
        weather = Weather(t_min_c=outside_c, t_max_c=outside_c)
        result = simulate(speed, 1.0, start, VIENNA, truth, weather=weather)
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
                ambient_c=np.full(speed.size, outside_c),
                role="validation" if k >= TRIPS - 2 else None,
            )
        )
    return trips


#: The van the coverage fits recover: the reefer with more drag and rolling resistance.
COVERAGE_TRUTH = {
    "drag_coefficient": 0.41,
    "rolling_resistance_coefficient": 0.0095,
    "drivetrain_efficiency": 0.87,
    "regen_efficiency": 0.75,
    "auxiliaries_power_w": 620.0,
}
COVERAGE_FITS = 200


def coverage_trips(truth: VanParams, seed: int, rho: float) -> list[MeasuredTrip]:
    """Ten minutes of the WLTC, the HWFET, the UDDS and the WLTC again (held out), battery
    power logged with noise of 3 % of the power plus 150 W, AR(1) with ``rho`` in time."""
    rng = np.random.default_rng(seed)
    trips = []
    for k, name in enumerate(["wltc_3b", "hwfet", "udds", "wltc_3b"]):
        clean = _clean(truth, name, k)
        n = clean.size
        unit = np.empty(n)
        unit[0] = rng.normal()
        shocks = rng.normal(size=n) * np.sqrt(1 - rho**2)
        for t in range(1, n):
            unit[t] = rho * unit[t - 1] + shocks[t]
        trips.append(
            MeasuredTrip(
                id=f"{name}-{k}",
                start=dt.datetime(2026, 7, 15, 8 + k, tzinfo=dt.UTC),
                location=VIENNA,
                time_s=np.arange(n, dtype=float),
                speed_mps=_cycle(name)[:n],
                measured_w={"battery_power_w": clean + (0.03 * np.abs(clean) + 150.0) * unit},
                ambient_c=np.full(n, 18.0 + 2 * k),
                role="validation" if k == 3 else None,
            )
        )
    return trips


def _cycle(name: str) -> np.ndarray:
    return load_cycle_csv(REFERENCE / "cycles" / f"{name}.csv").speed_mps


_CLEAN: dict[tuple[str, int], np.ndarray] = {}


def _clean(truth: VanParams, name: str, k: int) -> np.ndarray:
    """The battery power the van logs over ten minutes of cycle ``name`` on trip ``k``."""
    if (name, k) not in _CLEAN:
        speed = _cycle(name)[:601]
        outside_c = 18.0 + 2 * k
        start = dt.datetime(2026, 7, 15, 8 + k, tzinfo=dt.UTC)
        weather = Weather(t_min_c=outside_c, t_max_c=outside_c)
        result = simulate(speed, 1.0, start, VIENNA, truth, weather=weather)
        power = np.sum([result.power_w[c] for c in CHANNELS["battery_power_w"]], axis=0)
        _CLEAN[name, k] = np.concatenate([[power[0]], power])[: speed.size]
    return _CLEAN[name, k]


def coverage() -> None:
    """How often the 95 % intervals cover the truth, over :data:`COVERAGE_FITS` fits each of
    independent and of time-correlated noise that grows with the power."""
    preset = PRESETS["ev-van-3.5t-reefer"].van()
    truth = preset.model_copy(update={"vehicle": preset.vehicle.model_copy(update=COVERAGE_TRUTH)})
    parameters = [FitParameter(name=name) for name in COVERAGE_TRUTH]  # type: ignore[arg-type]
    rows = []
    for rho in (0.0, 0.8):
        hits: dict[str, list[bool]] = {name: [] for name in COVERAGE_TRUTH}
        widths: dict[str, list[float]] = {name: [] for name in COVERAGE_TRUTH}
        began = time.perf_counter()
        for seed in range(COVERAGE_FITS):
            fit = calibrate(preset, coverage_trips(truth, seed, rho), parameters)
            for p in fit.parameters:
                assert p.ci95 is not None
                hits[p.name].append(p.ci95[0] <= COVERAGE_TRUTH[p.name] <= p.ci95[1])
                widths[p.name].append((p.ci95[1] - p.ci95[0]) / 2 / COVERAGE_TRUTH[p.name])
        seconds = time.perf_counter() - began
        pooled = np.mean([h for v in hits.values() for h in v])
        rows.append(
            [
                f"ρ = {rho:g}",
                *(f"{np.mean(hits[n]) * 100:.1f} % (±{np.mean(widths[n]) * 100:.1f} %)"
                  for n in COVERAGE_TRUTH),
                f"{pooled * 100:.1f} %",
                f"{seconds / COVERAGE_FITS:.2f}",
            ]
        )  # fmt: skip
    print_table(
        f"Calibration: 95 % intervals covering the truth over {COVERAGE_FITS} fits (noise 3 % "
        "of the power + 150 W, AR(1) ρ; goal 90–98 %; mean half-width in brackets)",
        ["noise", *COVERAGE_TRUTH, "pooled", "s per fit"],
        rows,
    )


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
            "not given" if p.ci95 is None else f"{p.ci95[0]:.5g} … {p.ci95[1]:.5g}",
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
    coverage()


if __name__ == "__main__":
    main()
