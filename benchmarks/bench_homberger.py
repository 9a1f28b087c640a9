"""Fleets of 1,000 stops, over HTTP as users send them (``time_limit_s`` alone): the six
Gehring–Homberger instances in ``../shared/reference/homberger`` (types 1 and 2: tight windows
and short routes, wide windows and long routes) sent as one day's fleet plan to the real
service, beside PyVRP given the same instance and the same wall time in the same run; the
answer's wait against its time limit, the worker's peak memory, and where the time of one
request goes.

An instance as a day (``../shared/reference/homberger/README.md``): every time scaled by
1,439 / horizon into minutes (windows rounded inwards to whole minutes, as a client sends
them), one distance unit what a van drives in a time unit at :data:`SPEED_KMH` (type 2's long
horizons make a unit a fifth of a minute: a fixed length of unit had vans at 150 km/h, which
the simulation of the drive rightly refused), the instance's distances and scaled times sent as
the matrix; vans of the instance's capacity with batteries that never bind, no breaks, the
distance the objective. PyVRP solves the same rounded instance (distances in hundredths).
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import httpx
import numpy as np

from benchmarks.common import print_table
from testbed.reference import REFERENCE, pyvrp_vrptw
from testbed.services import Server

INSTANCES = ("C1_10_1", "R1_10_1", "RC1_10_1", "C2_10_1", "R2_10_1", "RC2_10_1")
#: The speed of every arc [km/h]: the shortest arcs (1 unit) can be driven from rest to rest
#: in their time.
SPEED_KMH = 40.0
#: PyVRP works on integers: distances and times in hundredths of a unit.
PYVRP_SCALE = 100
#: The time limit both are given [s] (``COLDROUTE_BENCH_HOMBERGER_S`` shortens it).
BUDGET_S = float(os.environ.get("COLDROUTE_BENCH_HOMBERGER_S", "60"))
#: The last minute of the day a shift may end at.
DAY_END_MIN = 1439


@dataclass(frozen=True)
class Instance:
    """One instance in the day's minutes: the depot first, then the customers."""

    name: str
    xy: np.ndarray
    demand: np.ndarray
    window_min: list[tuple[int, int]]  # whole minutes; the depot's, the shift
    service_min: float
    minutes_per_unit: float
    capacity: int
    vans: int
    best: tuple[int, float]  # best known vans and distance

    @property
    def unit_m(self) -> float:
        """One distance unit [m]: a time unit's drive at :data:`SPEED_KMH`."""
        return SPEED_KMH / 60.0 * self.minutes_per_unit * 1000.0

    @property
    def distance(self) -> np.ndarray:
        return np.sqrt(((self.xy[:, None] - self.xy[None]) ** 2).sum(-1))


def _section(lines: list[str], name: str) -> list[list[float]]:
    start = lines.index(name) + 1
    rows = []
    for line in lines[start:]:
        if not line[:1].isdigit():
            break
        rows.append([float(x) for x in line.split()[1:]])
    return rows


def homberger(name: str) -> Instance:
    folder = REFERENCE / "homberger"
    lines = [line.strip() for line in (folder / f"{name}.vrp").read_text().splitlines()]
    pairs = (line.partition(":") for line in lines if ":" in line)
    header = {key.strip(): value.strip() for key, _, value in pairs}
    xy = np.array(_section(lines, "NODE_COORD_SECTION"))
    demand = np.array([row[0] for row in _section(lines, "DEMAND_SECTION")])
    windows = _section(lines, "TIME_WINDOW_SECTION")
    horizon = windows[0][1]
    scale = DAY_END_MIN / horizon
    # rounded inwards, but at least a minute wide (type 2 has windows narrower than a minute)
    window_min = [
        (
            math.ceil(a * scale),
            max(min(math.floor(b * scale), DAY_END_MIN), math.ceil(a * scale) + 1),
        )
        for a, b in windows
    ]
    solution = (folder / f"{name}.sol").read_text().splitlines()
    routes = sum(1 for line in solution if line.startswith("Route"))
    cost = float(next(line.split()[1] for line in solution if line.startswith("Cost")))
    return Instance(
        name,
        xy,
        demand,
        window_min,
        float(header["SERVICE_TIME"]) * scale,
        scale,
        int(header["CAPACITY"]),
        int(header["VEHICLES"]),
        (routes, cost),
    )


