"""Helpers shared by the benchmarks: reference data location and table printing."""

from __future__ import annotations

import multiprocessing
import os
import socket
import subprocess
import sys
import tempfile
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import httpx
import numpy as np

REFERENCE = Path(__file__).resolve().parents[1].parent / "shared" / "reference"


def best_time_s(run: Callable[[], object], repeat: int = 5, number: int = 1) -> float:
    """Best wall-clock time of ``number`` calls, over ``repeat`` rounds [s per call]."""
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            run()
        best = min(best, (time.perf_counter() - start) / number)
    return best


def print_table(title: str, header: Sequence[str], rows: Sequence[Sequence[object]]) -> None:
    """Print a Markdown table with a title."""
    print(f"\n### {title}\n")
    print("| " + " | ".join(header) + " |")
    print("|" + "|".join("---" for _ in header) + "|")
    for row in rows:
        print("| " + " | ".join(str(cell) for cell in row) + " |")


def euc_2d_matrix(path: Path) -> np.ndarray:
    """Integer distance matrix of a TSPLIB EUC_2D instance: nint(euclidean distance)."""
    lines = path.read_text().splitlines()
    start = lines.index("NODE_COORD_SECTION") + 1
    points = []
    for line in lines[start:]:
        if line.strip() in ("EOF", ""):
            break
        _, x, y = line.split()[:3]
        points.append((float(x), float(y)))
    xy = np.array(points)
    distance = np.sqrt(((xy[:, None, :] - xy[None, :, :]) ** 2).sum(axis=-1))
    return np.floor(distance + 0.5).astype(np.int64)


def _burn(stop: Any, niceness: int) -> None:
    os.nice(niceness)
    while not stop.is_set():
        sum(i * i for i in range(10_000))


@contextmanager
def busy_core(niceness: int = 0) -> Iterator[None]:
    """Another process keeps one core fully busy for the duration (a second client's solve;
    at the service's workers' ``niceness``, another request's solve)."""
    context = multiprocessing.get_context("spawn")
    stop = context.Event()
    burner = context.Process(target=_burn, args=(stop, niceness), daemon=True)
    burner.start()
    time.sleep(0.3)
    try:
        yield
    finally:
        stop.set()
        burner.join(timeout=5)


class Server:
    """The real service (``python -m app.serve``) on a free loopback port, with a database of
    its own unless told otherwise."""

    def __init__(self, env: dict[str, str] | None = None, database_dir: Path | None = None):
        with socket.socket() as sock:
            sock.bind(("127.0.0.1", 0))
            self.port = int(sock.getsockname()[1])
        self.url = f"http://127.0.0.1:{self.port}"
        self._folder = None if database_dir else tempfile.TemporaryDirectory()
        folder = database_dir or Path(self._folder.name)  # type: ignore[union-attr]
        inherited = {k: v for k, v in os.environ.items() if not k.startswith("COLDROUTE_")}
        self.env = (
            inherited
            | {
                "COLDROUTE_LOG_LEVEL": "warning",
                "COLDROUTE_HOST": "127.0.0.1",
                "COLDROUTE_PORT": str(self.port),
                "COLDROUTE_DATABASE_URL": f"sqlite:///{folder}/jobs.db",
            }
            | (env or {})
        )
        self.process: subprocess.Popen[bytes] | None = None

    def start(self, timeout_s: float = 60.0) -> Server:
        # The server's log goes to a file: a pipe nobody reads would fill and stall it.
        self.log_path = Path(tempfile.mkstemp(prefix="coldroute-server-", suffix=".log")[1])
        log = self.log_path.open("wb")
        self.process = subprocess.Popen(
            [sys.executable, "-m", "app.serve"],
            env=self.env,
            stdout=log,  # the JSON lines
            stderr=log,  # anything else that goes wrong
        )
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise RuntimeError(f"the server exited: {self.log_path.read_text()[-2000:]}")
            try:
                if httpx.get(f"{self.url}/healthz", timeout=1).status_code == 200:
                    return self
            except httpx.TransportError:
                time.sleep(0.1)
        self.close()  # not left running behind the error
        raise RuntimeError(
            f"the server did not start within {timeout_s:g} s: {self.log_path.read_text()[-2000:]}"
        )

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.process.terminate()
            self.process.wait(timeout=20)

    def close(self) -> None:
        self.stop()
        if self._folder is not None:
            self._folder.cleanup()


@contextmanager
def running_server(env: dict[str, str] | None = None) -> Iterator[str]:
    """The real service for the duration; yields its URL."""
    server = Server(env).start()
    try:
        yield server.url
    finally:
        server.close()


POSTGRES = "postgresql://postgres@127.0.0.1:5432/test"


def children(pid: int) -> list[int]:
    """Direct child processes of ``pid`` (Linux /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                found.append(int(entry.name))
    return found


def rss_mib(pid: int) -> float:
    """Resident memory of a process [MiB] (Linux /proc); NaN when it is gone."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return float("nan")


