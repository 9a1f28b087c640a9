"""The OpenAPI document says what the server does: which statuses each operation can return
(problems as ``application/problem+json``), the API key as a security scheme (optional, as the
server may not set one), the GeoJSON answer's schema and realistic answer examples."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pydantic import BaseModel
from pydantic.json_schema import models_json_schema

PROBLEM_JSON = "application/problem+json"
#: Recorded answers of the request examples (``python -m app.examples``), shown in Swagger.
RESPONSE_EXAMPLES = Path(__file__).with_name("response_examples.json")

STATUS_TEXT = {
    401: "Missing or wrong X-API-Key (when the server sets a key).",
    404: "No such job (or it expired).",
    409: "The job has already ended, or the Idempotency-Key names another request.",
    413: "Request body larger than the server accepts.",
    422: "Invalid request: every offending field named by its JSON path.",
    503: "The service cannot take this now (workers busy, shutting down, or an outside "
    "service down); see Retry-After.",
}
#: What a status means for the vehicle profiles' operations, where the jobs' text is wrong.
PROFILE_STATUS_TEXT = {
    404: "No vehicle profile of that name.",
    409: "A vehicle profile of that name exists (POST; PUT replaces it), or other requests "
    "kept creating and deleting it while a PUT wrote it (try again).",
}
#: The error statuses each operation can answer.
ERRORS: dict[str, tuple[int, ...]] = {
    "createPlan": (401, 413, 422, 503),
    "createFleetPlan": (401, 413, 422, 503),
    "simulateTrace": (401, 413, 422, 503),
    "sweepSpeeds": (401, 413, 422, 503),
    "runScenarios": (401, 413, 422, 503),
    "studyElectrification": (401, 413, 422, 503),
    "electrificationStudyFromCsv": (401, 413, 422),
    "createCalibration": (401, 413, 422, 503),
    "createCalibrationFromCsv": (401, 413, 422, 503),
    "listPresets": (401,),
    "createVehicleProfile": (401, 409, 413, 422, 503),
    "listVehicleProfiles": (401, 503),
    "getVehicleProfile": (401, 404, 422, 503),
    "replaceVehicleProfile": (401, 409, 413, 422, 503),
    "deleteVehicleProfile": (401, 404, 422, 503),
    "createJob": (401, 409, 413, 422, 503),
    "listJobs": (401, 422, 503),
    "getJob": (401, 404, 422, 503),
    "cancelJob": (401, 404, 409, 422, 503),
}
#: Which recorded example answers which operation.
EXAMPLES = {
    "createPlan": "plan",
    "createFleetPlan": "fleet_plan",
    "simulateTrace": "simulate",
    "sweepSpeeds": "speed_sweep",
    "runScenarios": "scenarios",
    "studyElectrification": "electrification",
    "getJob": "job",
    "createCalibration": "calibration",
}


def request_examples(examples: dict[str, tuple[str, dict[str, Any]]]) -> dict[str, Any]:
    """Swagger's request examples: each with its summary and, as its description, the figures
    of its answer as ``make openapi`` recorded them (``app.examples.describe``); a search's
    example pinned to the work it did then (its ``replay``), so that its figures are these on
    any machine."""
    recorded = json.loads(RESPONSE_EXAMPLES.read_text()) if RESPONSE_EXAMPLES.exists() else {}
    described = recorded.get("descriptions", {})
    replays = recorded.get("replays", {})
    return {
        name: {
            "summary": summary,
            "value": body | ({"replay": replays[name]} if name in replays else {}),
        }
        | ({"description": f"Answers: {described[name]}"} if name in described else {})
        for name, (summary, body) in examples.items()
    }


def finish(schema: dict[str, Any], extra_models: list[type[BaseModel]]) -> dict[str, Any]:
    """Complete FastAPI's document (in place) and return it."""
    components = schema.setdefault("components", {})
    schemas = components.setdefault("schemas", {})
    _, definitions = models_json_schema(
        [(model, "serialization") for model in extra_models],
        ref_template="#/components/schemas/{model}",
    )
    schemas.update(definitions.get("$defs", {}))
    for name in ("HTTPValidationError", "ValidationError"):
        schemas.pop(name, None)
    components["securitySchemes"] = {
        "ApiKey": {
            "type": "apiKey",
            "in": "header",
            "name": "X-API-Key",
            "description": "Needed when the server sets COLDROUTE_API_KEY; otherwise leave it out.",
        }
    }
    examples = json.loads(RESPONSE_EXAMPLES.read_text()) if RESPONSE_EXAMPLES.exists() else {}
    for path, operations in schema.get("paths", {}).items():
        for operation in operations.values():
            operation_id = operation.get("operationId", "")
            responses = operation.setdefault("responses", {})
            for status in [s for s in responses if s.startswith(("4", "5"))]:
                if not (operation_id == "getReadiness" and status == "503"):
                    del responses[status]
            own = PROFILE_STATUS_TEXT if path.startswith("/v1/vehicle-profiles") else {}
            for status in ERRORS.get(operation_id, ()):
                responses[str(status)] = {
                    "description": own.get(status, STATUS_TEXT[status]),
                    "content": {PROBLEM_JSON: {"schema": {"$ref": "#/components/schemas/Problem"}}},
                }
            if path.startswith("/v1/"):
                # Either the key or nothing: the server decides whether it wants one.
                operation["security"] = [{"ApiKey": []}, {}]
            recorded = examples.get(EXAMPLES.get(operation_id, ""))
            content = responses.get("200", {}).get("content", {}).get("application/json")
            if recorded is not None and content is not None:
                content["example"] = recorded
    return schema
