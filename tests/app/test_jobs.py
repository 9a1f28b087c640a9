"""Async jobs on the server's own pool and SQLite: the real server in a subprocess."""

from __future__ import annotations

import copy
import datetime as dt
import itertools
import os
import signal
import tempfile
import time
from pathlib import Path

import httpx
import pytest

from app.examples import (
    ELECTRIFICATION_EXAMPLE,
    FLEET_PLAN_EXAMPLE,
    PLAN_EXAMPLE,
    SCENARIOS_EXAMPLE,
)
from testbed.services import Server, children
from testbed.serving import alive, big_fleet, busiest_child, long_plan, wait_quiet
from tests.router_stub import DownRouter

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

FAST = {
    "COLDROUTE_WORKERS": "2",
    "COLDROUTE_JOB_SLOTS": "1",
    "COLDROUTE_JOB_HEARTBEAT_S": "0.5",
    "COLDROUTE_JOB_STALE_AFTER_S": "2",
    "COLDROUTE_JOB_PART_ROUTE_DAYS": "100",  # a study job in many parts
}


@pytest.fixture(scope="module")
def server():
    started = Server(FAST).start()
    yield started
    started.close()


def submit(url: str, body: dict, key: str | None = None) -> httpx.Response:
    headers = {"Idempotency-Key": key} if key else {}
    return httpx.post(f"{url}/v1/jobs", json=body, headers=headers, timeout=30)


def wait_for(url: str, job_id: str, states=("succeeded", "failed", "cancelled"), timeout=60):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        job = httpx.get(f"{url}/v1/jobs/{job_id}", timeout=10).json()
        if job["status"] in states:
            return job
        time.sleep(0.2)
    raise AssertionError(f"job {job_id} still {job['status']} after {timeout} s")


def test_a_plan_job_answers_what_the_endpoint_answers(server):
    response = submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE})
    assert response.status_code == 202
    job = response.json()
    assert job["status"] == "queued" and job["type"] == "plan" and job["created_at"]
    assert response.headers["Location"] == f"/v1/jobs/{job['id']}"
    done = wait_for(server.url, job["id"])
    assert done["status"] == "succeeded" and done["attempts"] == 1 and done["error"] is None
    assert done["started_at"] >= done["created_at"] and done["finished_at"] >= done["started_at"]
    direct = httpx.post(f"{server.url}/v1/plans", json=PLAN_EXAMPLE, timeout=30).json()
    for answer in (done["result"], direct):
        answer["solver"].pop("runtime_s")
    assert done["result"] == direct
    asked = httpx.get(f"{server.url}/v1/jobs/{job['id']}?include_request=true", timeout=10)
    assert asked.json()["request"] == PLAN_EXAMPLE and done["request"] is None


def test_a_scenarios_job(server):
    done = wait_for(
        server.url,
        submit(server.url, {"type": "scenarios", "request": SCENARIOS_EXAMPLE}).json()["id"],
    )
    assert done["status"] == "succeeded" and len(done["result"]["cells"]) == 12


def test_a_fleet_plan_job_answers_what_the_endpoint_answers(server):
    response = submit(server.url, {"type": "fleet-plan", "request": FLEET_PLAN_EXAMPLE})
    assert response.status_code == 202 and response.json()["type"] == "fleet-plan"
    done = wait_for(server.url, response.json()["id"])
    assert done["status"] == "succeeded", done
    # the job's work again on the endpoint: on a busy machine the clock may have cut the job
    replay = {"replay": done["result"]["solver"]["replay"]}
    direct = httpx.post(
        f"{server.url}/v1/fleet-plans", json=FLEET_PLAN_EXAMPLE | replay, timeout=60
    ).json()
    for answer in (done["result"], direct):
        answer["solver"].pop("runtime_s")
        for route in answer["routes"]:
            route["solver"].pop("runtime_s")
    assert done["result"] == direct


