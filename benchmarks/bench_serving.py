"""Serving: a 60 s mixed load over HTTP, liveness while two 400-stop rounds are answered and
while two 500-stop jobs run, and jobs per second through the server's own pool and through
Celery with two workers (loopback only)."""

from __future__ import annotations

import asyncio
import concurrent.futures
import copy
import random
import time

import httpx
import numpy as np

from app.examples import PLAN_EXAMPLE, SIMULATE_EXAMPLE
from benchmarks.common import print_table
from testbed.reference import vienna_stops
from testbed.services import Server, celery_cluster
from testbed.serving import long_plan

LOAD_S = 60.0
CLIENTS = 8


def plan_with(n_stops: int, time_limit_s: float = 1.0, seed: int | None = None) -> dict:
    rng = np.random.default_rng(n_stops if seed is None else seed)
    body = copy.deepcopy(PLAN_EXAMPLE)
    body["stops"] = vienna_stops(rng, n_stops, 240, 90, 400 / n_stops)
    body["time_limit_s"] = time_limit_s
    return body


KINDS = {
    "plan, 8 stops": ("/v1/plans", plan_with(8)),
    "plan, 50 stops": ("/v1/plans", plan_with(50)),
    "simulate, 8 km urban leg": ("/v1/simulate", SIMULATE_EXAMPLE),
}


async def _load(url: str) -> dict[str, tuple[list[float], int]]:
    done: dict[str, tuple[list[float], int]] = {kind: ([], 0) for kind in KINDS}
    stop_at = time.monotonic() + LOAD_S
    choices = random.Random(0)

    async def client(http: httpx.AsyncClient) -> None:
        while time.monotonic() < stop_at:
            kind = choices.choice(list(KINDS))
            path, body = KINDS[kind]
            started = time.perf_counter()
            response = await http.post(f"{url}{path}", json=body)
            latencies, errors = done[kind]
            latencies.append(time.perf_counter() - started)
            done[kind] = (latencies, errors + (response.status_code != 200))

    async with httpx.AsyncClient(timeout=120) as http:
        await asyncio.gather(*(client(http) for _ in range(CLIENTS)))
    return done


def mixed_load() -> None:
    server = Server({"COLDROUTE_WORKERS": "2"}).start()
    try:
        done = asyncio.run(_load(server.url))
    finally:
        server.close()
    rows = []
    for kind, (latencies, errors) in done.items():
        ms = np.array(latencies) * 1000
        rows.append(
            [
                kind,
                len(latencies),
                f"{np.percentile(ms, 50):.0f}",
                f"{np.percentile(ms, 95):.0f}",
                f"{np.percentile(ms, 99):.0f}",
                errors,
            ]
        )
    print_table(
        f"Mixed load through the server ({LOAD_S:.0f} s, {CLIENTS} concurrent clients, "
        "2 worker processes, 2 cores)",
        ["kind", "requests", "p50 [ms]", "p95 [ms]", "p99 [ms]", "non-200"],
        rows,
    )


def wait_all(url: str, ids: list[str], timeout_s: float = 600) -> list[dict]:
    deadline = time.monotonic() + timeout_s
    finished: dict[str, dict] = {}
    with httpx.Client(timeout=30) as http:
        while len(finished) < len(ids) and time.monotonic() < deadline:
            for job_id in ids:
                if job_id not in finished:
                    job = http.get(f"{url}/v1/jobs/{job_id}").json()
                    if job["status"] in ("succeeded", "failed", "cancelled"):
                        finished[job_id] = job
            time.sleep(0.1)
    return list(finished.values())


