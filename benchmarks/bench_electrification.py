"""The electrification study as users run it: a job (``POST /v1/jobs``, type
``electrification``) on a generated fleet of Vienna routes (15–45 stops each, 40–160 km in the
order driven, chilled and frozen goods) over every day of 2026, three batteries of the reefer
van — on the server's own pool, and on Celery with one and with two workers; the thermostat
and the optimal refrigeration strategy side by side; and the memory the server and its
workers hold as the fleet grows (the parts' results go to the database as they finish)."""

from __future__ import annotations

import datetime as dt
import math
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import httpx
import numpy as np

from benchmarks.common import print_table
from core.params import PRESETS, Depot, Stop
from core.planning.electrification.model import DrivenRoute
from core.routing.geo import DETOUR_FACTOR
from testbed.services import Server, celery_cluster, children, rss_mib

DEPOT = Depot(id="depot", lat=48.17, lon=16.42)
BATTERIES_KWH = (40.0, 60.0, 80.0)
#: The issue's size: 50 routes × every day of 2026 × 3 batteries.
FULL = 50 * 365 * len(BATTERIES_KWH)
#: Kilometres per degree of latitude, and of longitude at Vienna.
KM_PER_DEG_LAT, KM_PER_DEG_LON = 111.2, 74.0


def generated_route(rng: np.random.Generator, k: int) -> DrivenRoute:
    """A route of 15–45 stops round the depot (by angle), scaled so that its day — at the
    planner's detour over the great circle — is 40–160 km, with chilled dairy (even ``k``)
    or frozen goods (odd), driven every day of the year."""
    n = int(rng.integers(15, 46))
    angle = np.sort(rng.uniform(0, 2 * math.pi, n))
    radius = np.sqrt(rng.uniform(0.2, 1.0, n))
    x = np.concatenate([[0.0], radius * np.cos(angle), [0.0]])
    y = np.concatenate([[0.0], radius * np.sin(angle), [0.0]])
    unit_km = float(np.hypot(np.diff(x), np.diff(y)).sum()) * DETOUR_FACTOR
    scale_km = float(rng.uniform(40.0, 160.0)) / unit_km
    stops = [
        Stop(
            id=f"r{k}-s{i}",
            lat=DEPOT.lat + scale_km * y[i + 1] / KM_PER_DEG_LAT,
            lon=DEPOT.lon + scale_km * x[i + 1] / KM_PER_DEG_LON,
            service_time_s=float(rng.uniform(180, 600)),
            door_open_s=60.0,
            delivery_kg=float(rng.uniform(2, 15)),
        )
        for i in range(n)
    ]
    product = "frozen" if k % 2 else "chilled-dairy"
    every_day = {"weekdays": ["mon", "tue", "wed", "thu", "fri", "sat", "sun"]}
    return DrivenRoute(
        id=f"route-{k}",
        depot=DEPOT,
        stops=stops,
        start_time="06:30",
        days=every_day,
        product=product,
    )


def fleet_study(routes: int, strategy: str, days: int = 365, seed: int = 34) -> dict[str, Any]:
    """The request: ``routes`` generated routes driven every day (or on ``days`` dates spread
    over the year), the reefer preset with each battery, the refrigeration ``strategy``."""
    rng = np.random.default_rng(seed)
    fleet = [generated_route(rng, k).model_dump(mode="json") for k in range(routes)]
    if days < 365:
        dates = [
            dt.date(2026, 1, 1) + dt.timedelta(days=round(d * 365 / days)) for d in range(days)
        ]
        for route in fleet:
            route["days"] = [d.isoformat() for d in dates]
    refrigeration = PRESETS["ev-van-3.5t-reefer"].van().refrigeration
    return {
        "year": 2026,
        "timezone": "Europe/Vienna",
        "routes": fleet,
        "candidates": [
            {
                "id": f"{kwh:g} kWh",
                "vehicle": {"preset": "ev-van-3.5t-reefer"},
                "battery": {"usable_capacity_kwh": kwh},
            }
            for kwh in BATTERIES_KWH
        ],
        "refrigeration": refrigeration.model_copy(update={"strategy": strategy}).model_dump(
            mode="json"
        ),
    }


