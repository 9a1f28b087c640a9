"""Energy core: simulation speed and the reference-vehicle comparison with FASTSim."""

from __future__ import annotations

import datetime as dt
from zoneinfo import ZoneInfo

import numpy as np

from benchmarks.common import REFERENCE, best_time_s, print_table
from core.cycles import generate_leg, load_cycle_csv
from core.params import PRESETS, STREET_TYPES, DoorOpening, Location, Weather
from core.simulate import simulate

START = dt.datetime(2026, 7, 15, 8, tzinfo=ZoneInfo("Europe/Vienna"))
VIENNA = Location(lat=48.21, lon=16.37)
# shared/reference/cycles/REFERENCE.md
FASTSIM_WH_KM = {"udds": 105.3, "hwfet": 133.1, "us06": 186.7, "wltc_3b": 143.2}
FASTSIM_SIM_S_PER_S = 43_000


def delivery_day_trace() -> tuple[np.ndarray, list[DoorOpening], np.ndarray]:
    """A 4-hour, 1 Hz delivery day: 20 urban legs with 5-minute stops, payload dropping."""
    legs, doors, payload, clock_s, load_kg = [], [], [], 0, 550.0
    while clock_s < 4 * 3600:
        leg = generate_leg(2500, STREET_TYPES["urban"], 0.5, 2.0)
        stop = np.zeros(300)
        legs += [leg, stop]
        payload += [np.full(leg.size, load_kg), np.full(stop.size, load_kg)]
        doors.append(DoorOpening(start_s=clock_s + leg.size + 30, duration_s=120))
        clock_s += leg.size + stop.size
        load_kg = max(load_kg - 25, 0.0)
    return np.concatenate(legs)[: 4 * 3600 + 1], doors, np.concatenate(payload)[: 4 * 3600 + 1]


def main() -> None:
    speed, doors, payload = delivery_day_trace()
    van = PRESETS["paper-generic"].van()
    weather = Weather(t_min_c=17, t_max_c=30)

    def run() -> object:
        return simulate(
            speed, 1.0, START, VIENNA, van, payload_kg=payload, weather=weather, door_openings=doors
        )

    seconds = best_time_s(run, repeat=7, number=5)
    simulated = speed.size - 1
    rate = simulated / seconds
    print_table(
        "Simulation speed (4-hour 1 Hz delivery day, every consumer, door openings, SoC)",
        ["samples", "wall time [ms]", "simulated s per wall s", "FASTSim (same machine)", "target"],
        [
            [
                speed.size,
                f"{seconds * 1e3:.2f}",
                f"{rate:,.0f}",
                f"{FASTSIM_SIM_S_PER_S:,}",
                "5,000,000",
            ]
        ],
    )
    rows = []
    zoe = PRESETS["reference-zoe"].van()
    for name, reference in FASTSIM_WH_KM.items():
        cycle = load_cycle_csv(REFERENCE / "cycles" / f"{name}.csv")
        result = simulate(cycle.speed_mps, cycle.dt_s, START, VIENNA, zoe, grade=cycle.grade)
        ours = result.energy_kwh["traction"] * 1e6 / result.distance_m
        rows.append(
            [
                name,
                f"{result.distance_m / 1000:.3f}",
                f"{ours:.1f}",
                f"{reference:.1f}",
                f"{(ours / reference - 1) * 100:+.1f} %",
            ]
        )
    print_table(
        "Reference vehicle (FASTSim 2022 Renault Zoe ZE50) — traction [Wh/km]",
        ["cycle", "distance [km]", "coldroute", "FASTSim 3.1.0", "difference"],
        rows,
    )


if __name__ == "__main__":
    main()
