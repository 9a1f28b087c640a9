"""Test clients of the app, one per set of settings for the whole session: each app has a
worker pool of its own, and starting one costs seconds."""

from __future__ import annotations

from typing import Any

from fastapi.testclient import TestClient

from app.main import create_app
from app.settings import Settings
from tests.app.invariants import CheckedClient

_CLIENTS: dict[str, TestClient] = {}


def app_client(**settings: Any) -> TestClient:
    """The session's client of an app with these settings (created on first use)."""
    key = repr(sorted(settings.items()))
    if key not in _CLIENTS:
        client = CheckedClient(create_app(Settings(**settings)))
        executor = client.app.state.executor  # type: ignore[attr-defined]
        executor.pool.warm(executor.load)
        _CLIENTS[key] = client
    return _CLIENTS[key]


def stop_all() -> None:
    """Stop every app's worker pool."""
    while _CLIENTS:
        _, client = _CLIENTS.popitem()
        client.app.state.executor.stop()  # type: ignore[attr-defined]