@contextmanager
def celery_cluster(processes: Sequence[int], env: dict[str, str] | None = None) -> Iterator[Server]:
    """A server with Celery workers (one per entry of ``processes``, each with that many worker
    processes and Celery threads, as ``make worker``) on this machine's PostgreSQL (a schema
    of its own) and Redis (database 13, emptied); yields the server."""
    import psycopg
    import redis

    schema = f"bench_{uuid.uuid4().hex[:8]}"
    broker = "redis://127.0.0.1:6379/13"
    redis.Redis.from_url(broker).flushdb()
    with psycopg.connect(POSTGRES, autocommit=True) as connection:
        connection.execute(f"CREATE SCHEMA {schema}")
    shared = {
        "COLDROUTE_DATABASE_URL": "postgresql+psycopg://postgres@127.0.0.1:5432/test"
        f"?options=-csearch_path%3D{schema}",
        "COLDROUTE_BROKER_URL": broker,
        "COLDROUTE_BROKER_QUEUE": f"jobs-{schema}",
        "COLDROUTE_WORKERS": "1",
    } | (env or {})
    server = Server(shared).start()
    workers = [
        subprocess.Popen(
            [
                sys.executable,
                "-m",
                "celery",
                "-A",
                "app.jobs.worker",
                "worker",
                "--pool=threads",
                f"--concurrency={n}",
                "--loglevel=WARNING",
                "-n",
                f"bench{i}@%h",
            ],
            env=server.env | {"COLDROUTE_WORKERS": str(n)},
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        for i, n in enumerate(processes)
    ]
    try:
        time.sleep(5)  # the workers connect and warm their processes
        yield server
    finally:
        for worker in workers:
            worker.terminate()
        for worker in workers:
            try:
                worker.wait(timeout=30)
            except subprocess.TimeoutExpired:
                worker.kill()
        server.close()
        with psycopg.connect(POSTGRES, autocommit=True) as connection:
            connection.execute(f"DROP SCHEMA {schema} CASCADE")


def pyvrp_vrptw(
    distance: np.ndarray,
    demand: Sequence[float],
    service_min: Sequence[float],
    window_min: Sequence[tuple[int, int]],
    minutes_per_unit: float,
    capacity: float,
    vans: int,
    budget_s: float,
    fixed_cost: bool = False,
    scale: int = 100,
) -> tuple[float, int, int]:
    """PyVRP alone on a VRPTW instance (the depot first; one unit of distance is one of time,
    ``minutes_per_unit`` minutes; windows in whole minutes) for ``budget_s``, in ``scale``-ths
    of a unit; ``fixed_cost``: a cost per van larger than any set of routes. Its distance
    [units], vans and the stops served (0 when its best breaks a rule)."""
    from pyvrp import Client, Depot, Location, ProblemData, VehicleType, solve
    from pyvrp.stop import MaxRuntime

    per_minute = scale / minutes_per_unit
    arcs = np.rint(distance * scale).astype(np.int64)
    n = arcs.shape[0]
    horizon = int(window_min[0][1] * per_minute)
    data = ProblemData(
        [Location(0.0, 0.0) for _ in range(n)],
        [
            Client(
                location=k,
                delivery=[int(demand[k])],
                service_duration=round(service_min[k] * per_minute),
                tw_early=int(a * per_minute),
                tw_late=int(b * per_minute),
            )
            for k, (a, b) in enumerate(window_min)
            if k
        ],
        [Depot(location=0, tw_early=0, tw_late=horizon)],
        [
            VehicleType(
                vans,
                capacity=[int(capacity)],
                fixed_cost=int(arcs.max() * 2 * n) if fixed_cost else 0,
                tw_late=horizon,
            )
        ],
        [arcs],
        [arcs],
    )
    result = solve(data, stop=MaxRuntime(budget_s), seed=1, display=False)
    served = result.best.num_clients() if result.is_feasible() else 0
    return result.best.distance() / scale, result.best.num_routes(), served


def vienna_stops(
    rng: np.random.Generator,
    n_stops: int,
    service_time_s: float,
    door_open_s: float,
    delivery_kg: float,
    spread_deg: tuple[float, float] = (0.05, 0.08),
) -> list[dict[str, Any]]:
    """``n_stops`` stops (as JSON) scattered uniformly around Vienna's centre, up to
    ``spread_deg`` degrees of latitude and longitude either way, named S0, S1, …"""
    return [
        {
            "id": f"S{i}",
            "lat": 48.21 + rng.uniform(-spread_deg[0], spread_deg[0]),
            "lon": 16.37 + rng.uniform(-spread_deg[1], spread_deg[1]),
            "service_time_s": service_time_s,
            "door_open_s": door_open_s,
            "delivery_kg": delivery_kg,
        }
        for i in range(n_stops)
    ]
