"""The service and the outside services as processes for tests and benchmarks: a server on a
free port, a Celery cluster, a busy core, a process's children and memory."""

from __future__ import annotations

import multiprocessing
import os
import socket
import subprocess
import sys
import tempfile
import time
import uuid
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import httpx


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
