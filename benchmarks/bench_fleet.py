"""Fleet planning: Solomon's RC208 beside PyVRP at the same budget, and a battery-limited day
where a plan without the energy constraint sends vans out that the simulation says run flat."""

from __future__ import annotations

import datetime as dt
import math
import time

import numpy as np
from pyvrp import Model
from pyvrp.stop import MaxRuntime

from benchmarks.common import REFERENCE, print_table
from core.params import PRESETS, BatteryParams, Depot, RoadMatrix, Stop, TimeWindow, Weather
from core.planning.fleet import plan_fleet
from core.planning.model import FleetProblem, FleetResult, FleetVehicle, PlanProblem
from core.planning.round import plan

#: RC208 as a city: one coordinate unit is 1 km, one time unit a minute (60 km/h, the
#: literature's travel time = distance), the horizon 00:00–16:00.
KM_M = 1000.0
MINUTE_S = 60.0
#: PyVRP works on integers: coordinates and times scaled by this, as in its own benchmarks.
PYVRP_SCALE = 100


def rc208() -> tuple[np.ndarray, list[list[float]]]:
    rows = [
        [float(x) for x in line.split()]
        for line in (REFERENCE / "vrptw" / "RC208.txt").read_text().splitlines()
        if line.split() and line.split()[0].isdigit() and len(line.split()) == 7
    ]
    xy = np.array([[r[1], r[2]] for r in rows])
    return np.sqrt(((xy[:, None] - xy[None]) ** 2).sum(-1)), rows


def clock(minutes: float) -> str:
    return f"{int(minutes) // 60:02d}:{int(minutes) % 60:02d}"


def rc208_problem(time_limit_s: float, minimize_vehicles: bool) -> FleetProblem:
    distance, rows = rc208()
    depot, customers = rows[0], rows[1:]
    van = (
        PRESETS["paper-generic"]
        .van()
        .model_copy(
            update={"battery": BatteryParams(usable_capacity_kwh=1000.0), "payload_kg": 1000.0}
        )
    )
    end = clock(depot[5] - 1)  # shifts end before midnight's 16:00 → "15:59"
    return FleetProblem(
        date=dt.date(2026, 4, 15),
        timezone="UTC",
        depot=Depot(id="depot", lat=48.0 + depot[2] / 111, lon=16.0 + depot[1] / 74),
        vehicles=[
            FleetVehicle(id=f"v{k}", van=van, shift_start="00:00", shift_end=end) for k in range(25)
        ],
        stops=[
            Stop(
                id=f"c{int(r[0])}",
                lat=48.0 + r[2] / 111,
                lon=16.0 + r[1] / 74,
                delivery_kg=r[3],
                service_time_s=r[6] * MINUTE_S,
                door_open_s=60.0,
                time_windows=[TimeWindow(start=clock(r[4]), end=clock(min(r[5], depot[5] - 1)))],
            )
            for r in customers
        ],
        matrix=RoadMatrix(
            distances_m=(distance * KM_M).tolist(), durations_s=(distance * MINUTE_S).tolist()
        ),
        weather=Weather(t_min_c=8, t_max_c=18),
        objective="distance",
        minimize_vehicles=minimize_vehicles,
        time_limit_s=time_limit_s,
    )


def pyvrp_rc208(time_limit_s: float) -> tuple[float, int]:
    distance, rows = rc208()
    scaled = np.rint(distance * PYVRP_SCALE).astype(int)
    model = Model()
    places = [
        model.add_location(x=int(r[1] * PYVRP_SCALE), y=int(r[2] * PYVRP_SCALE)) for r in rows
    ]
    model.add_depot(places[0], tw_early=0, tw_late=int(rows[0][5] * PYVRP_SCALE))
    model.add_vehicle_type(num_available=25, capacity=1000, tw_late=int(rows[0][5] * PYVRP_SCALE))
    for r, place in zip(rows[1:], places[1:], strict=True):
        model.add_client(
            place,
            delivery=int(r[3]),
            service_duration=int(r[6] * PYVRP_SCALE),
            tw_early=int(r[4] * PYVRP_SCALE),
            tw_late=int(r[5] * PYVRP_SCALE),
        )
    for i, a in enumerate(places):
        for j, b in enumerate(places):
            model.add_edge(a, b, distance=int(scaled[i, j]), duration=int(scaled[i, j]))
    result = model.solve(stop=MaxRuntime(time_limit_s), seed=1, display=False)
    assert result.is_feasible()
    return result.cost() / PYVRP_SCALE, result.best.num_routes()


def rc208_table() -> None:
    rows = []
    for budget in (10.0, 60.0):
        theirs, their_routes = pyvrp_rc208(budget)
        for minimize in (False, True):
            started = time.perf_counter()
            ours = plan_fleet(rc208_problem(budget, minimize))
            elapsed = time.perf_counter() - started
            km = ours.distance_m / KM_M
            rows.append(
                [
                    f"{budget:.0f} s",
                    "distance" if not minimize else "vans, then distance",
                    f"{km:.1f}",
                    ours.vehicles_used,
                    len(ours.unassigned),
                    f"{theirs:.1f}",
                    their_routes,
                    f"{(km / theirs - 1) * 100:+.2f} %",
                    f"{elapsed:.1f}",
                    ours.verification_rounds,
                ]
            )
    print_table(
        "Solomon RC208 (100 customers, windows, capacity 1000): coldroute vs PyVRP 0.14, same "
        "budget, same run (best known 776.1 with 3 vans)",
        [
            "budget",
            "objective",
            "ours",
            "vans",
            "unserved",
            "PyVRP",
            "vans",
            "ours vs PyVRP",
            "our wall time [s]",
            "verifications",
        ],
        rows,
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


def main() -> None:
    rc208_table()
    battery_table()


if __name__ == "__main__":
    main()
