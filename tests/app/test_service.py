import json
from pathlib import Path

from app.examples import PLAN_EXAMPLE, SIMULATE_EXAMPLE
from app.jobs.schemas import JobOut
from app.main import app, create_app
from app.openapi_doc import RESPONSE_EXAMPLES
from app.schemas.plans import PlanResponse
from app.schemas.simulate import SimulateResponse
from app.schemas.studies import ScenariosResponse, SpeedSweepResponse
from app.settings import Settings
from core.params import PRESETS
from tests.app.invariants import CheckedClient

OPENAPI = Path(__file__).resolve().parents[2] / "openapi" / "openapi.json"


def test_committed_openapi_matches_the_app():
    # `make openapi` regenerates it; a difference means the contract changed unnoticed.
    assert json.loads(OPENAPI.read_text()) == app.openapi()


def test_operation_ids_are_stable():
    ids = {op["operationId"] for path in app.openapi()["paths"].values() for op in path.values()}
    assert ids >= {"createPlan", "simulateTrace", "listPresets", "getHealth"}


def test_every_property_of_every_schema_is_described():
    # Requests and answers alike: a property is described itself, or is a reference to (or a
    # nullable reference to) a schema that is.
    schemas = app.openapi()["components"]["schemas"]

    def described(spec: dict) -> bool:
        if spec.get("description"):
            return True
        refs = [spec, *spec.get("anyOf", []), *spec.get("allOf", []), *spec.get("oneOf", [])]
        targets = [r["$ref"].rsplit("/", 1)[-1] for r in refs if "$ref" in r]
        return bool(targets) and all(schemas[t].get("description") for t in targets)

    missing = [
        f"{name}.{field}"
        for name, schema in schemas.items()
        for field, spec in schema.get("properties", {}).items()
        if not described(spec)
    ]
    assert missing == []


def test_every_operation_documents_only_problem_json_errors():
    for path, operations in app.openapi()["paths"].items():
        for method, operation in operations.items():
            for status, response in operation["responses"].items():
                # /readyz's 503 is its own report (which dependency is down), not a problem.
                if int(status) >= 400 and (path, status) != ("/readyz", "503"):
                    assert list(response["content"]) == ["application/problem+json"], (
                        path,
                        method,
                        status,
                    )
            if method == "get":  # no body: no 413 and no 422 for one
                assert "413" not in operation["responses"], path


def test_presets_and_health(client):
    presets = client.get("/v1/presets").json()["presets"]
    assert {p["name"] for p in presets} == set(PRESETS)
    generic = next(p for p in presets if p["name"] == "paper-generic")
    assert generic["vehicle"]["mass_kg"] == 1680 and generic["payload_kg"] == 550
    assert client.get("/healthz").json()["status"] == "ok"


def test_api_key_when_configured():
    secured = CheckedClient(create_app(Settings(api_key="s3cret")))
    assert secured.get("/v1/presets").status_code == 401
    assert secured.get("/v1/presets", headers={"X-API-Key": "nope"}).status_code == 401
    assert secured.get("/v1/presets", headers={"X-API-Key": "s3cret"}).status_code == 200
    assert secured.get("/healthz").status_code == 200


def test_unknown_path_is_a_problem(client):
    response = client.get("/v2/nothing")
    assert response.status_code == 404
    assert response.headers["content-type"] == "application/problem+json"


def test_cors_when_configured():
    with_cors = CheckedClient(create_app(Settings(cors_origins=["https://dispatch.example"])))
    response = with_cors.options(
        "/v1/presets",
        headers={"Origin": "https://dispatch.example", "Access-Control-Request-Method": "GET"},
    )
    assert response.headers["access-control-allow-origin"] == "https://dispatch.example"


def test_answer_examples_are_real_answers_of_the_request_examples(client, client_default):
    # `make openapi` records them by running the request examples; they must still be what
    # the server answers (and valid answers by their own schemas).
    recorded = json.loads(RESPONSE_EXAMPLES.read_text())
    for key, model in (
        ("plan", PlanResponse),
        ("simulate", SimulateResponse),
        ("speed_sweep", SpeedSweepResponse),
        ("scenarios", ScenariosResponse),
        ("job", JobOut),
    ):
        model.model_validate(recorded[key], strict=False)
    # With the work it did then, as the Swagger example sends it (and its time limit, which
    # the test client would cap): a busy machine's clock does not cut it short.
    replay = {"replay": recorded["replays"]["vienna-8-stops"]}
    plan = client_default.post("/v1/plans", json=PLAN_EXAMPLE | replay).json()
    assert plan["tour"] == recorded["plan"]["tour"]
    assert plan["totals"] == recorded["plan"]["totals"]
    simulated = client.post("/v1/simulate", json=SIMULATE_EXAMPLE).json()
    assert simulated["energy_kwh"] == recorded["simulate"]["energy_kwh"]
    shown = app.openapi()["paths"]["/v1/plans"]["post"]["responses"]["200"]["content"]
    assert shown["application/json"]["example"] == recorded["plan"]
