"""The electrification study's speed through the entry point POST /v1/studies/electrification
calls (:func:`core.planning.electrification.study.study`): a generated fleet of Vienna routes
(15–45 stops each, about 40–240 km in the order driven, chilled and frozen goods) over days
of 2026, three batteries of the reefer van, the thermostat and the optimal refrigeration
strategy side by side."""

from __future__ import annotations

import datetime as dt
import math
import time
from typing import Any

import httpx
import numpy as np

from benchmarks.common import print_table, running_server
from core.arrays import keep_heap
from core.params import PRESETS, Depot, Stop
from core.planning.electrification.model import (
    Candidate,
    DrivenRoute,
    ElectrificationProblem,
)
from core.planning.electrification.study import study

DEPOT = Depot(id="depot", lat=48.17, lon=16.42)
BATTERIES_KWH = (40.0, 60.0, 80.0)


def generated_route(rng: np.random.Generator, k: int, days: list[dt.date]) -> DrivenRoute:
    """A route of 15–45 stops in a ring around the depot, driven round it (by angle), with
    chilled dairy (even ``k``) or frozen goods (odd)."""
    n = int(rng.integers(15, 46))
    reach_km = float(rng.uniform(4.0, 16.0))
    angle = rng.uniform(0, 2 * math.pi, n)
    distance_km = reach_km * np.sqrt(rng.uniform(0.2, 1.0, n))
    stops = [
        Stop(
            id=f"r{k}-s{i}",
            lat=DEPOT.lat + distance_km[i] * math.sin(angle[i]) / 111.0,
            lon=DEPOT.lon + distance_km[i] * math.cos(angle[i]) / 74.0,
            service_time_s=float(rng.uniform(180, 600)),
            door_open_s=60.0,
            delivery_kg=float(rng.uniform(2, 15)),
        )
        for i in np.argsort(angle)
    ]
    product = "frozen" if k % 2 else "chilled-dairy"
    return DrivenRoute(
        id=f"route-{k}", depot=DEPOT, stops=stops, start_time="06:30", days=days, product=product
    )


def fleet_problem(routes: int, days: int, strategy: str, seed: int = 34) -> ElectrificationProblem:
    rng = np.random.default_rng(seed)
    dates = [dt.date(2026, 1, 1) + dt.timedelta(days=round(d * 365 / days)) for d in range(days)]
    van = PRESETS["ev-van-3.5t-reefer"].van()
    van = van.model_copy(
        update={"refrigeration": van.refrigeration.model_copy(update={"strategy": strategy})}
    )
    candidates = [
        Candidate(
            id=f"{kwh:g} kWh",
            van=van.model_copy(
                update={"battery": van.battery.model_copy(update={"usable_capacity_kwh": kwh})}
            ),
        )
        for kwh in BATTERIES_KWH
    ]
    return ElectrificationProblem(
        year=2026,
        timezone="Europe/Vienna",
        routes=[generated_route(rng, k, dates) for k in range(routes)],
        candidates=candidates,
    )


def _over_http(url: str, problem: ElectrificationProblem) -> dict[str, Any]:
    """The study sent as POST /v1/studies/electrification (its routes shared out over the
    server's workers)."""
    body = problem.model_dump(mode="json", exclude={"candidates"}) | {
        "candidates": [
            {"id": c.id, "vehicle": {"preset": "ev-van-3.5t-reefer"}}
            | {"battery": {"usable_capacity_kwh": c.van.battery.usable_capacity_kwh}}
            for c in problem.candidates
        ],
        "refrigeration": problem.candidates[0].van.refrigeration.model_dump(mode="json"),
    }
    response = httpx.post(f"{url}/v1/studies/electrification", json=body, timeout=3600)
    response.raise_for_status()
    return dict(response.json())


def _row(name: str, size: str, wall_s: float, simulated: int, fleet: list[Any]) -> list[Any]:
    per_s = simulated / wall_s
    full = 50 * 365 * len(BATTERIES_KWH)
    return [name, size, f"{wall_s:.1f}", f"{per_s:.0f}", f"{full / per_s:,.0f}", fleet]


def main(routes: int = 50, days: int = 12) -> None:
    keep_heap()  # as the service's workers do
    rows: list[list[Any]] = []
    env = {"COLDROUTE_WORKERS": "2", "COLDROUTE_MAX_SYNC_ROUTE_DAYS": "1000000"}
    with running_server(env) as url:
        for strategy in ("thermostat", "optimal"):
            problem = fleet_problem(routes, days, strategy)
            size = f"{routes} × {days} × {len(problem.candidates)}"
            started = time.perf_counter()
            result = study(problem)
            wall_s = time.perf_counter() - started
            simulated = result.route_days * len(problem.candidates)
            fleet = " / ".join(str(f.routes_all_year) for f in result.fleet)
            rows.append(_row(f"{strategy}, one process", size, wall_s, simulated, fleet))
            started = time.perf_counter()
            answer = _over_http(url, problem)
            wall_s = time.perf_counter() - started
            served = " / ".join(str(f["routes_all_year"]) for f in answer["fleet"])
            rows.append(_row(f"{strategy}, HTTP, 2 workers", size, wall_s, simulated, served))
        # the size, whole: every day of 2026, over HTTP
        problem = fleet_problem(routes, 365, "thermostat")
        started = time.perf_counter()
        answer = _over_http(url, problem)
        wall_s = time.perf_counter() - started
        simulated = answer["route_days"] * len(problem.candidates)
        served = " / ".join(str(f["routes_all_year"]) for f in answer["fleet"])
        size = f"{routes} × 365 × {len(problem.candidates)}"
        rows.append(_row("thermostat, HTTP, 2 workers", size, wall_s, simulated, served))
    print_table(
        "Electrification study: the core entry point in one process, and POST "
        "/v1/studies/electrification on a server of 2 workers (the routes shared out) — "
        "route-days × candidates per second, and the time 50 × 365 × 3 would take",
        [
            "refrigeration, path",
            "routes × days × batteries",
            "wall [s]",
            "simulated per s",
            "50 × 365 × 3 [s]",
            "routes all year (40/60/80 kWh)",
        ],
        rows,
    )


if __name__ == "__main__":
    main()
