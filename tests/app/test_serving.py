"""Serving that holds: the real server (python -m app.serve) in a subprocess, its worker pool
saturated, its queue full, its shutdown."""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import os
import signal
import time

import httpx
import pytest
from pebble import ProcessPool

from app.execution import WorkerPool, ping, pool_broke
from testbed.services import Server, children
from testbed.serving import alive, heap_kept_after_churn_bytes, long_plan

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow


@pytest.fixture
def server(request):
    env = {"COLDROUTE_WORKERS": "2"} | getattr(request, "param", {})
    started = Server(env).start()
    yield started
    started.close()


def post(url: str, body: dict, timeout: float = 60) -> httpx.Response:
    return httpx.post(f"{url}/v1/plans", json=body, timeout=timeout)


def workers_detail(url: str) -> str:
    checks = httpx.get(f"{url}/readyz", timeout=5).json()["checks"]
    return next(c["detail"] for c in checks if c["name"] == "workers")


def wait_until(url: str, words: str, timeout_s: float = 10.0) -> None:
    """Until readiness's workers check says ``words`` (e.g. "1 busy"): a loaded machine may
    take longer than a fixed sleep to hand a request to its worker."""
    deadline = time.monotonic() + timeout_s
    while words not in workers_detail(url):
        assert time.monotonic() < deadline, f"never {words!r}: {workers_detail(url)}"
        time.sleep(0.05)


def test_liveness_answers_while_every_worker_solves(server):
    # Two 300-stop rounds of up to 6 s each (the search may stall sooner) keep both workers
    # (both cores) busy.
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        solving = [pool.submit(post, server.url, long_plan(300, 6, seed=s)) for s in (1, 2)]
        time.sleep(1.0)
        latencies = []
        while not all(f.done() for f in solving) and len(latencies) < 200:
            started = time.perf_counter()
            assert httpx.get(f"{server.url}/healthz", timeout=5).status_code == 200
            latencies.append(time.perf_counter() - started)
            time.sleep(0.02)
        assert [f.result().status_code for f in solving] == [200, 200]
    assert len(latencies) >= 10
    # Answered while the solves run, not after them: a blocked event loop would hold the probes
    # for seconds (each solve takes seconds). How fast exactly is bench_serving's figure.
    assert max(latencies) < 1.0


@pytest.mark.parametrize(
    "server",
    [{"COLDROUTE_WORKERS": "1", "COLDROUTE_QUEUE_SIZE": "1", "COLDROUTE_QUEUE_DEADLINE_S": "2"}],
    indirect=True,
)
def test_a_full_queue_and_a_long_wait_are_503_with_retry_after(server):
    with concurrent.futures.ThreadPoolExecutor(3) as pool:
        busy = pool.submit(post, server.url, long_plan(300, 12))
        wait_until(server.url, "1 busy")
        queued = pool.submit(post, server.url, long_plan(8, 0.1))
        wait_until(server.url, "1 waiting")
        started = time.perf_counter()
        full = post(server.url, long_plan(8, 0.1))
        assert time.perf_counter() - started < 1.0  # refused at once, not left hanging
        assert full.status_code == 503 and "Retry-After" in full.headers
        assert full.headers["content-type"] == "application/problem+json"
        assert full.json()["service"] == "workers"
        # the queued one waited past its 2 s deadline for the busy worker
        late = queued.result()
        assert late.status_code == 503 and int(late.headers["Retry-After"]) >= 1
        assert busy.result().status_code == 200


@pytest.mark.parametrize("server", [{"COLDROUTE_WORKERS": "1"}], indirect=True)
def test_a_client_that_goes_away_gives_up_its_place(server):
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        busy = pool.submit(post, server.url, long_plan(300, 10))
        wait_until(server.url, "1 busy")  # not a fixed sleep: a busy machine parses slowly
        with pytest.raises(httpx.ReadTimeout):
            post(server.url, long_plan(8, 0.1), timeout=0.5)
        time.sleep(0.5)
        workers = next(
            c for c in httpx.get(f"{server.url}/readyz").json()["checks"] if c["name"] == "workers"
        )
        assert "0 waiting" in workers["detail"]
        assert busy.result().status_code == 200


