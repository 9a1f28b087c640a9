"""Helpers shared by the benchmarks: reference data location and table printing."""

from __future__ import annotations

import multiprocessing
import os
import socket
import subprocess
import sys
import time
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


def _burn(stop: Any) -> None:
    while not stop.is_set():
        sum(i * i for i in range(10_000))


@contextmanager
def busy_core() -> Iterator[None]:
    """Another process keeps one core fully busy for the duration (a second client's solve)."""
    context = multiprocessing.get_context("spawn")
    stop = context.Event()
    burner = context.Process(target=_burn, args=(stop,), daemon=True)
    burner.start()
    time.sleep(0.3)
    try:
        yield
    finally:
        stop.set()
        burner.join(timeout=5)


@contextmanager
def running_server(env: dict[str, str] | None = None) -> Iterator[str]:
    """The real service (uvicorn, a free loopback port) for the duration; yields its URL."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    environment = {k: v for k, v in os.environ.items() if not k.startswith("COLDROUTE_")}
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "uvicorn",
            "app.main:app",
            "--host",
            "127.0.0.1",
            "--port",
            str(port),
            "--log-level",
            "warning",
        ],
        env=environment | {"COLDROUTE_LOG_LEVEL": "warning"} | (env or {}),
        stdout=subprocess.DEVNULL,
    )
    url = f"http://127.0.0.1:{port}"
    try:
        for _ in range(150):
            try:
                if httpx.get(f"{url}/healthz", timeout=1).status_code == 200:
                    break
            except httpx.TransportError:
                time.sleep(0.1)
        else:
            raise RuntimeError("the server did not start within 15 s")
        yield url
    finally:
        process.terminate()
        process.wait(timeout=10)