def test_a_day_of_1000_stops_answers_within_its_time_limit(server):
    # the bound: the time limit plus 10 % or 2 s, whichever is larger, on the API
    # and as a job (its time running); the work is more than the limit allows
    limit_s = 20.0
    bound_s = limit_s + max(0.1 * limit_s, 2.0)
    body = big_fleet(1000, 100, limit_s)
    started = time.perf_counter()
    direct = httpx.post(f"{server.url}/v1/fleet-plans", json=body, timeout=120)
    waited_s = time.perf_counter() - started
    assert direct.status_code == 200
    answer = direct.json()
    assert answer["solver"]["stopped_by"] == "time_limit"
    assert sum(len(route["stops"]) for route in answer["routes"]) > 900
    assert waited_s <= bound_s
    submitted = submit(server.url, {"type": "fleet-plan", "request": body}).json()
    job = wait_for(server.url, submitted["id"])
    assert job["status"] == "succeeded"
    started_at, finished_at = (
        dt.datetime.fromisoformat(job[k]) for k in ("started_at", "finished_at")
    )
    assert (finished_at - started_at).total_seconds() <= bound_s


@pytest.mark.parametrize(
    ("body", "field"),
    [
        (
            {
                "type": "fleet-plan",
                "request": FLEET_PLAN_EXAMPLE
                | {"vehicles": [FLEET_PLAN_EXAMPLE["vehicles"][0] | {"shift_end": "05:00"}]},
            },
            "request.vehicles[0].shift_end",
        ),
        (
            {
                "type": "fleet-plan",
                "request": FLEET_PLAN_EXAMPLE | {"vehicles": FLEET_PLAN_EXAMPLE["vehicles"] * 2},
            },
            "request.vehicles[2].id",
        ),
        (
            {"type": "plan", "request": PLAN_EXAMPLE | {"depot": {"lat": 99, "lon": 16}}},
            "request.depot.lat",
        ),
        (
            {
                "type": "plan",
                "request": PLAN_EXAMPLE | {"stops": [PLAN_EXAMPLE["stops"][0]] * 2},
            },
            "request.stops[1].id",
        ),
        (
            {"type": "plan", "request": PLAN_EXAMPLE | {"timezone": "Mars/Olympus"}},
            "request.timezone",
        ),
        (
            {
                "type": "scenarios",
                "request": SCENARIOS_EXAMPLE
                | {"plan": PLAN_EXAMPLE | {"date": "2026-03-29", "start_time": "02:30"}},
            },
            "request.plan.start_time",
        ),
        ({"type": "fleet", "request": PLAN_EXAMPLE}, "type"),
        ({"type": "plan"}, "request"),
    ],
)
def test_bad_input_is_a_422_at_submission(server, body, field):
    response = submit(server.url, body)
    assert response.status_code == 422
    assert response.headers["content-type"] == "application/problem+json"
    assert any(e["field"] == field for e in response.json()["errors"]), response.json()


@pytest.mark.parametrize(
    ("kind", "body"),
    [
        (
            "plan",
            PLAN_EXAMPLE
            | {
                "cargo_box": {"product_limit_c": 2},
                "battery": {"initial_soc": 0.5, "min_soc": 0.6},
            },
        ),
        (
            "fleet-plan",
            FLEET_PLAN_EXAMPLE
            | {
                "vehicles": [
                    FLEET_PLAN_EXAMPLE["vehicles"][0]
                    | {
                        "cargo_box": {"setpoint_c": 8, "product_limit_c": 6},
                        "battery": {"initial_soc": 0.5, "min_soc": 0.6},
                    }
                ]
            },
        ),
        (
            "scenarios",
            SCENARIOS_EXAMPLE
            | {
                "plan": PLAN_EXAMPLE
                | {"battery": {"min_soc": 0.995}, "cargo_box": {"product_limit_c": 2}}
            },
        ),
    ],
)
def test_a_job_names_every_bad_field_the_endpoint_names(client, kind, body):
    # The same request, synchronously and as a job: the same entries, under request.
    endpoint = {"plan": "/v1/plans", "fleet-plan": "/v1/fleet-plans"}.get(
        kind, "/v1/studies/scenarios"
    )
    direct = client.post(endpoint, json=body)
    as_job = client.post("/v1/jobs", json={"type": kind, "request": body})
    assert direct.status_code == as_job.status_code == 422
    named = [(e["field"], e["message"]) for e in direct.json()["errors"]]
    assert len(named) >= 2
    assert [(e["field"], e["message"]) for e in as_job.json()["errors"]] == [
        (f"request.{field}", message) for field, message in named
    ]


