"""How much of its time limit a request as users send it uses: fleets of 25, 100 and 1,000
stops sent over HTTP with nothing about the search (the time limit the default for their size,
the work the default share of it), on an idle service with one worker; the answer's wait
against its limit, how the search ended, and whether the answer sent back with its replay
(``solver.replay``) is the same to the byte (but for the timing fields).

The days: Solomon's R101, C101 and RC101 (their first 25 customers, and all 100) and the
Gehring–Homberger R1_10_1, C1_10_1 and RC1_10_1 (1,000), as ``bench_homberger`` sends them.
"""

from __future__ import annotations

import json
import time
from typing import Any

import httpx
import numpy as np

from benchmarks.bench_homberger import Instance, fleet_request, homberger
from benchmarks.common import print_table
from core.planning.model import FLEET_TIME_LIMIT
from testbed.fleets import solomon
from testbed.services import Server

#: Solomon's vans: 25, as the literature allows.
SOLOMON_VANS = 25


def solomon_day(name: str, customers: int) -> Instance:
    """Solomon's ``name`` with its first ``customers`` customers, as a day of
    :func:`benchmarks.bench_homberger.fleet_request` (every service as long: Solomon's are)."""
    found = solomon(name)
    keep = slice(0, customers + 1)
    return Instance(
        f"{name}" if customers >= len(found.demand) - 1 else f"{name} (first {customers})",
        found.xy[keep],
        np.asarray(found.demand[keep]),
        found.window_min[keep],
        found.service_min[1],
        found.minutes_per_unit,
        int(found.capacity),
        SOLOMON_VANS,
        (0, 0.0),
    )


def as_users_send(instance: Instance) -> dict[str, Any]:
    """The day's request with nothing about the search: no time limit, no work."""
    body = fleet_request(instance, 0.0)
    body.pop("time_limit_s")
    return body


def timing_free(answer: dict[str, Any]) -> str:
    def strip(value: Any) -> Any:
        if isinstance(value, dict):
            return {k: strip(v) for k, v in value.items() if k != "runtime_s"}
        if isinstance(value, list):
            return [strip(v) for v in value]
        return value

    return json.dumps(strip(answer), sort_keys=True)


def row(server: Server, instance: Instance) -> list[object]:
    body = as_users_send(instance)
    limit_s = FLEET_TIME_LIMIT({"stops": body["stops"]})
    started = time.perf_counter()
    response = httpx.post(f"{server.url}/v1/fleet-plans", json=body, timeout=limit_s * 3 + 60)
    wall_s = time.perf_counter() - started
    assert response.status_code == 200, response.text[:500]
    answer = response.json()
    replay = answer["solver"]["replay"]
    again = httpx.post(
        f"{server.url}/v1/fleet-plans", json=body | {"replay": replay}, timeout=limit_s * 3 + 60
    ).json()
    served = sum(len(route["stops"]) for route in answer["routes"])
    return [
        instance.name,
        len(body["stops"]),
        f"{limit_s:g}",
        f"{answer['solver']['runtime_s']:.1f}",
        f"{wall_s:.1f}",
        f"{wall_s / limit_s:.0%}",
        answer["solver"]["stopped_by"],
        f"{served}/{len(body['stops'])}",
        answer["totals"]["vehicles_used"],
        "yes" if timing_free(again) == timing_free(answer) else "**no**",
    ]


def main() -> None:
    days = [
        *(solomon_day(name, 25) for name in ("R101", "C101", "RC101")),
        *(solomon_day(name, 100) for name in ("R101", "C101", "RC101")),
        *(homberger(name) for name in ("R1_10_1", "C1_10_1", "RC1_10_1")),
    ]
    server = Server({"COLDROUTE_WORKERS": "1", "COLDROUTE_MAX_BODY_BYTES": str(64_000_000)})
    server.start()
    try:
        row(server, days[0])  # the worker's first solve loads what the rest find loaded
        rows = [row(server, day) for day in days]
    finally:
        server.close()
    print_table(
        "Fleet plans as users send them (no time_limit_s, no work_s) over HTTP, one worker, "
        "idle: the answer's wait against the default limit for its size, and its replay",
        [
            "day",
            "stops",
            "default limit [s]",
            "search and verification [s]",
            "answer [s]",
            "of the limit",
            "stopped_by",
            "served",
            "vans",
            "replay the same",
        ],
        rows,
    )


if __name__ == "__main__":
    main()
