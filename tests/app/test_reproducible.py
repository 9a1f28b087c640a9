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
from core.planning.model import default_work_s
from testbed.services import Server, busy_core
from tests.app.apps import app_client
from tests.app.test_jobs import submit, wait_for
from tests.utils.answers import without_timing

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "integrators" / "rounds.md"


def examples(path: str) -> list[tuple[str, dict[str, Any]]]:
    operation = app.openapi()["paths"][path]["post"]
    found = operation["requestBody"]["content"]["application/json"]["examples"]
    return [(name, example["value"]) for name, example in found.items()]


CASES = [
    (path, name, body) for path in ("/v1/plans", "/v1/fleet-plans") for name, body in examples(path)
]


@contextlib.contextmanager
def both_cores_busy() -> Iterator[None]:
    """Another solve of the service (a process at its workers' priority) beside this one:
    both cores busy."""
    with busy_core(WORKER_NICENESS):
        yield


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
    body = copy.deepcopy(
        without_replay(dict(examples("/v1/plans"))["vienna-40-stops-depot-charger"])
    )
    body.pop("depot")
    body["depot"] = {"id": "depot", "lat": 48.21, "lon": 16.37}
    body["battery"] = {"usable_capacity_kwh": 200}
    cut = client_default.post("/v1/plans", json=body | {"time_limit_s": 0.05, "work_s": 20}).json()
    assert cut["solver"]["stopped_by"] == "time_limit"
    assert any("stopped by its time limit" in w for w in cut["warnings"])
    done = client_default.post("/v1/plans", json=body | {"time_limit_s": 20, "work_s": 0.2}).json()
    assert done["solver"]["stopped_by"] in ("work", "proof")
    assert not any("stopped by its time limit" in w for w in done["warnings"])


def without_replay(body: dict[str, Any]) -> dict[str, Any]:
    """An example's request as a client first sends it: without the work it is pinned to."""
    return {k: v for k, v in body.items() if k != "replay"}


CUT = [
    ("/v1/plans", "vienna-40-stops-depot-charger", {"time_limit_s": 0.3, "work_s": 20}),
    ("/v1/fleet-plans", "vienna-two-vans", {"time_limit_s": 0.4, "work_s": 30}),
]


@pytest.mark.parametrize(("path", "name", "limits"), CUT, ids=[n for _, n, _ in CUT])
def test_an_answer_the_time_limit_cut_is_replayed_to_the_byte_sync_and_as_a_job(
    server, path, name, limits
):
    body = without_replay(dict(examples(path))[name]) | limits
    response = httpx.post(f"{server.url}{path}", json=body, timeout=120)
    first = response.json()
    assert first["solver"]["stopped_by"] == "time_limit", first["solver"]
    replay = first["solver"]["replay"]
    assert replay["stops"] and replay["work_s"] == limits["work_s"]
    # on a busier machine, and with a limit that would cut it at once: the same work again
    with both_cores_busy():
        again = httpx.post(
            f"{server.url}{path}", json=body | {"replay": replay, "time_limit_s": 0.01}, timeout=120
        ).json()
    assert without_timing(again) == without_timing(first)
    kind = "plan" if path == "/v1/plans" else "fleet-plan"
    job = wait_for(
        server.url,
        submit(server.url, {"type": kind, "request": body | {"replay": replay}}).json()["id"],
        timeout=120,
    )
    assert job["status"] == "succeeded", job
    assert without_timing(job["result"]) == without_timing(first)


def test_a_default_request_answers_the_same_or_replays_to_the_same(client_default):
    """Without a time limit or work: the default for its size; done on its work, the same
    answer every time; cut (a busy machine), its replay gives it again."""
    body = without_replay(dict(examples("/v1/fleet-plans"))["vienna-two-vans"])
    body.pop("time_limit_s")
    body.pop("work_s")
    first, second = (client_default.post("/v1/fleet-plans", json=body).json() for _ in range(2))
    assert first["solver"]["replay"]["work_s"] == default_work_s(1.0)  # 8 stops: 1 s
    for answer in (first, second):
        if answer["solver"]["stopped_by"] == "time_limit":
            replayed = client_default.post(
                "/v1/fleet-plans", json=body | {"replay": answer["solver"]["replay"]}
            ).json()
            assert without_timing(replayed) == without_timing(answer)
    if "time_limit" not in (first["solver"]["stopped_by"], second["solver"]["stopped_by"]):
        assert without_timing(first) == without_timing(second)
        assert first["solver"]["replay"]["stops"] == []


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"seed": 5}, "replay.request"),  # another request (its seed is part of it)
        ({"time_limit_s": 7.0}, "replay.request"),  # its work from another limit
        ({"payload_kg": 500}, "replay.request"),
    ],
)
def test_a_replay_of_another_request_is_refused_naming_it(client_default, change, field):
    body = without_replay(dict(examples("/v1/plans"))["vienna-8-stops"]) | {"time_limit_s": 2.0}
    replay = client_default.post("/v1/plans", json=body).json()["solver"]["replay"]
    assert client_default.post("/v1/plans", json=body | {"replay": replay}).status_code == 200
    refused = client_default.post("/v1/plans", json=body | change | {"replay": replay})
    assert refused.status_code == 422, refused.text
    assert [e["field"] for e in refused.json()["errors"]] == [field], refused.json()
    forged = replay | {"seed": 3}
    refused = client_default.post("/v1/plans", json=body | {"replay": forged})
    assert refused.status_code == 422
    assert [e["field"] for e in refused.json()["errors"]] == ["replay.seed"]


def test_a_replay_of_work_no_answer_did_is_refused_at_the_servers_replay_limit():
    """A replay is not stopped by the clock: one whose work is beyond the server's cap and whose
    stops are emptied would search unbounded; the server refuses it after 3 times its cap and
    10 s (here 10.03 s), naming replay — while the answer's own replay is answered. (A round's
    search may end on a proof first; its engines' refusals are tested in the core.)"""
    client = app_client(max_time_limit_s=0.01)
    path = "/v1/fleet-plans"
    body = without_replay(dict(examples(path))["vienna-two-vans"]) | {"work_s": 600}
    first = client.post(path, json=body).json()
    replay = first["solver"]["replay"]
    assert replay["work_s"] == 600 and replay["stops"]  # cut at once by the 0.01 s cap
    again = client.post(path, json=body | {"replay": replay})
    assert again.status_code == 200 and without_timing(again.json()) == without_timing(first)
    unbounded = client.post(path, json=body | {"replay": replay | {"stops": []}})
    assert unbounded.status_code == 413, unbounded.text
    assert [e["field"] for e in unbounded.json()["errors"]] == ["replay"]
    assert "10.03 s this server gives a replay" in unbounded.json()["detail"]