@pytest.mark.parametrize("server", [{"COLDROUTE_WORKERS": "1"}], indirect=True)
def test_readiness_names_what_is_down(server):
    ready = httpx.get(f"{server.url}/readyz")
    assert ready.status_code == 200 and ready.json()["status"] == "ready"
    assert {c["name"] for c in ready.json()["checks"]} == {"workers", "database"}
    # a configured router that is down makes the server unready, naming it
    port = Server().port
    broken = Server({"COLDROUTE_OSRM_URL": f"http://127.0.0.1:{port}"}).start()
    try:
        response = httpx.get(f"{broken.url}/readyz")
        assert response.status_code == 503
        osrm = next(c for c in response.json()["checks"] if c["name"] == "osrm")
        assert not osrm["ok"] and osrm["critical"]
    finally:
        broken.close()


@pytest.mark.parametrize("server", [{"COLDROUTE_WORKERS": "1"}], indirect=True)
def test_sigterm_refuses_new_work_finishes_what_runs_and_exits_in_time(server):
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        running = pool.submit(post, server.url, long_plan(300, 3))
        wait_until(server.url, "1 busy")
        waiting = pool.submit(post, server.url, long_plan(8, 0.1))
        wait_until(server.url, "1 waiting")
        signalled = time.monotonic()
        server.process.send_signal(signal.SIGTERM)
        time.sleep(0.3)
        with pytest.raises(httpx.ConnectError):  # refused at once, not hanging
            httpx.get(f"{server.url}/healthz", timeout=2)
        assert waiting.result().status_code == 503
        assert running.result().status_code == 200  # finished within the 8 s grace
        server.process.wait(timeout=10)
        assert time.monotonic() - signalled < 10


@pytest.mark.parametrize(
    "server", [{"COLDROUTE_WORKERS": "1", "COLDROUTE_SHUTDOWN_GRACE_S": "2"}], indirect=True
)
def test_sigterm_answers_503_to_what_outlasts_the_grace(server):
    workers = children(server.process.pid)
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        running = pool.submit(post, server.url, long_plan(300, 8))
        wait_until(server.url, "1 busy")  # solving, not on its way in (a loaded machine)
        signalled = time.monotonic()
        server.process.send_signal(signal.SIGTERM)
        late = running.result()
        assert late.status_code == 503 and "shut down" in late.json()["detail"]
        server.process.wait(timeout=10)
        assert time.monotonic() - signalled < 2 + 3
    # no orphaned solver left behind (a worker's watchdog notices its server is gone within a
    # second of starting up)
    deadline = time.monotonic() + 8
    while any(alive(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert workers and not any(alive(pid) for pid in workers)


def test_workers_keep_freed_memory_for_the_next_simulation():
    # glibc trims the heap's top once 128 kB lie free there; the workers keep it (keep_heap),
    # so numpy's per-second arrays are not faulted in anew at every allocation.
    fresh = ProcessPool(max_workers=1, context=multiprocessing.get_context("spawn"))
    workers = WorkerPool(1)
    try:
        untuned = fresh.schedule(heap_kept_after_churn_bytes).result(timeout=60)
        tuned = workers.schedule(heap_kept_after_churn_bytes, ()).result(timeout=60)
    finally:
        fresh.stop()
        workers.stop()
    assert untuned < 1 << 20
    assert tuned > 6 << 20


def test_a_pool_a_dead_idle_worker_broke_is_replaced():
    """Pebble marks its whole pool broken when a worker dies while idle (the kernel's
    out-of-memory killer): every later task failed. The next task gets a new pool."""
    workers = WorkerPool(2)
    try:
        workers.warm()
        pid = workers.schedule(ping, ()).result(timeout=60)
        os.kill(pid, signal.SIGKILL)
        deadline = time.monotonic() + 10
        while workers._pool is not None and workers._pool.active:  # Pebble notices
            assert time.monotonic() < deadline, "the pool never noticed its dead worker"
            time.sleep(0.05)
        assert not workers.active
        again = workers.schedule(ping, ()).result(timeout=60)
        assert again != pid and workers.active
    finally:
        workers.stop()


def test_only_pebbles_own_breakage_is_taken_for_a_broken_pool():
    from concurrent.futures.process import BrokenProcessPool

    assert pool_broke(RuntimeError("Unexpected error within the Pool"))
    assert pool_broke(BrokenProcessPool("All workers expired"))
    assert not pool_broke(RuntimeError("a task's own error"))
    assert not pool_broke(ValueError("Unexpected error within the Pool"))
