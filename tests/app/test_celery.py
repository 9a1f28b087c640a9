"""Scale-out: jobs through Celery workers on Redis, with PostgreSQL — the real services of the
test machines (127.0.0.1:5432 database ``test``, 127.0.0.1:6379), real worker processes."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import threading
import time
import uuid
from collections.abc import Iterator

import httpx
import psycopg
import pytest
import redis

from app.examples import CHARGING_PLAN_EXAMPLE, PLAN_EXAMPLE
from testbed.services import Server, children
from testbed.serving import cpu_ticks, long_plan
from tests.app.test_jobs import (
    BIG_STUDY,
    assert_spaced,
    running_with_parts_done,
    submit,
    wait_for,
    without_clock,
)
from tests.router_stub import DownRouter
from tests.utils.answers import without_timing

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

POSTGRES = "postgresql://postgres@127.0.0.1:5432/test"
REDIS_DB = 11


@contextlib.contextmanager
def own_services() -> Iterator[dict[str, str]]:
    """A schema of our own in PostgreSQL and a queue of our own on Redis: the settings."""
    schema = f"coldroute_{uuid.uuid4().hex[:10]}"
    with psycopg.connect(POSTGRES, autocommit=True) as connection:
        connection.execute(f"CREATE SCHEMA {schema}")
    broker = f"redis://127.0.0.1:6379/{REDIS_DB}"
    env = {
        "COLDROUTE_DATABASE_URL": "postgresql+psycopg://postgres@127.0.0.1:5432/test"
        f"?options=-csearch_path%3D{schema}",
        "COLDROUTE_BROKER_URL": broker,
        "COLDROUTE_BROKER_QUEUE": f"jobs-{schema}",
        "COLDROUTE_JOB_HEARTBEAT_S": "0.5",
        "COLDROUTE_JOB_STALE_AFTER_S": "3",
        "COLDROUTE_WORKERS": "1",
        "COLDROUTE_JOB_PART_ROUTE_DAYS": "100",  # a study job in a part per route
        "COLDROUTE_MAX_SYNC_ROUTE_DAYS": "100000",  # the local answer to compare with
    }
    try:
        yield env
    finally:
        with psycopg.connect(POSTGRES, autocommit=True) as connection:
            connection.execute(f"DROP SCHEMA {schema} CASCADE")


@pytest.fixture(scope="module")
def services():
    """The module's schema and an empty Redis database."""
    broker = redis.Redis.from_url(f"redis://127.0.0.1:6379/{REDIS_DB}")
    broker.flushdb()
    with own_services() as env:
        yield env
    broker.flushdb()


class Worker:
    """``celery -A app.jobs.worker worker --pool=threads`` with one worker process (as
    ``make worker``), in its own process group."""

    def __init__(self, env: dict[str, str], name: str, concurrency: int = 1) -> None:
        inherited = {k: v for k, v in os.environ.items() if not k.startswith("COLDROUTE_")}
        self.process = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "celery",
                "-A",
                "app.jobs.worker",
                "worker",
                "--pool=threads",
                f"--concurrency={concurrency}",
                "--loglevel=WARNING",
                "--without-gossip",
                "--without-mingle",
                "-n",
                f"{name}@%h",
            ],
            env=inherited | env,
            start_new_session=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )

    def kill(self) -> None:
        os.killpg(self.process.pid, signal.SIGKILL)
        self.process.wait()

    def stop(self) -> None:
        if self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGTERM)
            try:
                self.process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.kill()


@pytest.fixture(scope="module")
def workers(services):
    started = [Worker(services, f"w{i}") for i in (1, 2)]
    yield started
    for worker in started:
        worker.stop()


@pytest.fixture(scope="module")
def server(services, workers):
    started = Server(services).start()
    yield started
    started.close()


def ready_within(url: str, timeout_s: float) -> dict:
    """Readiness once it says ready, or as it last said after ``timeout_s``: the Celery
    workers start beside the server and answer the inspection once they have loaded."""
    deadline = time.monotonic() + timeout_s
    while True:
        ready = httpx.get(f"{url}/readyz", timeout=10).json()
        if ready["status"] == "ready" or time.monotonic() > deadline:
            return ready
        time.sleep(0.5)


