"""Shared test fixtures: the reference data beside the repository, a real OSRM router on the
Monaco extract and the local weather-API stand-in."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import settings

from core.routing.tsp import prepare as prepare_search
from tests.weather_stub import StubServer
from tools import osrm

# The tests' jobs go to a database of their own, never to a coldroute.db in the checkout.
os.environ.setdefault(
    "COLDROUTE_DATABASE_URL", f"sqlite:///{tempfile.mkdtemp(prefix='coldroute-tests-')}/jobs.db"
)

# CI replays the same examples every run (a red CI must be reproducible); developers' runs
# keep exploring new ones.
settings.register_profile("ci", derandomize=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "reference"


@pytest.fixture(scope="session", autouse=True)
def compiled_search() -> None:
    """The round trip's compiled search loaded before any test times a solve, as the
    server's workers load it at start."""
    prepare_search()


@pytest.fixture(scope="session")
def reference_dir() -> Path:
    if not SHARED.is_dir():
        pytest.fail(f"reference data not found at {SHARED}: clone with ../shared beside the repo")
    return SHARED


@pytest.fixture(scope="session")
def monaco_osrm(reference_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The Monaco extract prepared for OSRM's car profile (about 1 s)."""
    return osrm.prepare(reference_dir / "osm" / "monaco.osm.pbf", tmp_path_factory.mktemp("osrm"))


@pytest.fixture(scope="session")
def osrm_url(monaco_osrm: Path) -> Iterator[str]:
    """A real osrm-routed on the Monaco extract for the whole session."""
    with osrm.running(monaco_osrm) as url:
        yield url


@pytest.fixture(scope="session")
def weather_stub() -> Iterator[StubServer]:
    server = StubServer()
    yield server
    server.shutdown()


#: Fixtures that start a server or an outside service: a test that uses one is in the slow tier.
SERVER_FIXTURES = frozenset({"server", "server_url", "services", "broker", "osrm_url", "page"})


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Refuse a test that starts a server but is not marked ``slow``: ``make test`` (the fast
    tier) leaves those to ``make check``, and one left out of the mark would slow it again."""
    unmarked = [
        item.nodeid
        for item in items
        if SERVER_FIXTURES.intersection(getattr(item, "fixturenames", ()))
        and item.get_closest_marker("slow") is None
    ]
    if unmarked:
        raise pytest.UsageError(
            "these tests start a server but are not marked slow (pytest.mark.slow): "
            + ", ".join(unmarked)
        )
