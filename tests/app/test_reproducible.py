"""The same request gives the same answer: every OpenAPI example of /v1/plans and
/v1/fleet-plans sent three times — once while another solve keeps both cores busy — to a
real server with two worker processes, and as a job, answers byte for byte the same, but for
the timing fields the OpenAPI document names (``solver.runtime_s``). And a status claims only
what was proven: a round trip proven optimal, a charging day's order proven but its charges
not, a fleet never."""

from __future__ import annotations

import contextlib
import copy
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from app.examples import describe
from app.execution import WORKER_NICENESS
from app.main import app
from app.openapi_doc import RESPONSE_EXAMPLES
from benchmarks.common import Server, busy_core
from tests.app.apps import app_client
from tests.app.test_jobs import submit, wait_for

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "integrators" / "rounds.md"
#: The answer's fields that report timing: they differ between runs.
TIMING = ("runtime_s",)


def examples(path: str) -> list[tuple[str, dict[str, Any]]]:
    operation = app.openapi()["paths"][path]["post"]
    found = operation["requestBody"]["content"]["application/json"]["examples"]
    return [(name, example["value"]) for name, example in found.items()]


CASES = [
    (path, name, body) for path in ("/v1/plans", "/v1/fleet-plans") for name, body in examples(path)
]


def without_timing(answer: Any) -> Any:
    """The answer without its timing fields, as canonical JSON text."""

    def strip(value: Any) -> Any:
        if isinstance(value, dict):
            return {k: strip(v) for k, v in value.items() if k not in TIMING}
        if isinstance(value, list):
            return [strip(v) for v in value]
        return value

    return json.dumps(strip(answer), sort_keys=True)


@contextlib.contextmanager
def both_cores_busy() -> Iterator[None]:
    """Another solve of the service (a process at its workers' priority) beside this one:
    both cores busy."""
    with busy_core(WORKER_NICENESS):
        yield


@pytest.fixture
def client_default():
    """A client of the app with the default settings (a request's time limit up to 30 s)."""
    return app_client()


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    started = Server({"COLDROUTE_WORKERS": "2", "COLDROUTE_JOB_SLOTS": "1"}).start()
    yield started
    started.close()


@pytest.mark.parametrize(("path", "name", "body"), CASES, ids=[f"{p}:{n}" for p, n, _ in CASES])
def test_every_example_answers_the_same_idle_busy_and_as_a_job(server, path, name, body):
    def ask() -> dict[str, Any]:
        response = httpx.post(f"{server.url}{path}", json=body, timeout=120)
        assert response.status_code == 200, response.text[:300]
        return response.json()

    first, second = ask(), ask()
    with both_cores_busy():
        busy = ask()
    assert first["solver"].get("stopped_by") != "time_limit", first["solver"]
    assert without_timing(first) == without_timing(second) == without_timing(busy)
    # the figures its description (and the guide) quotes are this answer's
    recorded = json.loads(RESPONSE_EXAMPLES.read_text())["descriptions"][name]
    assert describe(first) == recorded
    if "charg" in name:
        assert recorded in " ".join(GUIDE.read_text().split())
    kind = "plan" if path == "/v1/plans" else "fleet-plan"
    job = wait_for(
        server.url, submit(server.url, {"type": kind, "request": body}).json()["id"], timeout=120
    )
    assert job["status"] == "succeeded", job
    assert without_timing(job["result"]) == without_timing(first)


def test_a_proven_round_trip_is_optimal_with_its_order_proven(client_default):
    answer = client_default.post("/v1/plans", json=examples("/v1/plans")[0][1]).json()
    assert answer["solver"]["status"] == "optimal"
    assert answer["solver"]["proven"] == ["order"]
    assert answer["solver"]["stopped_by"] == "proof"


def test_a_charging_day_proves_its_order_but_not_its_charges(client_default):
    body = dict(examples("/v1/plans"))["vienna-40-stops-depot-charger"]
    answer = client_default.post("/v1/plans", json=body).json()
    assert answer["charges"], answer["warnings"]
    assert answer["solver"]["status"] == "feasible"
    assert answer["solver"]["stopped_by"] in ("work", "proof")
    assert answer["solver"]["proven"] in ([], ["order"])


def test_a_fleet_never_claims_a_proof(client_default):
    answer = client_default.post("/v1/fleet-plans", json=examples("/v1/fleet-plans")[0][1]).json()
    assert answer["solver"]["status"] == "feasible"
    assert all(route["solver"]["status"] == "feasible" for route in answer["routes"])
    assert all(route["solver"]["proven"] == [] for route in answer["routes"])


def test_a_search_the_time_limit_stops_says_so(client_default):
    """A large round with work far beyond its limit: stopped by the clock, said in the
    solver's answer and in a warning; with the same work and room, stopped by its work."""
    body = copy.deepcopy(dict(examples("/v1/plans"))["vienna-40-stops-depot-charger"])
    body.pop("depot")
    body["depot"] = {"id": "depot", "lat": 48.21, "lon": 16.37}
    body["battery"] = {"usable_capacity_kwh": 200}
    cut = client_default.post("/v1/plans", json=body | {"time_limit_s": 0.05, "work_s": 20}).json()
    assert cut["solver"]["stopped_by"] == "time_limit"
    assert any("stopped by its time limit" in w for w in cut["warnings"])
    done = client_default.post("/v1/plans", json=body | {"time_limit_s": 20, "work_s": 0.2}).json()
    assert done["solver"]["stopped_by"] in ("work", "proof")
    assert not any("stopped by its time limit" in w for w in done["warnings"])
