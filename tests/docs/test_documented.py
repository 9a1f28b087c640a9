"""The guide names what the service has — every setting (with its default), every endpoint
and every problem type — and nothing it does not have: a renamed or removed one would leave
readers a knob, a path or an error that is not there."""

from __future__ import annotations

import re

import pytest

from app.errors import PROBLEMS
from app.main import app
from app.settings import Settings
from tests.app.apps import app_client
from tests.docs.examples import ROOT

SETTINGS = (ROOT / "docs" / "operators" / "settings.md").read_text(encoding="utf-8")
ENDPOINTS = (ROOT / "docs" / "integrators" / "index.md").read_text(encoding="utf-8")
ERRORS = (ROOT / "docs" / "integrators" / "contract.md").read_text(encoding="utf-8")
#: The pages the service serves beside its API (not in the OpenAPI document).
PAGES = {("GET", p) for p in ("/docs", "/redoc", "/openapi.json", "/metrics", "/viewer", "/guide")}


def _guides() -> str:
    return "\n".join(p.read_text(encoding="utf-8") for p in (ROOT / "docs").rglob("*.md"))


def test_every_setting_is_in_the_settings_table_and_every_one_named_exists():
    settings = {f"COLDROUTE_{name.upper()}" for name in Settings.model_fields}
    table = set(re.findall(r"^\| `(COLDROUTE_[A-Z0-9_]+)`", SETTINGS, flags=re.MULTILINE))
    named = set(re.findall(r"COLDROUTE_[A-Z0-9_]+", _guides()))
    named |= set(re.findall(r"COLDROUTE_[A-Z0-9_]+", (ROOT / "README.md").read_text()))
    assert sorted(settings - table) == []
    assert sorted(named - settings) == []


def test_the_settings_tables_defaults_are_the_codes():
    """Each plain default in the table (a number or a text in backticks) is the setting's."""
    rows = dict(
        re.findall(r"^\| `(COLDROUTE_[A-Z0-9_]+)` \| `([^`|]*)` \|", SETTINGS, re.MULTILINE)
    )
    compared = 0
    for name, field in Settings.model_fields.items():
        said = rows.get(f"COLDROUTE_{name.upper()}")
        default = field.default
        if said is None or isinstance(default, bool) or default is None:
            continue
        if isinstance(default, int | float):
            assert float(said) == float(default), name
            compared += 1
        elif isinstance(default, str):
            assert said == default, name
            compared += 1
    assert compared >= 20  # the table's plain defaults were read


@pytest.mark.slow
def test_every_endpoint_is_in_the_endpoint_table_and_every_one_listed_exists():
    listed = set(re.findall(r"^\| (GET|POST|PUT|DELETE) \| `([^`]+)` \|", ENDPOINTS, re.M))
    operations = {
        (method.upper(), path)
        for path, methods in app.openapi()["paths"].items()
        for method in methods
    }
    assert sorted(operations - listed) == []
    assert sorted(listed - operations - PAGES) == []
    client = app_client()
    for method, path in PAGES:  # the pages outside the OpenAPI document are served
        answer = client.request(method, path, follow_redirects=True)
        assert answer.status_code == 200, path


def test_every_problem_type_is_in_the_errors_table_with_its_status():
    rows = re.findall(r"^\| `/problems/([a-z-]+)` \| ([A-Za-z ]+) \| (\d{3}) \|", ERRORS, re.M)
    documented = {title: (slug, int(status)) for slug, title, status in rows}
    assert documented == {
        title: (title.lower().replace(" ", "-"), status) for title, (status, _) in PROBLEMS.items()
    }