def clock(minutes: float) -> str:
    return f"{int(minutes) // 60:02d}:{int(minutes) % 60:02d}"


def fleet_request(instance: Instance, time_limit_s: float) -> dict[str, Any]:
    """The instance as the JSON body of ``POST /v1/fleet-plans``."""
    distance = instance.distance
    unit_s = instance.minutes_per_unit * 60.0
    van = {
        "vehicle": {"preset": "paper-generic"},
        "payload_kg": instance.capacity,
        "battery": {"usable_capacity_kwh": 2000.0},
    }
    day_end = instance.window_min[0][1]
    return {
        "date": "2026-04-15",
        "timezone": "UTC",
        "depot": {"id": "depot", "lat": 48.0, "lon": 16.0},
        "vehicles": [
            {
                "id": f"v{k}",
                **van,
                "shift_start": "00:00",
                "shift_end": clock(day_end),
                "breaks": "none",
            }
            for k in range(instance.vans)
        ],
        "stops": [
            {
                "id": f"c{k}",
                "lat": 48.0 + (instance.xy[k, 1] - instance.xy[0, 1]) * instance.unit_m / 111_000,
                "lon": 16.0 + (instance.xy[k, 0] - instance.xy[0, 0]) * instance.unit_m / 74_000,
                "delivery_kg": float(instance.demand[k]),
                "service_time_s": instance.service_min * 60.0,
                "door_open_s": 60.0,
                "time_windows": [{"start": clock(a), "end": clock(b)}],
            }
            for k, (a, b) in enumerate(instance.window_min)
            if k
        ],
        "matrix": {
            "distances_m": np.round(distance * instance.unit_m, 1).tolist(),
            "durations_s": np.round(distance * unit_s, 1).tolist(),
        },
        "weather": {"t_min_c": 8, "t_max_c": 18},
        "objective": "distance",
        "minimize_vehicles": False,
        "time_limit_s": time_limit_s,
    }


def pyvrp_day(instance: Instance, budget_s: float) -> tuple[float, int, int]:
    """PyVRP on the same rounded instance for ``budget_s``: distance [units], vans, served."""
    return pyvrp_vrptw(
        instance.distance,
        instance.demand,
        [instance.service_min] * len(instance.demand),
        instance.window_min,
        instance.minutes_per_unit,
        instance.capacity,
        instance.vans,
        budget_s,
        scale=PYVRP_SCALE,
    )


def peak_rss_mb(server: Server) -> float:
    """The largest peak resident memory of the server's processes [MB] (VmHWM)."""
    assert server.process is not None
    pids = {server.process.pid}
    for status in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = status.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == server.process.pid:
            pids.add(int(status.parent.name))
    peaks = []
    for pid in pids:
        try:
            text = Path(f"/proc/{pid}/status").read_text()
        except OSError:
            continue
        kb = next(int(line.split()[1]) for line in text.splitlines() if line.startswith("VmHWM"))
        peaks.append(kb / 1024)
    return max(peaks)


def ours(server: Server, instance: Instance, budget_s: float) -> dict[str, Any]:
    body = json.dumps(fleet_request(instance, budget_s))
    started = time.perf_counter()
    response = httpx.post(
        f"{server.url}/v1/fleet-plans",
        content=body,
        headers={"content-type": "application/json"},
        timeout=budget_s * 4 + 60,
    )
    wall_s = time.perf_counter() - started
    assert response.status_code == 200, response.text[:500]
    answer = response.json()
    served = sum(len(route["stops"]) for route in answer["routes"])
    return {
        "distance": answer["totals"]["distance_m"] / instance.unit_m,
        "vans": answer["totals"]["vehicles_used"],
        "served": served,
        "wall_s": wall_s,
        "stopped_by": answer["solver"]["stopped_by"],
        "body_mb": len(body) / 1e6,
    }


