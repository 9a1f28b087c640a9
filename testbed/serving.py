"""Serving under load, for its tests and benchmarks: long rounds, big fleets, worker processes
and what they use of the CPU and the heap."""

from __future__ import annotations

import copy
import ctypes
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from app.examples import FLEET_PLAN_EXAMPLE, PLAN_EXAMPLE
from testbed.reference import vienna_stops
from testbed.services import children


def long_plan(n_stops: int, time_limit_s: float, seed: int = 1) -> dict[str, Any]:
    """A round whose solve takes about ``time_limit_s`` of work (too many stops to prove)."""
    rng = np.random.default_rng(seed)
    body = copy.deepcopy(PLAN_EXAMPLE)
    body["stops"] = vienna_stops(rng, n_stops, 120, 30, 1)
    # work of about the time asked for (the reference machine's), the limit well beyond it
    body["work_s"] = time_limit_s
    body["time_limit_s"] = 2 * time_limit_s
    body["objective"] = "distance"
    return body


def big_fleet(n_stops: int, n_vans: int, time_limit_s: float, seed: int = 1) -> dict[str, Any]:
    """A day of ``n_stops`` across Vienna, each with an hour's window between 07:00 and 17:00,
    for ``n_vans`` vans; more work than ``time_limit_s`` allows, so the limit ends the search."""
    rng = np.random.default_rng(seed)
    body = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    van = body["vehicles"][1] | {"payload_kg": 1000, "shift_start": "06:00", "shift_end": "19:00"}
    body["vehicles"] = [van | {"id": f"van-{k}"} for k in range(n_vans)]
    stops = vienna_stops(rng, n_stops, 120, 30, 10, spread_deg=(0.06, 0.1))
    opens = rng.integers(7, 17, n_stops)
    body["stops"] = [
        stop | {"time_windows": [{"start": f"{hour:02d}:00", "end": f"{hour + 1:02d}:00"}]}
        for stop, hour in zip(stops, opens, strict=True)
    ]
    body |= {"objective": "distance", "time_limit_s": time_limit_s, "work_s": 10 * time_limit_s}
    return body


def cpu_ticks(pids: list[int], window_s: float = 1.0) -> dict[int, int]:
    """CPU clock ticks (user + system, 1/100 s) each process used over the same ``window_s``;
    a process that ended meanwhile is left out."""

    def ticks(pid: int) -> int:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return int(fields[11]) + int(fields[12])

    before = {}
    for pid in pids:
        try:
            before[pid] = ticks(pid)
        except (OSError, IndexError):
            continue
    time.sleep(window_s)
    used = {}
    for pid, start in before.items():
        try:
            used[pid] = ticks(pid) - start
        except (OSError, IndexError):
            continue
    return used


def wait_quiet(pid: int, timeout_s: float = 60.0, window_s: float = 0.5) -> None:
    """Until no child of ``pid`` works (a worker started in place of a stopped one imports
    for seconds, and would look like the one that solves)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if all(used <= 2 for used in cpu_ticks(children(pid), window_s).values()):
            return
    raise AssertionError(f"the workers of {pid} still work after {timeout_s} s")


def busiest_child(pid: int, window_s: float = 1.0) -> int | None:
    """The child of ``pid`` that used the most CPU over ``window_s`` (the worker that solves,
    however loaded the machine is), or None when none used any."""
    used = cpu_ticks(children(pid), window_s)
    busiest = max(used, key=used.__getitem__, default=None)
    return busiest if busiest is not None and used[busiest] > 0 else None


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    stat = Path(f"/proc/{pid}/stat")
    return stat.exists() and stat.read_text().rsplit(")", 1)[1].split()[0] != "Z"


class _MallInfo2(ctypes.Structure):
    """glibc's ``struct mallinfo2`` (malloc.h)."""

    _fields_ = [
        (name, ctypes.c_size_t)
        for name in (
            "arena",
            "ordblks",
            "smblks",
            "hblks",
            "hblkhd",
            "usmblks",
            "fsmblks",
            "uordblks",
            "fordblks",
            "keepcost",
        )
    ]


def heap_kept_after_churn_bytes() -> int:
    """Free bytes left at the top of this process's heap after 8 MB of simulation-sized
    arrays (100 kB each, below glibc's mmap threshold) were allocated and freed."""
    arrays = [np.ones(12_500) for _ in range(80)]
    del arrays
    mallinfo2 = ctypes.CDLL(None).mallinfo2
    mallinfo2.restype = _MallInfo2
    return int(mallinfo2().keepcost)
