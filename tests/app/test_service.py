import json
from pathlib import Path

from fastapi.testclient import TestClient

from app.main import app, create_app
from app.settings import Settings
from core.params import PRESETS

OPENAPI = Path(__file__).resolve().parents[2] / "openapi" / "openapi.json"


def test_committed_openapi_matches_the_app():
    # `make openapi` regenerates it; a difference means the contract changed unnoticed.
    assert json.loads(OPENAPI.read_text()) == app.openapi()


def test_operation_ids_are_stable():
    ids = {op["operationId"] for path in app.openapi()["paths"].values() for op in path.values()}
    assert ids >= {"createPlan", "simulateTrace", "listPresets", "getHealth"}


def test_every_request_field_is_described():
    schemas = app.openapi()["components"]["schemas"]
    for name in (
        "PlanRequest",
        "SimulateRequest",
        "VehicleRequest",
        "CargoBoxRequest",
        "Stop",
        "Depot",
        "Weather",
    ):
        for field, spec in schemas[name]["properties"].items():
            assert (
                spec.get("description")
                or "$ref" in spec
                or "allOf" in spec
                or ("anyOf" in spec and any("$ref" in s for s in spec["anyOf"]))
            ), (name, field)


def test_presets_and_health(client):
    presets = client.get("/v1/presets").json()["presets"]
    assert {p["name"] for p in presets} == set(PRESETS)
    generic = next(p for p in presets if p["name"] == "paper-generic")
    assert generic["vehicle"]["mass_kg"] == 1680 and generic["payload_kg"] == 550
    assert client.get("/healthz").json()["status"] == "ok"


def test_api_key_when_configured():
    secured = TestClient(create_app(Settings(api_key="s3cret")))
    assert secured.get("/v1/presets").status_code == 401
    assert secured.get("/v1/presets", headers={"X-API-Key": "nope"}).status_code == 401
    assert secured.get("/v1/presets", headers={"X-API-Key": "s3cret"}).status_code == 200
    assert secured.get("/healthz").status_code == 200


def test_unknown_path_is_a_problem(client):
    response = client.get("/v2/nothing")
    assert response.status_code == 404
    assert response.headers["content-type"] == "application/problem+json"


def test_cors_when_configured():
    with_cors = TestClient(create_app(Settings(cors_origins=["https://dispatch.example"])))
    response = with_cors.options(
        "/v1/presets",
        headers={"Origin": "https://dispatch.example", "Access-Control-Request-Method": "GET"},
    )
    assert response.headers["access-control-allow-origin"] == "https://dispatch.example"