def assert_spaced(calls: list[float], backoff_s: list[float], slack_s: float) -> None:
    """Attempts at the times of ``calls``, each after the backoff before it (and not much
    later)."""
    gaps = [b - a for a, b in itertools.pairwise(calls)]
    assert len(gaps) == len(backoff_s), calls
    for gap, wait_s in zip(gaps, backoff_s, strict=True):
        assert wait_s <= gap < wait_s + slack_s, (gaps, backoff_s)


def test_a_job_whose_router_is_down_is_retried_after_its_backoff():
    router = DownRouter()
    server = Server(
        FAST
        | {
            "COLDROUTE_OSRM_URL": router.url,
            "COLDROUTE_JOB_MAX_ATTEMPTS": "3",
            "COLDROUTE_JOB_RETRY_BACKOFF_S": "[2, 4]",
        }
    ).start()
    try:
        job_id = submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE}).json()["id"]
        done = wait_for(server.url, job_id, timeout=60)
    finally:
        server.close()
        router.stop()
    # Three attempts, 2 s then 4 s apart; then failed, and the failure can be read.
    assert done["status"] == "failed" and done["attempts"] == 3
    assert done["error"]["status"] == 503 and done["error"]["service"] == "osrm"
    assert_spaced(router.table_calls, [2, 4], slack_s=1.5)


def test_an_idempotency_key_returns_the_same_job(server):
    key = f"nightly-{time.time_ns()}"
    first = submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE}, key)
    again = submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE}, key)
    assert (first.status_code, again.status_code) == (202, 200)
    assert again.json()["id"] == first.json()["id"]
    other = copy.deepcopy(PLAN_EXAMPLE) | {"driver_aggressiveness": 1.0}
    conflict = submit(server.url, {"type": "plan", "request": other}, key)
    assert conflict.status_code == 409 and first.json()["id"] in conflict.json()["detail"]


def test_listing_and_unknown_jobs(server):
    ids = [
        submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE}).json()["id"] for _ in range(3)
    ]
    for job_id in ids:
        wait_for(server.url, job_id)
    listed = httpx.get(f"{server.url}/v1/jobs", params={"limit": 2}).json()["jobs"]
    assert [j["id"] for j in listed] == ids[::-1][:2]
    assert "result" not in listed[0]
    succeeded = httpx.get(f"{server.url}/v1/jobs", params={"status": "succeeded"}).json()["jobs"]
    assert set(ids) <= {j["id"] for j in succeeded}
    assert httpx.get(f"{server.url}/v1/jobs", params={"status": "lost"}).status_code == 422
    missing = httpx.get(f"{server.url}/v1/jobs/no-such-job")
    assert (
        missing.status_code == 404 and missing.headers["content-type"] == "application/problem+json"
    )


def test_cancel_a_queued_and_a_running_job(server):
    running = submit(server.url, {"type": "plan", "request": long_plan(300, 30)}).json()["id"]
    wait_for(server.url, running, states=("running",))
    queued = submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE}).json()["id"]
    time.sleep(0.5)
    assert httpx.get(f"{server.url}/v1/jobs/{queued}").json()["status"] == "queued"  # one slot
    cancelled = httpx.delete(f"{server.url}/v1/jobs/{queued}").json()
    assert cancelled["status"] == "cancelled"
    stopped_at = time.monotonic()
    assert httpx.delete(f"{server.url}/v1/jobs/{running}").json()["status"] == "cancelled"
    # the running job's worker is stopped: the next job starts at once, not after 30 s
    following = submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE}).json()["id"]
    assert wait_for(server.url, following)["status"] == "succeeded"
    assert time.monotonic() - stopped_at < 10
    never = httpx.get(f"{server.url}/v1/jobs/{queued}").json()
    assert (
        never["status"] == "cancelled" and never["started_at"] is None and never["result"] is None
    )
    assert httpx.get(f"{server.url}/v1/jobs/{running}").json()["result"] is None
    assert httpx.delete(f"{server.url}/v1/jobs/{following}").status_code == 409


