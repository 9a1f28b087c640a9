from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from app.main import create_app
from app.settings import Settings


@pytest.fixture
def client() -> TestClient:
    return TestClient(
        create_app(
            Settings(
                max_stops=40, max_trace_samples=5000, max_body_bytes=200_000, max_time_limit_s=0.5
            )
        )
    )