def test_jobs_run_on_the_celery_workers(server, workers):
    ready = ready_within(server.url, 30)
    assert {c["name"] for c in ready["checks"]} >= {"workers", "database", "broker"}
    assert ready["status"] == "ready", ready
    # The same work for the jobs and the direct answer: a busy machine's clock cuts none.
    body = PLAN_EXAMPLE | {"time_limit_s": 30, "work_s": 0.5}
    ids = [submit(server.url, {"type": "plan", "request": body}).json()["id"] for _ in range(4)]
    done = [wait_for(server.url, job_id, timeout=90) for job_id in ids]
    assert [job["status"] for job in done] == ["succeeded"] * 4
    direct = httpx.post(f"{server.url}/v1/plans", json=body, timeout=30).json()
    assert done[0]["result"]["tour"] == direct["tour"]


def test_a_celery_job_answers_byte_for_byte_what_the_endpoint_answers(server, workers):
    """The same request, the same answer on a Celery worker (but the timing fields): a day
    that charges, where a search stopped by the clock would differ — so the endpoint is sent
    the job's work (its replay): on a busy machine the clock may have cut the job's."""
    job = submit(server.url, {"type": "plan", "request": CHARGING_PLAN_EXAMPLE}).json()
    done = wait_for(server.url, job["id"], timeout=120)
    assert done["status"] == "succeeded"
    replay = {"replay": done["result"]["solver"]["replay"]}
    direct = httpx.post(
        f"{server.url}/v1/plans", json=CHARGING_PLAN_EXAMPLE | replay, timeout=60
    ).json()
    assert without_timing(done["result"]) == without_timing(direct)


def part_runners(env: dict[str, str], job_id: str) -> dict[int, tuple[str, str]]:
    """Each part of a job: its status and the worker that holds or did it."""
    schema = env["COLDROUTE_DATABASE_URL"].rsplit("search_path%3D", 1)[1]
    with psycopg.connect(POSTGRES, options=f"-csearch_path={schema}") as connection:
        rows = connection.execute(
            'SELECT "index", status, runner FROM job_parts WHERE job_id = %s', (job_id,)
        )
        return {index: (status, (runner or "").split("@")[0]) for index, status, runner in rows}


@pytest.fixture(scope="module")
def local_study(server):
    """The study answered by the server's own pool (the synchronous endpoint)."""
    answer = httpx.post(f"{server.url}/v1/studies/electrification", json=BIG_STUDY, timeout=300)
    assert answer.status_code == 200, answer.text
    return answer.json()


def test_a_study_job_is_shared_out_over_the_workers_and_equals_the_local_answer(
    services, server, workers, local_study
):
    job_id = submit(server.url, {"type": "electrification", "request": BIG_STUDY}).json()["id"]
    done = wait_for(server.url, job_id, timeout=300)
    assert done["status"] == "succeeded", done
    assert done["progress"]["parts_total"] == len(BIG_STUDY["routes"])  # a part per route
    by = part_runners(services, job_id)
    assert {status for status, _ in by.values()} == {"done"}
    assert {worker for _, worker in by.values()} == {"w1", "w2"}  # both took parts
    assert without_clock(done["result"]) == without_clock(local_study)


def test_a_worker_killed_mid_study_loses_nothing(services, server, workers, local_study):
    """Two more workers; one is killed while it runs a part: that part is redone elsewhere,
    the parts done are kept, and the answer is the local one."""
    extra = [Worker(services, name) for name in ("w3", "w4")]
    try:
        ready_within(server.url, 30)
        job_id = submit(server.url, {"type": "electrification", "request": BIG_STUDY}).json()["id"]
        running_with_parts_done(server.url, job_id, timeout_s=120)
        deadline = time.monotonic() + 60
        while ("running", "w3") not in part_runners(services, job_id).values():
            assert time.monotonic() < deadline, part_runners(services, job_id)
            time.sleep(0.05)
        extra[0].kill()
        done = wait_for(server.url, job_id, timeout=300)
        assert done["status"] == "succeeded", done
        assert done["progress"]["parts_done"] == done["progress"]["parts_total"]
        assert without_clock(done["result"]) == without_clock(local_study)
    finally:
        for worker in extra:
            worker.stop()


