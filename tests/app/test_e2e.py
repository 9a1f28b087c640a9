"""End to end: the real server (uvicorn on a free port) answers over HTTP."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time

import httpx
import pytest

from app.examples import PLAN_EXAMPLE


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@pytest.fixture(scope="module")
def server_url():
    port = free_port()
    env = os.environ | {"COLDROUTE_API_KEY": "e2e-key"}
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "uvicorn",
            "app.main:app",
            "--host",
            "127.0.0.1",
            "--port",
            str(port),
        ],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    url = f"http://127.0.0.1:{port}"
    try:
        for _ in range(100):
            try:
                if httpx.get(f"{url}/healthz", timeout=1).status_code == 200:
                    break
            except httpx.TransportError:
                time.sleep(0.1)
        else:
            pytest.fail("server did not start")
        yield url
    finally:
        process.terminate()
        process.wait(timeout=10)


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
