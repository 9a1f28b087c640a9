"""Soak: an hour of mixed requests through one server (``COLDROUTE_BENCH_SOAK_S`` shortens
it), and the resident memory of its two worker processes every few minutes. The workers keep
up to 64 MiB of freed memory at the top of their heap by design (``core.arrays.keep_heap``,
which saves the simulations re-faulting their arrays): their memory should rise by about that
early on and then stay flat. The table says whether it did: the growth over the second half
of the run."""

from __future__ import annotations

import asyncio
import os
import random
import time
from pathlib import Path

import httpx

from app.examples import (
    CALIBRATION_EXAMPLE,
    CHARGING_PLAN_EXAMPLE,
    FLEET_PLAN_EXAMPLE,
    PLAN_EXAMPLE,
    SIMULATE_EXAMPLE,
)
from benchmarks.bench_serving import plan_with
from benchmarks.common import print_table
from testbed.services import Server, children, rss_mib

SOAK_S = float(os.environ.get("COLDROUTE_BENCH_SOAK_S", "3600"))
CLIENTS = 4
#: Memory samples over the run.
SAMPLES = 12
REQUESTS = {
    "plan, 8 stops": ("/v1/plans", PLAN_EXAMPLE),
    "plan, 40 stops": ("/v1/plans", plan_with(40)),
    "plan, 40 stops, charging": ("/v1/plans", CHARGING_PLAN_EXAMPLE),
    "fleet plan": ("/v1/fleet-plans", FLEET_PLAN_EXAMPLE),
    "simulate": ("/v1/simulate", SIMULATE_EXAMPLE),
    "calibration": ("/v1/calibrations", CALIBRATION_EXAMPLE),
}


def workers_of(pid: int) -> list[int]:
    """The server's worker processes: its spawned children but the resource tracker (Linux
    /proc)."""
    found = []
    for child in children(pid):
        try:
            command = Path(f"/proc/{child}/cmdline").read_bytes()
        except OSError:
            continue
        if b"spawn_main" in command and b"resource_tracker" not in command:
            found.append(child)
    return sorted(found)


async def _soak(url: str, pid: int) -> tuple[list[list[object]], int, int]:
    stop_at = time.monotonic() + SOAK_S
    counts = {"requests": 0, "errors": 0}
    rows: list[list[object]] = []
    choices = random.Random(3)
    began = time.monotonic()

    async def client(http: httpx.AsyncClient) -> None:
        while time.monotonic() < stop_at:
            path, body = REQUESTS[choices.choice(list(REQUESTS))]
            response = await http.post(f"{url}{path}", json=body)
            counts["requests"] += 1
            counts["errors"] += response.status_code != 200

    async def sampler() -> None:
        every_s = SOAK_S / SAMPLES
        for k in range(SAMPLES + 1):
            workers = workers_of(pid)
            rows.append(
                [
                    f"{(time.monotonic() - began) / 60:.1f}",
                    counts["requests"],
                    counts["errors"],
                    *(f"{rss_mib(w):.0f}" for w in workers[:2]),
                ]
            )
            if k < SAMPLES:
                await asyncio.sleep(max(began + (k + 1) * every_s - time.monotonic(), 0.0))

    async with httpx.AsyncClient(timeout=300) as http:
        await asyncio.gather(sampler(), *(client(http) for _ in range(CLIENTS)))
    return rows, counts["requests"], counts["errors"]


def main() -> None:
    server = Server({"COLDROUTE_WORKERS": "2", "COLDROUTE_MAX_BODY_BYTES": "20000000"}).start()
    try:
        assert server.process is not None
        rows, requests, errors = asyncio.run(_soak(server.url, server.process.pid))
    finally:
        server.close()
    print_table(
        f"Soak: {SOAK_S / 60:.0f} min of mixed requests ({CLIENTS} clients: plans, a charging "
        "day, a fleet, simulations, calibrations), resident memory of the 2 workers",
        ["minute", "requests", "non-200", "worker 1 [MiB]", "worker 2 [MiB]"],
        rows,
    )
    half = rows[len(rows) // 2]
    last = rows[-1]
    growth = [float(last[k]) - float(half[k]) for k in (3, 4)]  # type: ignore[arg-type]
    print(
        f"\nSecond half of the soak: the workers' memory changed by {growth[0]:+.0f} and "
        f"{growth[1]:+.0f} MiB over {requests - int(half[1]):,} requests "  # type: ignore[call-overload]
        f"({requests:,} in all, {errors} not 200)."
    )


if __name__ == "__main__":
    main()