class _Stages:
    """Wall time of the named functions of the fleet's path [s], wrapped where the fleet
    planner calls them (the same functions, the same call sites)."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}
        self.calls: dict[str, int] = {}

    def wrap(self, module: Any, attribute: str, stage: str) -> None:
        inner = getattr(module, attribute)

        def timed(*args: Any, **kwargs: Any) -> Any:
            started = time.perf_counter()
            try:
                return inner(*args, **kwargs)
            finally:
                self.add(stage, time.perf_counter() - started)

        setattr(module, attribute, timed)

    def add(self, stage: str, seconds: float) -> None:
        self.seconds[stage] = self.seconds.get(stage, 0.0) + seconds
        self.calls[stage] = self.calls.get(stage, 0) + 1


def profile_table(name: str = "R1_10_1") -> None:
    """Where the time of one 1,000-stop request goes, stage by stage, in process."""
    from app.operations.fleet_plan import answer, fleet_problem
    from app.schemas.fleet import FleetPlanRequest
    from app.settings import Settings
    from core.planning.fleet import planner as fleet
    from core.planning.search import day
    from core.planning.search import fleet as fleet_search

    stages = _Stages()
    stages.wrap(fleet, "legs_for", "matrix (checked, legs)")
    stages.wrap(fleet, "client_legs_too_fast", "matrix: arcs faster than a van")
    stages.wrap(fleet, "fleet_day", "estimates (per kind of van)")
    stages.wrap(fleet_search, "routing_input", "solver input")
    stages.wrap(fleet_search, "solve_routes", "search (PyVRP, OR-Tools)")
    stages.wrap(day.FleetDay, "simulate", "verification (simulated days)")
    stages.wrap(fleet_search, "_repair", "repair")
    stages.wrap(fleet_search, "_given_to_idle", "idle vans")
    stages.wrap(fleet_search, "explain", "reasons of the unserved")
    instance = homberger(name)
    text = json.dumps(fleet_request(instance, BUDGET_S))
    started = time.perf_counter()
    request = FleetPlanRequest.model_validate(json.loads(text))
    stages.add("parse (JSON, schema)", time.perf_counter() - started)
    started = time.perf_counter()
    settings = Settings(max_time_limit_s=BUDGET_S)
    problem = fleet_problem(request, settings)
    fleet.check_fleet(problem)
    stages.add("validation", time.perf_counter() - started)
    started = time.perf_counter()
    result = fleet.plan_fleet(problem)
    total = time.perf_counter() - started
    started = time.perf_counter()
    answer(request, result).model_dump_json()
    stages.add("response (JSON)", time.perf_counter() - started)
    inside = ("parse (JSON, schema)", "validation", "response (JSON)")
    rows = [
        [stage, stages.calls[stage], f"{seconds:.2f}", f"{seconds / total * 100:.1f} %"]
        for stage, seconds in stages.seconds.items()
    ]
    accounted = sum(v for k, v in stages.seconds.items() if k not in inside and k != "repair")
    rows.append(["plan_fleet, all of it", 1, f"{total:.2f}", "100 %"])
    rows.append(["plan_fleet, the rest", "—", f"{total - accounted:.2f}", "—"])
    print_table(
        f"One {name} request (1,000 stops, {instance.vans} vans, time_limit_s {BUDGET_S:g}) "
        "stage by stage, in process (share of plan_fleet's time)",
        ["stage", "calls", "time [s]", "share"],
        rows,
    )


def main() -> None:
    server = Server(
        {
            "COLDROUTE_WORKERS": "1",
            "COLDROUTE_MAX_BODY_BYTES": str(64_000_000),
        }
    ).start()
    rows = []
    try:
        for name in INSTANCES:
            instance = homberger(name)
            their_distance, their_vans, their_served = pyvrp_day(instance, BUDGET_S)
            got = ours(server, instance, BUDGET_S)
            rows.append(
                [
                    name,
                    f"{instance.best[0]}, {instance.best[1]:,.1f}",
                    f"{their_served}, {their_vans}, {their_distance:,.1f}",
                    f"{got['served']}, {got['vans']}, {got['distance']:,.1f}",
                    f"{(got['distance'] / their_distance - 1) * 100:+.2f} %",
                    f"{got['wall_s']:.1f}",
                    got["stopped_by"],
                    f"{got['body_mb']:.1f}",
                ]
            )
        peak = peak_rss_mb(server)
    finally:
        server.close()
    print_table(
        f"Gehring–Homberger 1,000 stops over HTTP at time_limit_s {BUDGET_S:g} beside PyVRP 0.14 "
        f"at {BUDGET_S:g} s, same run (peak memory of the service's processes: {peak:,.0f} MB)",
        [
            "instance",
            "best known (vans, distance)",
            "PyVRP (served, vans, distance)",
            "ours (served, vans, distance)",
            "ours vs PyVRP",
            "our answer [s]",
            "stopped_by",
            "request [MB]",
        ],
        rows,
    )
    profile_table()


if __name__ == "__main__":
    main()