def test_a_worker_killed_mid_job_leaves_it_to_another(server, workers):
    job_id = submit(server.url, {"type": "plan", "request": long_plan(300, 6)}).json()["id"]
    wait_for(server.url, job_id, states=("running",), timeout=60)
    time.sleep(1.0)
    pids = {pid: w for w in workers for pid in children(w.process.pid)}
    used = cpu_ticks(list(pids))
    running = pids[max(used, key=used.__getitem__)]  # the worker that solves, however loaded
    running.kill()
    done = wait_for(server.url, job_id, timeout=120)
    assert done["status"] == "succeeded" and done["attempts"] == 2
    workers.remove(running)


def test_sigkill_of_the_server_loses_no_job(services, workers):
    first = Server(services).start()
    ids = [
        submit(first.url, {"type": "plan", "request": long_plan(100, 2, seed=s)}).json()["id"]
        for s in range(3)
    ]
    first.process.send_signal(signal.SIGKILL)
    first.process.wait()
    second = Server(services).start()
    try:
        done = [wait_for(second.url, job_id, timeout=120) for job_id in ids]
        assert [job["status"] for job in done] == ["succeeded"] * 3
    finally:
        second.close()
        first.close()


def test_cancel_a_running_celery_job(server, workers):
    job_id = submit(server.url, {"type": "plan", "request": long_plan(300, 30)}).json()["id"]
    wait_for(server.url, job_id, states=("running",), timeout=60)
    stopped_at = time.monotonic()
    assert httpx.delete(f"{server.url}/v1/jobs/{job_id}").json()["status"] == "cancelled"
    following = submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE}).json()["id"]
    assert wait_for(server.url, following, timeout=60)["status"] == "succeeded"
    assert time.monotonic() - stopped_at < 20
    assert httpx.get(f"{server.url}/v1/jobs/{job_id}").json()["status"] == "cancelled"


class Messages:
    """Every task message sent to a queue, counted from Redis's MONITOR stream."""

    def __init__(self, queue: str) -> None:
        self.queue = queue
        self.sent: list[float] = []
        self._stop = False
        self._client = redis.Redis(port=6379, db=REDIS_DB)
        self._thread = threading.Thread(target=self._watch, daemon=True)
        self._thread.start()
        time.sleep(0.3)

    def _watch(self) -> None:
        with self._client.monitor() as monitor:
            for command in monitor.listen():
                if self._stop:
                    return
                words = command["command"].split(" ", 2)
                if words[0].upper() == "LPUSH" and words[1].strip('"') == self.queue:
                    self.sent.append(time.time())

    def stop(self) -> None:
        self._stop = True
        self._client.ping()  # one more command, so that the monitor loop sees the flag


def test_a_job_whose_router_is_down_is_retried_after_its_backoff_one_message_each():
    router = DownRouter()
    with own_services() as env:
        env |= {
            "COLDROUTE_OSRM_URL": router.url,
            "COLDROUTE_JOB_MAX_ATTEMPTS": "3",
            "COLDROUTE_JOB_RETRY_BACKOFF_S": "[3, 6]",
        }
        messages = Messages(env["COLDROUTE_BROKER_QUEUE"])
        worker = Worker(env, "retrying")
        server = Server(env).start()
        try:
            job_id = submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE}).json()["id"]
            done = wait_for(server.url, job_id, timeout=90)
        finally:
            server.close()
            worker.stop()
            messages.stop()
            router.stop()
    assert done["status"] == "failed" and done["attempts"] == 3
    assert done["error"]["service"] == "osrm"
    # Three attempts 3 s then 6 s apart (the dispatcher looks every 2 s), one message each.
    assert_spaced(router.table_calls, [3, 6], slack_s=3.5)
    assert len(messages.sent) == 3, messages.sent
