"""The guide as its readers meet it: served by the service at /guide, offline — a real headless
Chromium opens its pages, follows a link, finds the equations typeset and the API reference
linked, and asks no other host; and the dispatchers' first day, done in the viewer as the guide
says, answers what the guide says."""

from __future__ import annotations

import datetime as dt
import re
from collections.abc import Iterator

import pytest
from playwright.sync_api import expect

from testbed.services import Server
from tests.app.test_browser import offline_tab
from tests.docs.examples import ROOT, blocks

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

VIEWER_GUIDE = ROOT / "docs" / "dispatchers" / "viewer.md"


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    started = Server({"COLDROUTE_WORKERS": "1", "COLDROUTE_TILE_URL": ""}).start()
    yield started
    started.close()


def test_the_guide_opens_offline_follows_a_link_and_typesets_its_equations(server):
    with offline_tab(server.url) as (tab, outside, errors):
        answer = tab.goto(f"{server.url}/guide")
        assert answer is not None and answer.url == f"{server.url}/guide/"
        assert "default-src 'none'" in answer.headers["content-security-policy"]
        expect(tab.locator("h1")).to_contain_text("coldroute")
        # a dispatcher follows the home page's link to the viewer's guide
        tab.locator("article a", has_text="the plan viewer").first.click()
        tab.wait_for_url(f"{server.url}/guide/dispatchers/viewer/")
        expect(tab.locator("h1")).to_contain_text("The plan viewer")
        # a fleet engineer reads the equations, typeset by the vendored KaTeX
        tab.goto(f"{server.url}/guide/engineers/model/")
        expect(tab.locator("h1")).to_contain_text("The model")
        expect(tab.locator(".katex-display").first).to_be_visible()
        assert tab.locator(".katex-display").count() >= 10
        assert "\\frac" not in tab.locator("article").inner_text()  # nothing left as source
        # an integrator finds an operation and follows it to its schema
        tab.goto(f"{server.url}/guide/reference/")
        expect(tab.locator("h3#post-v1plans")).to_have_count(1)
        tab.locator("article a[href='#schema-planrequest']").first.click()
        expect(tab.locator("#schema-planrequest")).to_be_in_viewport()
        assert outside == [], f"the guide asked other hosts: {outside}"
        assert errors == [], f"the guide's scripts threw: {errors}"


def _said(pattern: str) -> re.Match[str]:
    found = re.search(pattern, VIEWER_GUIDE.read_text(encoding="utf-8"))
    assert found, pattern
    return found


def test_the_dispatchers_first_day_answers_what_the_guide_says(server, tmp_path):
    stops = next(b for b in blocks(VIEWER_GUIDE) if b.title == "stops.csv")
    (tmp_path / "stops.csv").write_text(stops.text, encoding="utf-8")
    depot = _said(r"\*\*Depot lat, lon\*\*: `([^`]+)`").group(1)
    date = dt.datetime.strptime(_said(r"\*\*Date\*\*: (\d+ \w+ \d{4})").group(1), "%d %B %Y")
    low, high = _said(r"\*\*Low / high\*\*: (-?\d+) and (-?\d+) °C").groups()
    vans = _said(r"\*\*How many\*\*: (\d+)").group(1)
    payload = _said(r"\*\*Payload\*\*: (\d+) kg").group(1)
    product = _said(r"\*\*Product\*\*: ([a-z ]+) \(").group(1).replace(" ", "-")
    shown = _said(
        r"\*\*(\d+) vans, (\d+) of (\d+) stops served, ([\d.]+) km, ([\d.]+) kWh, "
        r"cold chain (holds|breaks)\*\*"
    ).groups()
    with offline_tab(server.url) as (tab, outside, errors):
        tab.goto(f"{server.url}/viewer")
        kind = "#van-kind option[value='preset:ev-van-3.5t-reefer']"
        expect(tab.locator(kind)).to_have_count(1)
        tab.get_by_test_id("stops-csv").set_input_files(str(tmp_path / "stops.csv"))
        tab.fill("#depot", depot)
        tab.fill("#date", date.date().isoformat())
        tab.fill("#t-min", low)
        tab.fill("#t-max", high)
        tab.select_option("#product", product)
        tab.select_option("#van-kind", "preset:ev-van-3.5t-reefer")
        tab.get_by_test_id("van-count").fill(vans)
        tab.fill(".payload-kg", payload)
        tab.get_by_test_id("plan").click()
        expect(tab.get_by_test_id("route-line").first).to_be_visible(timeout=120_000)
        answer = tab.evaluate("window.coldroute.answer()")
        assert outside == [] and errors == []
    served = sum(len(route["stops"]) for route in answer["routes"])
    chains = {route["cold_chain"]["verdict"] for route in answer["routes"]}
    assert (
        str(answer["totals"]["vehicles_used"]),
        str(served),
        str(served + len(answer["unassigned"])),
        f"{answer['totals']['distance_m'] / 1000:.1f}",
        f"{answer['totals']['energy_kwh']['total']:.1f}",
        "breaks" if "breaks" in chains else "holds",
    ) == shown
