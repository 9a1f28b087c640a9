"""Behaviour kept through a change of the code's shape: every OpenAPI request example of every
endpoint that takes JSON (the searches pinned by the work they record) answers what it answered
when its fingerprint was recorded (``identical_answers.json``), but for the timing fields; and
the charging search finds the routes it found on benchmark instances of Schneider et al. at a
pinned work (:data:`INSTANCES`).

An answer's fingerprint is the SHA-256 of its canonical JSON with the timing fields left out
and every number to :data:`DIGITS` significant digits: the last digit of a float may differ
between machines (numpy picks its vector code by the processor), nothing else may. A change
meant to change answers records them again::

    .venv/bin/python -m tests.app.test_identical

and says why in its commit."""

from __future__ import annotations

import hashlib
import json
import math
import sys
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from app.main import app
from core.routing.effort import Effort
from core.routing.evrp import solve_evrptw
from testbed.evrptw import FOLDER, read
from tests.app.apps import app_client
from tests.utils.answers import without_timing

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

RECORDED = Path(__file__).with_name("identical_answers.json")
#: Significant digits a number is compared to (a least-squares fit's last digits move).
DIGITS = 9
#: The id a stored answer is given (a calibration is kept to be named later).
OWN_ID = "id"
#: Endpoints whose answer is a stored resource of its own (an id, the time it was made): a
#: job's result is the synchronous answer (tests/app/test_reproducible.py), a stored profile
#: the preset or calibration it names (tests/app/test_profiles.py).
STORES = ("/v1/jobs", "/v1/vehicle-profiles")
#: E-VRPTW instances solved at a pinned work [reference s]: one of clustered customers and
#: narrow windows, one of wide windows and long routes.
INSTANCES = {"c101": 2.0, "r201": 2.0}


def cases() -> list[tuple[str, str, dict[str, Any]]]:
    """(path, example name, body) of every JSON request example the OpenAPI document shows."""
    found = []
    for path, operations in app.openapi()["paths"].items():
        if path in STORES:
            continue
        body = operations.get("post", {}).get("requestBody", {})
        examples = body.get("content", {}).get("application/json", {}).get("examples", {})
        found += [(path, name, example["value"]) for name, example in examples.items()]
    return found


def fingerprint(answer: Any) -> str:
    """The answer's SHA-256 without its timing, its numbers to :data:`DIGITS` digits."""
    return hashlib.sha256(without_timing(answer, DIGITS).encode()).hexdigest()


def answer(client: TestClient, path: str, body: dict[str, Any]) -> Any:
    """The answer to ``body`` at ``path``, without the id it was stored under."""
    response = client.post(path, json=body)
    assert response.status_code == 200, response.text[:300]
    found = response.json()
    found.pop(OWN_ID, None)
    return found


CASES = cases()


def test_the_fingerprint_sees_a_change_and_not_the_last_digit_of_a_float():
    base = {"totals": {"distance_m": 1234.5678901234567, "stops": ["a", "b"]}}
    noise = {"totals": {"distance_m": 1234.5678901289, "stops": ["a", "b"]}}
    timed = base | {"runtime_s": 3.0}
    assert fingerprint(base) == fingerprint(noise) == fingerprint(timed)
    assert fingerprint(base) != fingerprint({"totals": {"distance_m": 1234.57, "stops": ["a"]}})
    assert fingerprint(base) != fingerprint(
        {"totals": {"distance_m": 1234.568, "stops": ["a", "b"]}}
    )


@pytest.mark.parametrize(("path", "name", "body"), CASES, ids=[f"{p}:{n}" for p, n, _ in CASES])
def test_every_example_answers_as_recorded(path, name, body):
    recorded = json.loads(RECORDED.read_text())
    assert fingerprint(answer(app_client(), path, body)) == recorded[f"{path} {name}"]


def solved(name: str) -> Any:
    """The instance's routes (places and charges), distance and stops left out."""
    problem = read(FOLDER / f"{name}_21.txt").problem
    solution = solve_evrptw(problem, Effort(INSTANCES[name], math.inf))
    return {
        "routes": [[(v.place, v.charge) for v in route.visits] for route in solution.routes],
        "distance": solution.distance,
        "left_out": solution.left_out,
    }


@pytest.mark.parametrize("name", INSTANCES)
def test_the_charging_search_finds_what_it_found(name):
    assert fingerprint(solved(name)) == json.loads(RECORDED.read_text())[f"evrptw {name}"]


def keys() -> set[str]:
    return {f"{p} {n}" for p, n, _ in CASES} | {f"evrptw {name}" for name in INSTANCES}


def test_every_example_and_instance_is_recorded():
    assert set(json.loads(RECORDED.read_text())) == keys()


def record() -> None:
    """Record the fingerprint of every example's answer and every instance's routes."""
    client = app_client()
    prints = {f"{p} {n}": fingerprint(answer(client, p, body)) for p, n, body in CASES}
    prints |= {f"evrptw {name}": fingerprint(solved(name)) for name in INSTANCES}
    assert set(prints) == keys()
    RECORDED.write_text(json.dumps(prints, indent=1, sort_keys=True) + "\n")
    print(f"recorded {len(prints)} answers in {RECORDED}", file=sys.stderr)


if __name__ == "__main__":
    record()
