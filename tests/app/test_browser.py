"""Swagger UI and ReDoc as a dispatcher meets them: a real headless Chromium (Debian's, driven by
Playwright, no browser download) against the real server, with every request to another host
refused — the docs must work without internet."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from playwright.sync_api import Page, sync_playwright

from testbed.services import Server

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

CHROMIUM = "/usr/bin/chromium"
ARTIFACTS = Path(__file__).resolve().parents[2] / "test-artifacts"
CHROMIUM_FLAGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


@pytest.fixture(scope="module")
def server():
    started = Server({"COLDROUTE_WORKERS": "1"}).start()
    yield started
    started.close()


@contextlib.contextmanager
def offline_tab(url: str, **context: Any) -> Iterator[tuple[Page, list[str], list[str]]]:
    """A Chromium tab on the service at ``url`` whose requests to any other host are refused
    and listed; with the errors its scripts threw."""
    outside: list[str] = []
    errors: list[str] = []
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
        options = {"viewport": {"width": 1400, "height": 1000}} | context
        opened = browser.new_context(**options).new_page()
        opened.on("pageerror", lambda error: errors.append(str(error)))

        def offline(route):
            if route.request.url.startswith(url):
                route.continue_()
            else:
                outside.append(route.request.url)
                route.abort()

        opened.route("**/*", offline)
        yield opened, outside, errors
        browser.close()


@pytest.fixture
def page(server):
    with offline_tab(server.url) as (opened, outside, _):
        yield opened, outside


def test_swagger_ui_works_offline_and_try_it_out_plans_a_round(server, page):
    tab, outside = page
    operations = sum(
        len(methods) for methods in httpx.get(f"{server.url}/openapi.json").json()["paths"].values()
    )
    tab.goto(f"{server.url}/docs")
    tab.wait_for_selector(".opblock", timeout=30_000)
    assert tab.locator(".opblock").count() == operations
    assert tab.locator(".authorize").count() == 1  # the API key's Authorize button

    create_plan = tab.locator("#operations-plans-createPlan")
    create_plan.locator(".opblock-summary").click()
    create_plan.locator("button.try-out__btn").click()
    create_plan.locator("button.execute").click()
    status = create_plan.locator(".live-responses-table tbody .response-col_status").first
    status.wait_for(timeout=60_000)
    assert status.inner_text().strip().startswith("200")
    body = create_plan.locator(".live-responses-table .microlight").first.inner_text()
    assert '"tour"' in body and "depot-simmering" in body
    ARTIFACTS.mkdir(exist_ok=True)
    status.scroll_into_view_if_needed()
    tab.screenshot(path=ARTIFACTS / "swagger-ui-create-plan.png", full_page=False)
    assert outside == [], f"the docs asked other hosts: {outside}"


def test_redoc_works_offline(server, page):
    tab, outside = page
    answer = tab.goto(f"{server.url}/redoc")
    assert "default-src 'self'" in answer.headers["content-security-policy"]
    heading = tab.locator("h2", has_text="Plan and simulate a delivery round")
    heading.wait_for(timeout=30_000)
    assert tab.locator("h2", has_text="Submit a plan or a scenario study").count() == 1
    ARTIFACTS.mkdir(exist_ok=True)
    tab.screenshot(path=ARTIFACTS / "redoc.png")
    assert outside == [], f"ReDoc asked other hosts: {outside}"