def liveness_under_jobs() -> None:
    server = Server({"COLDROUTE_WORKERS": "2", "COLDROUTE_JOB_SLOTS": "2"}).start()
    try:
        ids = [
            httpx.post(
                f"{server.url}/v1/jobs",
                json={"type": "plan", "request": plan_with(500, 10, seed=s)},
                timeout=30,
            ).json()["id"]
            for s in (1, 2)
        ]
        latencies = []
        with httpx.Client(timeout=10) as http:
            while True:
                started = time.perf_counter()
                http.get(f"{server.url}/healthz")
                latencies.append(time.perf_counter() - started)
                statuses = [http.get(f"{server.url}/v1/jobs/{i}").json()["status"] for i in ids]
                if all(s in ("succeeded", "failed") for s in statuses):
                    break
                time.sleep(0.05)
    finally:
        server.close()
    ms = np.array(latencies) * 1000
    print_table(
        "GET /healthz while two 500-stop jobs (10 s solves) keep both workers busy",
        ["probes", "p50 [ms]", "p99 [ms]", "max [ms]", "target p99"],
        [
            [
                len(ms),
                f"{np.percentile(ms, 50):.1f}",
                f"{np.percentile(ms, 99):.1f}",
                f"{ms.max():.1f}",
                "< 100 ms",
            ]
        ],
    )


def _probed_while(url: str, bodies: list[dict]) -> np.ndarray:
    """GET /healthz latencies [ms] from the moment ``bodies`` are posted to /v1/plans at once
    until the last is answered (its parsing, solve and writing all inside)."""
    latencies = []
    with concurrent.futures.ThreadPoolExecutor(len(bodies)) as pool, httpx.Client() as http:
        posted = [
            pool.submit(httpx.post, f"{url}/v1/plans", json=body, timeout=120) for body in bodies
        ]
        while not all(f.done() for f in posted):
            started = time.perf_counter()
            http.get(f"{url}/healthz", timeout=10)
            latencies.append(time.perf_counter() - started)
            time.sleep(0.01)
        assert all(f.result().status_code == 200 for f in posted)
    return np.array(latencies) * 1000


def liveness_under_rounds() -> None:
    """The audit's case (issue #50): two 400-stop rounds posted at once to a fresh server, then
    again; their answers (0.6 MB each) are written out in the workers."""
    server = Server({"COLDROUTE_WORKERS": "2"}).start()
    rows = []
    try:
        for when in ("first requests", "second requests"):
            bodies = [long_plan(400, 3, seed=s) for s in (1, 2)]
            ms = _probed_while(server.url, bodies)
            rows.append(
                [
                    when,
                    len(ms),
                    f"{np.percentile(ms, 50):.1f}",
                    f"{np.percentile(ms, 99):.1f}",
                    f"{ms.max():.1f}",
                ]
            )
    finally:
        server.close()
    print_table(
        "GET /healthz while two 400-stop rounds are posted to /v1/plans at once (parsed, "
        "solved, answered)",
        ["server", "probes", "p50 [ms]", "p99 [ms]", "max [ms]"],
        rows,
    )


def _throughput(url: str, n_jobs: int) -> tuple[float, int]:
    started = time.perf_counter()
    with httpx.Client(timeout=30) as http:
        ids = [
            http.post(f"{url}/v1/jobs", json={"type": "plan", "request": plan_with(25)}).json()[
                "id"
            ]
            for _ in range(n_jobs)
        ]
    jobs = wait_all(url, ids)
    elapsed = time.perf_counter() - started
    return len(jobs) / elapsed, n_jobs - sum(j["status"] == "succeeded" for j in jobs)


def jobs_per_second(n_jobs: int = 40) -> None:
    rows = []
    local = Server({"COLDROUTE_WORKERS": "2", "COLDROUTE_JOB_SLOTS": "2"}).start()
    try:
        rate, failed = _throughput(local.url, n_jobs)
        rows.append(["the server's own pool (2 processes)", n_jobs, f"{rate:.2f}", failed])
    finally:
        local.close()
    with celery_cluster([1, 1]) as server:
        rate, failed = _throughput(server.url, n_jobs)
        rows.append(
            ["Celery, 2 workers × 1 process, PostgreSQL + Redis", n_jobs, f"{rate:.2f}", failed]
        )
    print_table(
        "Jobs per second (25-stop plans, submitted at once, until all have succeeded)",
        ["runner", "jobs", "jobs/s", "failed"],
        rows,
    )


def main() -> None:
    mixed_load()
    liveness_under_rounds()
    liveness_under_jobs()
    jobs_per_second()


if __name__ == "__main__":
    main()
