"""Small fleets whose answers can be checked by hand: a client's matrix makes the driving times
exact, and the paper's van on a summer day in Vienna."""

from __future__ import annotations

import datetime as dt
from typing import Any
from zoneinfo import ZoneInfo

import numpy as np

from core.params import PRESETS, Depot, RoadMatrix, Stop, TimeWindow, Weather
from core.planning.day.scene import Scene, legs_for
from core.planning.fleet.planner import check_fleet
from core.planning.model import FleetProblem, FleetVehicle, default_work_s
from core.planning.search.day import FleetDay, fleet_day

VIENNA = ZoneInfo("Europe/Vienna")
DAY = dt.date(2026, 7, 15)
SUMMER = Weather(t_min_c=18, t_max_c=31)
DEPOT = Depot(id="depot", lat=48.17, lon=16.42)
VAN = PRESETS["paper-generic"].van()


def at(hhmm: str) -> dt.datetime:
    """A moment of the day in Vienna."""
    return dt.datetime.combine(DAY, dt.time.fromisoformat(hhmm), tzinfo=VIENNA)


def window(start: str, end: str) -> TimeWindow:
    return TimeWindow(start=start, end=end)


def two_clusters(service_s: float = 300.0, **changes: Any) -> tuple[list[Stop], RoadMatrix]:
    """East stops E1–E3 and west stops W1–W3, 10 min from the depot, 2 min apart within a
    cluster and 30 min across; 5 km per 10 min."""
    names = ["E1", "E2", "E3", "W1", "W2", "W3"]
    stops = [
        Stop(id=name, lat=48.17 + 0.001 * k, lon=16.42, service_time_s=service_s, **changes)
        for k, name in enumerate(names, start=1)
    ]
    n = 7
    minutes = np.zeros((n, n))
    for i in range(1, n):
        minutes[0, i] = minutes[i, 0] = 10
        for j in range(1, n):
            if i != j:
                minutes[i, j] = 2 if (i <= 3) == (j <= 3) else 30
    matrix = RoadMatrix(distances_m=(minutes * 500).tolist(), durations_s=(minutes * 60).tolist())
    return stops, matrix


def fleet(stops: list[Stop], vehicles: list[FleetVehicle], **fields: Any) -> FleetProblem:
    """The fleet day of ``vehicles`` serving ``stops``. Without a time limit, the work a default
    request of this size gets (a second's) and the time to do it on a busy machine: a search the
    clock cut would give another answer."""
    if "time_limit_s" not in fields:
        fields = {"time_limit_s": 60.0, "work_s": default_work_s(1.0)} | fields
    return FleetProblem(
        date=DAY,
        timezone="Europe/Vienna",
        depot=DEPOT,
        stops=stops,
        vehicles=vehicles,
        weather=SUMMER,
        **fields,
    )


def van(vehicle_id: str, start: str = "08:00", end: str = "17:00", **changes: Any) -> FleetVehicle:
    return FleetVehicle(
        id=vehicle_id,
        van=VAN.model_copy(update=changes),
        shift_start=dt.time.fromisoformat(start),
        shift_end=dt.time.fromisoformat(end),
    )


def day_of(problem: FleetProblem) -> FleetDay:
    """The fleet day a search of ``problem`` starts from (no router)."""
    shifts, zone = check_fleet(problem)
    scene = Scene(problem.places, legs_for(problem, None), zone, lambda _b, _s: (SUMMER, []))
    return fleet_day(shifts, scene, None)