def test_a_worker_killed_mid_job_runs_it_again(server):
    wait_quiet(server.process.pid)  # the only worker that works is then the job's
    job_id = submit(server.url, {"type": "plan", "request": long_plan(300, 8)}).json()["id"]
    wait_for(server.url, job_id, states=("running",))
    time.sleep(0.5)
    solving = busiest_child(server.process.pid)
    assert solving is not None, "no worker is solving"
    killed_at = dt.datetime.now(dt.UTC)
    os.kill(solving, signal.SIGKILL)
    done = wait_for(server.url, job_id)
    assert done["status"] == "succeeded"
    assert dt.datetime.fromisoformat(done["started_at"]) > killed_at  # it ran again
    # An attempt, unless Pebble had not yet heard that worker take it: on a busy machine the
    # word may come late, and the pool then broke "before it ran" (no attempt counted).
    assert done["attempts"] in (1, 2)


def test_sigkill_and_restart_lose_no_job():
    with tempfile.TemporaryDirectory() as folder:
        first = Server(FAST, database_dir=Path(folder)).start()
        done_before = submit(first.url, {"type": "plan", "request": PLAN_EXAMPLE}).json()["id"]
        wait_for(first.url, done_before)
        pending = [
            submit(first.url, {"type": "plan", "request": long_plan(150, 3, seed=s)}).json()["id"]
            for s in range(3)
        ]
        wait_for(first.url, pending[0], states=("running",))
        workers = children(first.process.pid)
        first.process.send_signal(signal.SIGKILL)
        first.process.wait()
        deadline = time.monotonic() + 8  # the workers notice their server is gone
        while any(alive(pid) for pid in workers) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not any(alive(pid) for pid in workers)
        second = Server(FAST, database_dir=Path(folder)).start()
        try:
            finished = [wait_for(second.url, job_id, timeout=90) for job_id in pending]
            assert [job["status"] for job in finished] == ["succeeded"] * 3
            assert finished[0]["attempts"] == 2  # the one that was running ran again
            kept = httpx.get(f"{second.url}/v1/jobs/{done_before}").json()
            assert kept["status"] == "succeeded" and kept["result"]["tour"][0] == "depot-simmering"
        finally:
            second.close()


def test_finished_jobs_expire_after_the_retention():
    short = Server(FAST | {"COLDROUTE_JOB_RETENTION_S": "1"}).start()
    try:
        job_id = submit(short.url, {"type": "plan", "request": PLAN_EXAMPLE}).json()["id"]
        wait_for(short.url, job_id)
        deadline = time.monotonic() + 15
        while httpx.get(f"{short.url}/v1/jobs/{job_id}").status_code != 404:
            assert time.monotonic() < deadline
            time.sleep(0.5)
    finally:
        short.close()


def fleet_study(copies: int, weekdays: list[str], candidates: int) -> dict:
    """The example study's routes ``copies`` times (their own ids), driven on ``weekdays``,
    with its first ``candidates``."""
    study = copy.deepcopy(ELECTRIFICATION_EXAMPLE)
    study["routes"] = [
        route | {"id": f"{route['id']}-{k}", "days": {"weekdays": weekdays}}
        for k in range(copies)
        for route in copy.deepcopy(ELECTRIFICATION_EXAMPLE["routes"])
    ]
    study["candidates"] = study["candidates"][:candidates]
    return study


#: A study of some seconds on two workers: 8 routes, 6 days a week, 2 candidates.
BIG_STUDY = fleet_study(4, ["mon", "tue", "wed", "thu", "fri", "sat"], 2)


def without_clock(answer: dict) -> dict:
    return {k: v for k, v in answer.items() if k not in ("runtime_s", "route_days_per_s")}


def test_an_electrification_job_answers_what_the_endpoint_answers(server):
    """The study as a job, cut into a part per route (each of about 100 route-days) shared out
    over the workers: the same routes, days and verdicts as the synchronous answer, which cuts
    it in two (one part per worker) — its clock aside."""
    study = fleet_study(2, ["mon", "wed", "fri"], 1)
    sync = httpx.post(f"{server.url}/v1/studies/electrification", json=study, timeout=120)
    assert sync.status_code == 200, sync.text
    job_id = submit(server.url, {"type": "electrification", "request": study}).json()["id"]
    done = wait_for(server.url, job_id, timeout=120)
    assert done["status"] == "succeeded", done
    route_days = sync.json()["route_days"]
    assert done["progress"] == {
        "done": route_days,
        "total": route_days,
        "parts_done": 4,
        "parts_total": 4,
    }
    assert without_clock(done["result"]) == without_clock(sync.json())
    listed = httpx.get(f"{server.url}/v1/jobs?limit=5").json()["jobs"]
    assert next(j for j in listed if j["id"] == job_id)["progress"]["parts_done"] == 4
    plan_job = submit(server.url, {"type": "plan", "request": PLAN_EXAMPLE}).json()
    assert plan_job["progress"] is None  # not run in parts


