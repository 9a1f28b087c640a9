from __future__ import annotations

from collections.abc import Iterator

import pytest
from fastapi.testclient import TestClient

from tests.app.apps import app_client, stop_all


@pytest.fixture(scope="session", autouse=True)
def _stop_the_apps() -> Iterator[None]:
    yield
    stop_all()


@pytest.fixture
def client() -> TestClient:
    return app_client(
        max_stops=40, max_trace_samples=5000, max_body_bytes=200_000, max_time_limit_s=0.5
    )


@pytest.fixture
def client_default() -> TestClient:
    """A client of the app with the default settings (a request's time limit up to 30 s)."""
    return app_client()
