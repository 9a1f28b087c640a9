"""Fleet days for tests and benchmarks: Solomon's VRPTW instances as a city's day (and PyVRP
on the same rounded instance), and a grid of stops in central Vienna."""

from __future__ import annotations

import datetime as dt
import math
from dataclasses import dataclass

import numpy as np

from core.params import PRESETS, BatteryParams, Depot, RoadMatrix, Stop, TimeWindow, Weather
from core.planning.model import FleetProblem, FleetVehicle
from testbed.reference import REFERENCE, pyvrp_vrptw

#: Solomon's instances as a city: one distance unit is ``UNIT_KM[name]`` km and the same time
#: unit that many minutes (60 km/h, the literature's travel time = distance), so the horizon
#: fits in a day (C201's 3390 units are 22.6 h at 0.4 min). Windows become whole minutes
#: (opening rounded up, closing down), and PyVRP solves the same rounded instance.
UNIT_KM = {"C201": 0.4}


#: The seven instances and their best-known values: distance only, (fewest vans, distance).
SOLOMON = {
    "C101": (827.3, (10, 828.94)),
    "C201": (589.1, (3, 591.56)),
    "R101": (1637.7, (19, 1650.80)),
    "R201": (1143.2, (4, 1252.37)),
    "RC101": (1619.8, (14, 1696.94)),
    "RC201": (1261.8, (4, 1406.94)),
    "RC208": (776.1, (3, 828.14)),
}


MINUTE_S = 60.0


#: PyVRP works on integers: distances scaled by this, as in its own benchmarks.
PYVRP_SCALE = 100


VANS = 25


@dataclass(frozen=True)
class Solomon:
    """One instance in minutes: the depot first, then the customers."""

    name: str
    xy: np.ndarray  # the instance's units
    distance: np.ndarray
    minutes_per_unit: float
    demand: list[float]
    service_min: list[float]
    window_min: list[tuple[int, int]]  # whole minutes, the depot's the horizon
    capacity: float

    @property
    def km_per_unit(self) -> float:
        return self.minutes_per_unit


def solomon(name: str) -> Solomon:
    lines = (REFERENCE / "vrptw" / f"{name}.txt").read_text().splitlines()
    capacity = next(
        float(line.split()[1])
        for k, line in enumerate(lines)
        if k and "CAPACITY" in lines[k - 1] and len(line.split()) == 2
    )
    rows = [
        [float(x) for x in line.split()]
        for line in lines
        if line.split() and line.split()[0].isdigit() and len(line.split()) == 7
    ]
    xy = np.array([[r[1], r[2]] for r in rows])
    scale = UNIT_KM.get(name, 1.0)
    horizon = math.floor(rows[0][5] * scale) - 1  # shifts end before midnight
    windows = [(math.ceil(r[4] * scale), min(math.floor(r[5] * scale), horizon)) for r in rows]
    return Solomon(
        name,
        xy,
        np.sqrt(((xy[:, None] - xy[None]) ** 2).sum(-1)),
        scale,
        [r[3] for r in rows],
        [r[6] * scale for r in rows],
        [(0, horizon), *windows[1:]],
        capacity,
    )


def clock(minutes: float) -> str:
    return f"{int(minutes) // 60:02d}:{int(minutes) % 60:02d}"


def solomon_problem(
    instance: Solomon, time_limit_s: float, minimize_vehicles: bool
) -> FleetProblem:
    van = (
        PRESETS["paper-generic"]
        .van()
        .model_copy(
            update={
                "battery": BatteryParams(usable_capacity_kwh=1000.0),
                "payload_kg": instance.capacity,
            }
        )
    )
    unit_m = instance.km_per_unit * 1000.0
    unit_s = instance.minutes_per_unit * MINUTE_S
    return FleetProblem(
        date=dt.date(2026, 4, 15),
        timezone="UTC",
        depot=Depot(
            id="depot",
            lat=48.0 + instance.xy[0, 1] * instance.km_per_unit / 111,
            lon=16.0 + instance.xy[0, 0] * instance.km_per_unit / 74,
        ),
        vehicles=[
            FleetVehicle(
                id=f"v{k}",
                van=van,
                shift_start="00:00",
                shift_end=clock(instance.window_min[0][1]),
                breaks="none",  # Solomon's rules have none
            )
            for k in range(VANS)
        ],
        stops=[
            Stop(
                id=f"c{k}",
                lat=48.0 + instance.xy[k, 1] * instance.km_per_unit / 111,
                lon=16.0 + instance.xy[k, 0] * instance.km_per_unit / 74,
                delivery_kg=instance.demand[k],
                service_time_s=instance.service_min[k] * MINUTE_S,
                door_open_s=min(60.0, instance.service_min[k] * MINUTE_S),
                time_windows=[TimeWindow(start=clock(a), end=clock(b))]
                if (a, b) != (0, instance.window_min[0][1])
                else [],
            )
            for k, (a, b) in enumerate(instance.window_min)
            if k
        ],
        matrix=RoadMatrix(
            distances_m=(instance.distance * unit_m).tolist(),
            durations_s=(instance.distance * unit_s).tolist(),
        ),
        weather=Weather(t_min_c=8, t_max_c=18),
        objective="distance",
        minimize_vehicles=minimize_vehicles,
        **same_wall_time(time_limit_s),
    )


def same_wall_time(budget_s: float) -> dict[str, float]:
    """The product's search at the peer's wall time, as users send it: the time limit alone
    (its work the default share of it)."""
    return {"time_limit_s": budget_s}


def pyvrp_solomon(
    instance: Solomon, time_limit_s: float, minimize_vehicles: bool
) -> tuple[float, int]:
    """PyVRP on the same instance at the same budget: distance [units] and vans; with
    ``minimize_vehicles`` a fixed cost per van larger than any set of routes."""
    distance, vans, served = pyvrp_vrptw(
        instance.distance,
        instance.demand,
        instance.service_min,
        instance.window_min,
        instance.minutes_per_unit,
        instance.capacity,
        VANS,
        time_limit_s,
        fixed_cost=minimize_vehicles,
        scale=PYVRP_SCALE,
    )
    assert served == len(instance.window_min) - 1
    return distance, vans


def vienna_grid(n_stops: int, n_vans: int, time_limit_s: float) -> FleetProblem:
    """``n_stops`` stops of 1 kg on a grid in central Vienna (60 s service, 30 s door), paper
    vans with 40 kWh and 400 kg, shifts 06:30–16:30."""
    rng = np.random.default_rng(3)
    side = math.ceil(math.sqrt(n_stops))
    stops = [
        Stop(
            id=f"s{k}",
            lat=48.19 + (k // side) * 0.0009 + rng.normal() * 1e-4,
            lon=16.35 + (k % side) * 0.0013 + rng.normal() * 1e-4,
            service_time_s=60,
            door_open_s=30,
            delivery_kg=1.0,
        )
        for k in range(n_stops)
    ]
    van = (
        PRESETS["paper-generic"]
        .van()
        .model_copy(
            update={"battery": BatteryParams(usable_capacity_kwh=40.0), "payload_kg": 400.0}
        )
    )
    return FleetProblem(
        date=dt.date(2026, 5, 12),
        timezone="Europe/Vienna",
        depot=Depot(id="depot", lat=48.1703, lon=16.4207),
        vehicles=[
            FleetVehicle(id=f"v{k}", van=van, shift_start="06:30", shift_end="16:30")
            for k in range(n_vans)
        ],
        stops=stops,
        weather=Weather(t_min_c=12, t_max_c=22),
        objective="distance",
        **same_wall_time(time_limit_s),
    )