def running_with_parts_done(url: str, job_id: str, timeout_s: float = 60) -> dict:
    """The job once it runs and some, not all, of its parts are done."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        job = httpx.get(f"{url}/v1/jobs/{job_id}", timeout=10).json()
        progress = job["progress"]
        if job["status"] == "running" and progress and progress["parts_done"] > 0:
            assert progress["parts_done"] < progress["parts_total"], "finished too soon to test"
            return job
        time.sleep(0.1)
    raise AssertionError(f"job {job_id}: no part done within {timeout_s} s")


def test_a_study_job_loses_nothing_when_a_worker_is_killed(server):
    """A worker process killed mid-part: that part is redone (not the job, not the parts
    done), and the answer is that of a run nobody disturbed."""
    calm = submit(server.url, {"type": "electrification", "request": BIG_STUDY}).json()["id"]
    calm_done = wait_for(server.url, calm, timeout=180)
    assert calm_done["status"] == "succeeded", calm_done
    wait_quiet(server.process.pid)
    job_id = submit(server.url, {"type": "electrification", "request": BIG_STUDY}).json()["id"]
    before = running_with_parts_done(server.url, job_id)["progress"]
    working = busiest_child(server.process.pid)
    assert working is not None, "no worker is simulating"
    os.kill(working, signal.SIGKILL)
    done = wait_for(server.url, job_id, timeout=180)
    assert done["status"] == "succeeded" and done["attempts"] == 1, done
    assert done["progress"]["parts_done"] == done["progress"]["parts_total"]
    assert done["progress"]["parts_done"] > before["parts_done"]
    assert without_clock(done["result"]) == without_clock(calm_done["result"])


def test_a_running_study_job_is_cancelled_with_its_parts(server):
    wait_quiet(server.process.pid)
    job_id = submit(server.url, {"type": "electrification", "request": BIG_STUDY}).json()["id"]
    running_with_parts_done(server.url, job_id)
    cancelled = httpx.delete(f"{server.url}/v1/jobs/{job_id}").json()
    assert cancelled["status"] == "cancelled"
    wait_quiet(server.process.pid, timeout_s=10)  # every part's worker was stopped
    left = httpx.get(f"{server.url}/v1/jobs/{job_id}").json()
    time.sleep(1.5)
    assert httpx.get(f"{server.url}/v1/jobs/{job_id}").json()["progress"] == left["progress"]
    progress = left["progress"]
    assert left["result"] is None and progress["parts_done"] < progress["parts_total"]


def test_a_study_job_resumes_after_the_server_is_killed_keeping_its_parts():
    """SIGKILL of the server mid-study; the next server on the same database runs the job
    again from the parts that were done (their count never goes back) to the same answer."""
    with tempfile.TemporaryDirectory() as folder:
        first = Server(FAST, database_dir=Path(folder)).start()
        calm = submit(first.url, {"type": "electrification", "request": BIG_STUDY}).json()["id"]
        calm_done = wait_for(first.url, calm, timeout=180)
        job_id = submit(first.url, {"type": "electrification", "request": BIG_STUDY}).json()["id"]
        running_with_parts_done(first.url, job_id)
        first.process.send_signal(signal.SIGKILL)
        first.process.wait()
        second = Server(FAST, database_dir=Path(folder)).start()
        try:
            resumed = httpx.get(f"{second.url}/v1/jobs/{job_id}").json()["progress"]
            assert resumed["parts_done"] > 0  # what the first server finished is kept
            seen = [resumed["parts_done"]]
            deadline = time.monotonic() + 180
            while (job := httpx.get(f"{second.url}/v1/jobs/{job_id}").json())["status"] in (
                "queued",
                "running",
            ):
                seen.append(job["progress"]["parts_done"])
                assert time.monotonic() < deadline
                time.sleep(0.2)
            assert seen == sorted(seen), seen  # never counted down
            assert job["status"] == "succeeded" and job["attempts"] == 2, job
            assert without_clock(job["result"]) == without_clock(calm_done["result"])
        finally:
            second.close()
