"""Classes of hostile HTTP the audit of issue #21 found examples of: made-up methods, repeated
credentials, odd headers, and bodies built so that refusing them costs more than they weigh."""

from __future__ import annotations

import asyncio
import json
import random
import string

import pytest
from fastapi.testclient import TestClient

from app.errors import MAX_ERRORS
from app.examples import PLAN_EXAMPLE, SIMULATE_TRACE_EXAMPLE
from app.main import create_app
from app.settings import Settings
from core.params import MAX_STOPS, MAX_UNKNOWN_NAMED
from tests.app.apps import app_client
from tests.app.invariants import CheckedClient
from tests.app.test_hostile import metric

PROBLEM = "application/problem+json"


@pytest.fixture(scope="module")
def secured() -> TestClient:
    return CheckedClient(create_app(Settings(api_key="s3cret")), raise_server_exceptions=False)


@pytest.fixture(scope="module")
def roomy() -> TestClient:
    """The default limits (a 10 MB body)."""
    return app_client()


def made_up_methods(n: int, seed: int = 21) -> list[str]:
    rng = random.Random(seed)
    return ["".join(rng.choices(string.ascii_uppercase, k=rng.randint(3, 12))) for _ in range(n)]


# --- methods -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("path", "allowed"),
    [
        ("/v1/plans", "POST"),
        ("/healthz", "GET"),
        ("/v1/jobs", "GET, POST"),
        ("/v1/jobs/some-id", "DELETE, GET"),
        # pages outside the contract: the router's methods (an audit found an empty Allow)
        ("/guide/", "GET, HEAD"),
        ("/guide/integrators/index.html", "GET, HEAD"),
        ("/viewer", "GET"),
    ],
)
def test_a_made_up_method_is_a_405_naming_the_paths_methods_without_a_key(secured, path, allowed):
    for method in [*made_up_methods(5), "QUERY", "X" * 5000]:
        response = secured.request(method, path)
        assert response.status_code == 405, (method, path)
        assert response.headers["content-type"] == PROBLEM
        assert response.headers["allow"] == allowed
        assert len(response.content) < 1000  # a long method is echoed briefly


def test_a_made_up_method_on_a_path_the_service_lacks_is_a_404(secured):
    response = secured.request("BREW", "/coffee")
    assert response.status_code == 404 and response.headers["content-type"] == PROBLEM


def test_made_up_methods_do_not_grow_the_metrics(secured):
    # Issue #21: 25 random methods added 475 lines to /metrics.
    key = {"X-API-Key": "s3cret"}
    secured.request("FIRSTMADEUP", "/v1/plans")
    secured.get("/metrics", headers=key)  # its own series, before counting lines
    before = secured.get("/metrics", headers=key).text.splitlines()
    for method in made_up_methods(25):
        secured.request(method, "/v1/plans")
    after = secured.get("/metrics", headers=key).text.splitlines()
    assert len(after) == len(before)
    assert not any("FIRSTMADEUP" in line for line in after)
    series = 'coldroute_requests_total{method="OTHER",route="/v1/plans",status="405"}'
    assert metric("\n".join(after), series) == metric("\n".join(before), series) + 25


@pytest.mark.parametrize(
    ("path", "allowed"), [("/v1/plans", "POST"), ("/guide/", "GET, HEAD"), ("/viewer", "GET")]
)
def test_a_known_method_on_a_path_without_it_is_a_405_naming_the_allowed(client, path, allowed):
    response = client.request("PATCH", path)
    assert response.status_code == 405 and response.headers["allow"] == allowed


# --- credentials and headers -------------------------------------------------------------------


@pytest.mark.parametrize(
    "keys", [["s3cret", "wrong"], ["wrong", "s3cret"], ["s3cret", "s3cret"], ["s3cret", ""]]
)
def test_a_repeated_api_key_is_a_401_in_any_order(secured, keys):
    response = secured.get("/v1/presets", headers=[("X-API-Key", key) for key in keys])
    assert response.status_code == 401
    assert "X-API-Key" in response.json()["detail"]
    assert secured.get("/v1/presets", headers={"X-API-Key": "s3cret"}).status_code == 200


