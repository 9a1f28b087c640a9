"""End to end: the real server (uvicorn on a free port) answers over HTTP."""

from __future__ import annotations

import httpx
import pytest

from app.examples import PLAN_EXAMPLE
from testbed.services import running_server

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def server_url():
    with running_server({"COLDROUTE_API_KEY": "e2e-key"}) as url:
        yield url


def test_plan_over_http(server_url):
    response = httpx.post(
        f"{server_url}/v1/plans", json=PLAN_EXAMPLE, headers={"X-API-Key": "e2e-key"}, timeout=30
    )
    assert response.status_code == 200
    body = response.json()
    assert body["tour"][0] == "depot-simmering" and body["battery"]["feasible"]


def test_key_is_required_over_http(server_url):
    assert httpx.get(f"{server_url}/v1/presets", timeout=5).status_code == 401


def test_concurrent_requests_are_all_answered(server_url):
    import concurrent.futures

    def call(_: int) -> int:
        return httpx.post(
            f"{server_url}/v1/plans",
            json=PLAN_EXAMPLE,
            headers={"X-API-Key": "e2e-key"},
            timeout=60,
        ).status_code

    with concurrent.futures.ThreadPoolExecutor(8) as pool:
        assert list(pool.map(call, range(16))) == [200] * 16