def run_job(url: str, study: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The study as a job: the wall time from submission to its answer [s], and the answer."""
    started = time.perf_counter()
    job = httpx.post(f"{url}/v1/jobs", json={"type": "electrification", "request": study})
    job.raise_for_status()
    while True:
        done = httpx.get(f"{url}/v1/jobs/{job.json()['id']}", timeout=30).json()
        if done["status"] not in ("queued", "running"):
            break
        time.sleep(0.2)
    wall_s = time.perf_counter() - started
    if done["status"] != "succeeded":
        raise RuntimeError(f"the study job {done['status']}: {done.get('error')}")
    return wall_s, dict(done["result"])


@contextmanager
def peak_rss(pid: int) -> Iterator[dict[str, float]]:
    """The peak resident memory of the server ``pid`` and of its largest worker [MB], sampled
    every 0.1 s while the block runs."""
    peaks = {"server_mb": 0.0, "worker_mb": 0.0}
    stop = threading.Event()

    def sample() -> None:
        while not stop.wait(0.1):
            peaks["server_mb"] = max(peaks["server_mb"], rss_mib(pid))
            workers = [rss_mib(child) for child in children(pid)]
            peaks["worker_mb"] = max([peaks["worker_mb"], *(w for w in workers if w == w)])

    thread = threading.Thread(target=sample, daemon=True)
    thread.start()
    try:
        yield peaks
    finally:
        stop.set()
        thread.join()


def _covered(answer: dict[str, Any]) -> str:
    return " / ".join(str(f["routes_all_year"]) for f in answer["fleet"])


def _timeless(answer: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in answer.items() if k not in ("runtime_s", "route_days_per_s")}


def _speed_row(
    path: str, wall_s: float, answer: dict[str, Any], reference: dict[str, Any] | None
) -> list[Any]:
    simulated = answer["route_days"] * len(BATTERIES_KWH)
    per_s = simulated / wall_s
    routes = len(answer["routes"])
    size = f"{routes} × {answer['route_days'] // routes} × {len(BATTERIES_KWH)}"
    same = "—" if reference is None else ("yes" if _timeless(answer) == reference else "NO")
    distance = [route["distance_km"] for route in answer["routes"]]
    spread = f"{min(distance):.0f}–{max(distance):.0f}"
    pace = [f"{wall_s:.1f}", f"{per_s:,.0f}", f"{FULL / per_s:,.0f}"]
    return [path, size, spread, *pace, _covered(answer), same]


def main(routes: int = 50, optimal_days: int = 24) -> None:
    speed: list[list[Any]] = []
    memory: list[list[Any]] = []
    whole = fleet_study(routes, "thermostat")
    local = Server({"COLDROUTE_WORKERS": "2"}).start()
    try:
        assert local.process is not None
        for size in (10, 25, routes):
            with peak_rss(local.process.pid) as peaks:
                wall_s, answer = run_job(local.url, fleet_study(size, "thermostat"))
            simulated = answer["route_days"] * len(BATTERIES_KWH)
            peak = [f"{peaks['server_mb']:.0f}", f"{peaks['worker_mb']:.0f}"]
            memory.append([f"{size} × 365 × 3", f"{simulated:,}", f"{wall_s:.1f}", *peak])
        reference = _timeless(answer)  # the whole fleet, thermostat, local
        speed.append(_speed_row("thermostat, local pool (2 processes)", wall_s, answer, None))
        wall_s, answer = run_job(local.url, fleet_study(routes, "optimal", optimal_days))
        speed.append(_speed_row("optimal, local pool (2 processes)", wall_s, answer, None))
    finally:
        local.close()
    for processes in ([2], [1, 1]):
        with celery_cluster(processes) as cluster:
            wall_s, answer = run_job(cluster.url, whole)
        said = f"thermostat, Celery: {len(processes)} worker(s) × {processes[0]} process(es)"
        speed.append(_speed_row(said, wall_s, answer, reference))
    print_table(
        "Electrification study as a job (POST /v1/jobs): route-days × batteries per second, "
        "and the time 50 × 365 × 3 takes at that pace; Celery's answer compared with the "
        "local one",
        [
            "refrigeration, runner",
            "routes × days × batteries",
            "route km",
            "wall [s]",
            "simulated per s",
            "50 × 365 × 3 [s]",
            "routes all year (40/60/80 kWh)",
            "equal to local",
        ],
        speed,
    )
    print_table(
        "Electrification job on the local pool: peak resident memory as the fleet grows "
        "(parts of ~2,000 route-days; results stored as they finish)",
        ["routes × days × batteries", "simulated", "wall [s]", "server [MB]", "worker [MB]"],
        memory,
    )


if __name__ == "__main__":
    main()
