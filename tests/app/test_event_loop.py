"""The server's event loop only passes bytes: answers are built and written out in the worker
that made them, and the OpenAPI document (which every request's log line reads) is built at
start-up. Either done on the event loop held ``/healthz`` and every waiting request: 0.1–0.2 s
per 400-stop answer, 1–2.5 s for the first request (issue #50's audit: 0.51–0.55 s)."""

from __future__ import annotations

import asyncio
import json
from typing import Any

import pytest
from pydantic import TypeAdapter

from app.examples import FLEET_PLAN_EXAMPLE, PLAN_EXAMPLE, SIMULATE_EXAMPLE, SPEED_SWEEP_EXAMPLE
from app.main import create_app
from app.openapi_doc import RESPONSE_EXAMPLES
from app.operations.encoded import encoded
from app.schemas.fleet import FleetPlanResponse
from app.schemas.plans import PlanFeatureCollection, PlanResponse
from app.schemas.simulate import SimulateResponse
from app.schemas.studies import SpeedSweepResponse
from app.settings import Settings

ANSWERS = [
    ("/v1/plans", PLAN_EXAMPLE, PlanResponse),
    ("/v1/fleet-plans", FLEET_PLAN_EXAMPLE, FleetPlanResponse),
    ("/v1/simulate", SIMULATE_EXAMPLE, SimulateResponse),
    ("/v1/studies/speed-sweep", SPEED_SWEEP_EXAMPLE, SpeedSweepResponse),
]


@pytest.mark.parametrize(("path", "body", "model"), ANSWERS, ids=[a[0] for a in ANSWERS])
def test_the_server_process_builds_no_answer(client, monkeypatch, path, body, model):
    # The workers are processes of their own: a model built in this one is built on the loop.
    def built_here(*args: Any, **kwargs: Any) -> None:
        raise AssertionError(f"{model.__name__} built in the server's process")

    monkeypatch.setattr(model, "__init__", built_here)
    response = client.post(path, json=body)
    monkeypatch.undo()
    assert response.status_code == 200, response.text
    assert response.headers["content-type"] == "application/json"
    model.model_validate(response.json(), strict=False)  # a whole answer all the same


def test_a_map_is_built_in_the_worker_too(client, monkeypatch):
    def built_here(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("the map built in the server's process")

    monkeypatch.setattr(PlanFeatureCollection, "__init__", built_here)
    response = client.post(
        "/v1/plans", json=PLAN_EXAMPLE, headers={"Accept": "application/geo+json"}
    )
    monkeypatch.undo()
    assert (
        response.status_code == 200 and response.headers["content-type"] == "application/geo+json"
    )
    collection = PlanFeatureCollection.model_validate(response.json(), strict=False)
    assert collection.features[0].properties["kind"] == "depot"


def test_an_answer_is_written_as_fastapi_writes_a_response_model():
    # FastAPI writes a response model with its field's TypeAdapter, by alias: the same bytes.
    recorded = json.loads(RESPONSE_EXAMPLES.read_text())
    for key, model in (("plan", PlanResponse), ("fleet_plan", FleetPlanResponse)):
        answer = model.model_validate(recorded[key], strict=False)
        assert encoded(answer).body == TypeAdapter(model).dump_json(answer, by_alias=True)


@pytest.mark.slow
def test_the_contract_is_read_at_start_up_not_by_the_first_request(tmp_path):
    app = create_app(Settings(database_url=f"sqlite:///{tmp_path}/jobs.db", workers=1))

    async def started() -> bool:
        async with app.router.lifespan_context(app):
            return app.openapi_schema is not None

    assert app.openapi_schema is None
    assert asyncio.run(started())
