"""Real roads: plan latency with OSRM against the estimate on Monaco, the router's share of it,
and the energy of real road speed profiles against synthetic traces on the same tour."""

from __future__ import annotations

import datetime as dt
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

import httpx
import numpy as np

from app.connectors.osrm import OsrmRouter
from benchmarks.common import print_table
from core.params import Depot, RoadMatrix, Stop, Weather
from core.planning.model import PlanProblem
from core.planning.round.planner import plan
from core.routing.roads import LegRoute, RoadTable
from testbed.reference import REFERENCE
from tools import osrm

DEPOT = Depot(id="depot-fontvieille", lat=43.7290, lon=7.4180)


class TimedRouter:
    """The OSRM client, with the wall time spent in it."""

    def __init__(self, inner: OsrmRouter) -> None:
        self.inner = inner
        self.name = inner.name
        self.seconds = 0.0

    def table(self, places: Sequence[Depot]) -> RoadTable:
        started = time.perf_counter()
        try:
            return self.inner.table(places)
        finally:
            self.seconds += time.perf_counter() - started

    def route(self, origin: Depot, destination: Depot) -> LegRoute:
        started = time.perf_counter()
        try:
            return self.inner.route(origin, destination)
        finally:
            self.seconds += time.perf_counter() - started


def monaco_stops(url: str, n: int, seed: int) -> list[Stop]:
    """``n`` random delivery addresses in Monaco: random points snapped to the road network."""
    rng = np.random.default_rng(seed)
    stops: list[Stop] = []
    while len(stops) < n:
        lat, lon = rng.uniform(43.725, 43.748), rng.uniform(7.410, 7.438)
        found = httpx.get(f"{url}/nearest/v1/driving/{lon},{lat}").json()["waypoints"][0]
        if found["distance"] < 60:
            snapped_lon, snapped_lat = found["location"]
            stops.append(
                Stop(
                    id=f"S{len(stops)}",
                    lat=snapped_lat,
                    lon=snapped_lon,
                    service_time_s=240,
                    door_open_s=90,
                    delivery_kg=400 / n,
                )
            )
    return stops


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        base = osrm.prepare(REFERENCE / "osm" / "monaco.osm.pbf", Path(folder))
        with osrm.running(base) as url:
            latency_rows, energy_rows = [], []
            for n in (8, 25, 50, 100):
                problem = PlanProblem(
                    date=dt.date(2026, 7, 15),
                    start_time=dt.time(9),
                    timezone="Europe/Monaco",
                    depot=DEPOT,
                    stops=monaco_stops(url, n, seed=n),
                    weather=Weather(t_min_c=21, t_max_c=29),
                    time_limit_s=2.0,
                )
                router = TimedRouter(OsrmRouter(url, 10.0, 100, 500.0))
                plan(problem, router)  # warm-up: connections and caches
                router.seconds = 0.0
                started = time.perf_counter()
                real = plan(problem, router)
                with_osrm_s = time.perf_counter() - started
                started = time.perf_counter()
                guess = plan(problem)
                estimate_s = time.perf_counter() - started
                latency_rows.append(
                    [
                        n,
                        f"{with_osrm_s * 1000:.0f}",
                        f"{router.seconds * 1000:.0f} ({router.seconds / with_osrm_s:.0%})",
                        f"{estimate_s * 1000:.0f}",
                        f"{real.distance_m / 1000:.1f}",
                        f"{guess.distance_m / 1000:.1f}",
                    ]
                )
                # The same tour on the same road distances and durations, driven as the paper's
                # synthetic street-type traces instead of the road's speed profile.
                synthetic = _synthetic_on_same_tour(problem, real, router.inner)
                real_kwh, fake_kwh = real.energy_kwh, synthetic.energy_kwh
                energy_rows.append(
                    [
                        n,
                        f"{real.distance_m / 1000:.1f}",
                        f"{real.duration_s / 3600:.2f} / {synthetic.duration_s / 3600:.2f}",
                        f"{real_kwh['traction']:.2f} / {fake_kwh['traction']:.2f}",
                        f"{real_kwh['total']:.2f} / {fake_kwh['total']:.2f}",
                        f"{(real_kwh['total'] / fake_kwh['total'] - 1) * 100:+.1f} %",
                    ]
                )
    print_table(
        "Plan latency on Monaco: OSRM road router vs the great-circle estimate (one process)",
        [
            "stops",
            "with OSRM [ms]",
            "in the router [ms]",
            "estimate [ms]",
            "road km",
            "estimate km",
        ],
        latency_rows,
    )
    print_table(
        "Energy on the same tour: OSRM speed profiles vs synthetic street-type traces "
        "(real / synthetic)",
        ["stops", "km", "round [h]", "traction [kWh]", "total [kWh]", "total difference"],
        energy_rows,
    )


def _synthetic_on_same_tour(problem: PlanProblem, real, router: OsrmRouter):
    """The real plan's tour, on the router's matrix, with generated traces stretched to the
    router's durations (what a client-sent matrix gets)."""
    by_id = {stop.id: stop for stop in problem.stops}
    ordered = [by_id[i] for i in real.tour[1:-1]]
    table = router.table([problem.depot, *ordered])
    matrix = RoadMatrix(
        distances_m=table.distance_m.tolist(), durations_s=table.duration_s.tolist()
    )
    return plan(problem.model_copy(update={"stops": ordered, "matrix": matrix, "keep_order": True}))


if __name__ == "__main__":
    main()