def test_without_the_key_an_upload_is_a_401_before_its_body_is_read():
    """The audit: /v1/calibrations/csv parsed a whole multipart upload, then answered a bad one
    with a 422, before it looked at the key."""
    app = create_app(Settings(api_key="s3cret"))
    sent: list[dict] = []

    async def receive() -> dict:
        raise AssertionError("the body was read")

    async def send(message: dict) -> None:
        sent.append(message)

    scope = {
        "type": "http",
        "method": "POST",
        "path": "/v1/calibrations/csv",
        "raw_path": b"/v1/calibrations/csv",
        "query_string": b"",
        "headers": [(b"content-type", b"multipart/form-data; boundary=x")],
        "http_version": "1.1",
        "scheme": "http",
        "server": ("test", 80),
        "client": ("test", 1),
        "root_path": "",
    }
    asyncio.run(app(scope, receive, send))
    assert sent[0]["status"] == 401
    assert dict(sent[0]["headers"])[b"www-authenticate"] == b"ApiKey"


def test_an_unreadable_upload_says_it_is_not_multipart(secured):
    response = secured.post(
        "/v1/calibrations/csv",
        content=b"--x\r\nnot a part",
        headers={"X-API-Key": "s3cret", "content-type": "multipart/form-data; boundary=x"},
    )
    assert response.status_code == 422
    assert "multipart/form-data" in response.json()["detail"]
    assert "JSON" not in response.json()["detail"]


@pytest.mark.parametrize("key", ["", " ", "tab\there", "caf\u00e9", "\x7f"])
def test_an_idempotency_key_that_is_empty_or_not_visible_ascii_is_a_422(roomy, key):
    response = roomy.post(
        "/v1/jobs",
        json={"type": "plan", "request": PLAN_EXAMPLE},
        headers=[(b"Idempotency-Key", key.encode())],
    )
    assert response.status_code == 422, response.text[:300]
    assert [e["field"] for e in response.json()["errors"]] == ["header.idempotency-key"]


@pytest.mark.parametrize("path", ["/healthz", "/readyz"])
def test_the_probes_answer_head_like_get_without_a_body(client, path):
    got, head = client.get(path), client.head(path)
    assert head.status_code == got.status_code == 200
    assert head.content == b""
    assert head.headers["content-type"] == got.headers["content-type"]


# --- bodies whose refusal would cost more than they weigh --------------------------------------


def refusal(client: TestClient, body: bytes, path: str = "/v1/plans") -> dict:
    response = client.post(path, content=body, headers={"content-type": "application/json"})
    assert response.status_code == 422, response.text[:300]
    assert response.headers["content-type"] == PROBLEM
    # However large the body, the answer is a few kilobytes.
    assert len(response.content) < 16_000, len(response.content)
    return response.json()


def test_a_5_mb_property_name_is_answered_briefly(roomy):
    problem = refusal(roomy, json.dumps({"x" * 5_000_000: 1} | PLAN_EXAMPLE).encode())
    assert problem["errors"][0]["field"].startswith("x" * 64 + "…")


def test_half_a_million_unknown_properties_name_five(roomy):
    body = PLAN_EXAMPLE | {"vehicle": {f"k{i}": 1 for i in range(500_000)}}
    problem = refusal(roomy, json.dumps(body).encode())
    named = [e["field"] for e in problem["errors"]]
    assert named == [f"vehicle.k{i}" for i in range(MAX_UNKNOWN_NAMED)]


def test_more_stops_than_any_server_takes_is_one_error(roomy):
    problem = refusal(roomy, json.dumps(PLAN_EXAMPLE | {"stops": [{}] * 100_000}).encode())
    assert [e["field"] for e in problem["errors"]] == ["stops"]
    assert str(MAX_STOPS) in problem["errors"][0]["message"]


def test_a_million_strings_in_a_trace_name_the_first(roomy):
    body = SIMULATE_TRACE_EXAMPLE | {"speed_mps": ["fast"] * 1_000_000}
    problem = refusal(roomy, json.dumps(body).encode(), "/v1/simulate")
    assert [e["field"] for e in problem["errors"]] == ["speed_mps[0]"]


def test_thousands_of_bad_stops_list_the_first_fifty_and_count_the_rest(roomy):
    stops = [{"id": f"s{i}", "lat": "north", "lon": "east"} for i in range(2000)]
    problem = refusal(roomy, json.dumps(PLAN_EXAMPLE | {"stops": stops}).encode())
    assert [e["field"] for e in problem["errors"]][:4] == [
        "stops[0].lat",
        "stops[0].lon",
        "stops[1].lat",
        "stops[1].lon",
    ]
    assert len(problem["errors"]) == MAX_ERRORS
    assert problem["errors_omitted"] == 4000 - MAX_ERRORS
    assert "and 3,995 more" in problem["detail"]
