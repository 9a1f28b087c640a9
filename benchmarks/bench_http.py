"""The real server over HTTP: latency percentiles and throughput with concurrent clients."""

from __future__ import annotations

import asyncio
import copy
import time

import httpx
import numpy as np

from app.examples import PLAN_EXAMPLE
from benchmarks.common import print_table, running_server

CLIENTS = 8
REQUESTS = 64


def _plan_with(n_stops: int) -> dict[str, object]:
    rng = np.random.default_rng(n_stops)
    body = copy.deepcopy(PLAN_EXAMPLE)
    body["stops"] = [
        {
            "id": f"S{i}",
            "lat": 48.21 + rng.uniform(-0.05, 0.05),
            "lon": 16.37 + rng.uniform(-0.08, 0.08),
            "service_time_s": 240,
            "door_open_s": 90,
            "delivery_kg": 400 / n_stops,
        }
        for i in range(n_stops)
    ]
    return body


async def _load(url: str, body: dict[str, object]) -> tuple[list[float], float, int]:
    latencies: list[float] = []
    failures = 0
    queue: asyncio.Queue[int] = asyncio.Queue()
    for i in range(REQUESTS):
        queue.put_nowait(i)

    async def worker(client: httpx.AsyncClient) -> None:
        nonlocal failures
        while not queue.empty():
            queue.get_nowait()
            started = time.perf_counter()
            response = await client.post(f"{url}/v1/plans", json=body)
            latencies.append(time.perf_counter() - started)
            failures += response.status_code != 200

    started = time.perf_counter()
    async with httpx.AsyncClient(timeout=120) as client:
        await asyncio.gather(*(worker(client) for _ in range(CLIENTS)))
    return latencies, time.perf_counter() - started, failures


def main() -> None:
    with running_server() as url:
        rows = []
        for n in (8, 50):
            body = _plan_with(n)
            httpx.post(f"{url}/v1/plans", json=body, timeout=60)  # warm-up
            latencies, elapsed, failures = asyncio.run(_load(url, body))
            ms = np.array(latencies) * 1000
            rows.append(
                [
                    n,
                    CLIENTS,
                    REQUESTS,
                    f"{np.percentile(ms, 50):.0f}",
                    f"{np.percentile(ms, 95):.0f}",
                    f"{REQUESTS / elapsed:.1f}",
                    failures,
                ]
            )
    print_table(
        "POST /v1/plans through uvicorn over HTTP (one worker process, 2 cores)",
        ["stops", "clients", "requests", "p50 [ms]", "p95 [ms]", "requests/s", "non-200"],
        rows,
    )


if __name__ == "__main__":
    main()
