"""Energy core: simulation speed and the reference-vehicle comparison with FASTSim."""

from __future__ import annotations

import datetime as dt
from zoneinfo import ZoneInfo

import numpy as np

from benchmarks.common import best_time_s, print_table
from core.arrays import keep_heap
from core.params import PRESETS, STREET_TYPES, DoorOpening, Interval, Location, Weather
from core.physics.cycles import generate_leg, load_cycle_csv
from core.physics.simulate import Along, simulate
from core.physics.weather import HourlyWeather
from testbed.reference import REFERENCE

START = dt.datetime(2026, 7, 15, 8, tzinfo=ZoneInfo("Europe/Vienna"))
VIENNA = Location(lat=48.21, lon=16.37)
# shared/reference/cycles/REFERENCE.md
FASTSIM_WH_KM = {"udds": 105.3, "hwfet": 133.1, "us06": 186.7, "wltc_3b": 143.2}
FASTSIM_SIM_S_PER_S = 43_000


def delivery_day_trace() -> tuple[np.ndarray, list[DoorOpening], np.ndarray, list[Interval]]:
    """A 4-hour, 1 Hz delivery day: 20 urban legs with 5-minute stops, payload dropping."""
    legs, doors, payload, parked, clock_s, load_kg = [], [], [], [], 0, 500.0
    while clock_s < 4 * 3600:
        leg = generate_leg(2500, STREET_TYPES["urban"], 0.5, 2.0)
        stop = np.zeros(300)
        legs += [leg, stop]
        payload += [np.full(leg.size, load_kg), np.full(stop.size, load_kg)]
        doors.append(DoorOpening(start_s=clock_s + leg.size + 30, duration_s=120))
        parked.append(Interval(start_s=clock_s + leg.size, duration_s=300))
        clock_s += leg.size + stop.size
        load_kg = max(load_kg - 25, 0.0)
    n = 4 * 3600 + 1
    parked = [p for p in parked if p.start_s < n - 1]
    doors = [d for d in doors if d.start_s < n - 1]
    return np.concatenate(legs)[:n], doors, np.concatenate(payload)[:n], parked


def hourly_forecast() -> HourlyWeather:
    """A summer day's hourly forecast with sun and a 6 m/s westerly, as a service sends it."""
    hours = np.arange(48)
    day = START.astimezone(dt.UTC).replace(hour=0)
    return HourlyWeather(
        time_utc_s=day.timestamp() + hours * 3600.0,
        temperature_c=24 + 6 * np.sin((hours % 24 - 9) / 24 * 2 * np.pi),
        direct_radiation_w_m2=np.clip(650 * np.sin((hours % 24 - 5) / 14 * np.pi), 0, None),
        diffuse_radiation_w_m2=np.clip(120 * np.sin((hours % 24 - 5) / 14 * np.pi), 0, None),
        wind_speed_mps=np.full(48, 6.0),
        wind_direction_deg=np.full(48, 270.0),
    )


def main() -> None:
    speed, doors, payload, parked = delivery_day_trace()
    # the road turns: a new heading every 20 s, as a router's segments give them
    heading = np.repeat(np.arange(0, speed.size, 20) * 7.0 % 360, 20)[: speed.size]
    cases = [
        (
            "paper-generic (steady box, Table 2 cab, daily sine)",
            PRESETS["paper-generic"].van(),
            Weather(t_min_c=17, t_max_c=30),
            None,
        ),
        (
            "ev-van-3.5t-reefer (dynamic box, cab off at stops, derating, forecast, wind)",
            PRESETS["ev-van-3.5t-reefer"].van(),
            hourly_forecast(),
            heading,
        ),
    ]
    rows = []
    # A library user's process first (glibc's defaults), then as the service's worker
    # processes run (core.arrays.keep_heap; the rest of `make bench` runs so too).
    for allocator in ("glibc defaults", "as the service's workers (keep_heap)"):
        if allocator != "glibc defaults":
            keep_heap()
        for label, van, weather, headings in cases:

            def run(van=van, weather=weather, headings=headings) -> object:
                return simulate(
                    speed,
                    1.0,
                    START,
                    VIENNA,
                    van,
                    weather=weather,
                    along=Along(
                        payload_kg=payload, door_openings=doors, parked=parked, heading_deg=headings
                    ),
                )

            seconds = best_time_s(run, repeat=15, number=5)
            rows.append(
                [
                    label,
                    allocator,
                    speed.size,
                    f"{seconds * 1e3:.2f}",
                    f"{(speed.size - 1) / seconds:,.0f}",
                    f"{FASTSIM_SIM_S_PER_S:,}",
                    "5,000,000",
                ]
            )
    print_table(
        "Simulation speed (4-hour 1 Hz delivery day, every consumer, 20 stops with door "
        "openings, SoC)",
        [
            "van and terms",
            "memory allocator",
            "samples",
            "wall time [ms]",
            "simulated s per wall s",
            "FASTSim (same machine)",
            "target",
        ],
        rows,
    )
    rows = []
    zoe = PRESETS["reference-zoe"].van()
    for name, reference in FASTSIM_WH_KM.items():
        cycle = load_cycle_csv(REFERENCE / "cycles" / f"{name}.csv")
        result = simulate(
            cycle.speed_mps, cycle.dt_s, START, VIENNA, zoe, along=Along(grade=cycle.grade)
        )
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
