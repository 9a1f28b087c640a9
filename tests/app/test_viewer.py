"""The plan viewer as a dispatcher meets it: Debian's Chromium driven by Playwright against the
real server, every request to another host refused and counted. A Vienna day of 24 stops from
a CSV for three vans, one stop no van can take; the same day as a job reopened by its URL; a
bad CSV row named by row and column; the exports. Screenshots of each state go to
test-artifacts/viewer/."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import pytest
from playwright.sync_api import Page, expect
from pydantic import ValidationError

from app.main import create_app
from app.settings import Settings
from benchmarks.common import Server
from tests.app.invariants import CheckedClient
from tests.app.test_browser import offline_tab
from tests.app.test_roads import monaco_plan

ARTIFACTS = Path(__file__).resolve().parents[2] / "test-artifacts" / "viewer"
#: The server wants an API key: the page sends what its field holds.
KEY = "dispatch-key"
HEADER = "id,lat,lon,service_min,door_min,kg,window_start,window_end"
#: A stop of 900 kg: heavier than any van's payload, so no van takes it.
TOO_HEAVY = "pallet-of-ice"
#: A stop id a spreadsheet would run: the CSV export keeps it text.
FORMULA = '=HYPERLINK("http://x")'


def vienna_round(count: int = 24) -> list[dict[str, object]]:
    """Shops on a spiral within about 8 km of the centre; some with morning windows."""
    stops = []
    for k in range(count):
        radius_m = 8000 * math.sqrt((k + 4) / (count + 4))
        angle = k * 2.399963
        stops.append(
            {
                # one a spreadsheet would run as a formula, exported as text
                "id": FORMULA if k == 2 else f"shop-{k + 1:02d}",
                "lat": round(48.208 + radius_m * math.sin(angle) / 111_000, 5),
                "lon": round(16.372 + radius_m * math.cos(angle) / 74_000, 5),
                "service_min": 6,
                "door_min": 2,
                "kg": 35,
                "window_start": "07:00" if k % 5 == 0 else "",
                "window_end": "11:00" if k % 5 == 0 else "",
            }
        )
    stops.append(
        {
            "id": TOO_HEAVY, "lat": 48.2, "lon": 16.39, "service_min": 10, "door_min": 5,
            "kg": 900, "window_start": "", "window_end": "",
        }
    )  # fmt: skip
    return stops


def as_csv(stops: list[dict[str, object]], delimiter: str = ",") -> str:
    out = io.StringIO()
    writer = csv.writer(out, delimiter=delimiter, lineterminator="\r\n")
    writer.writerow(HEADER.split(","))
    for stop in stops:
        row = [stop[c] for c in HEADER.split(",")]
        if delimiter == ";":
            row = [str(v).replace(".", ",") if isinstance(v, float) else v for v in row]
        writer.writerow(row)
    return out.getvalue()


@pytest.fixture(scope="module")
def server():
    started = Server(
        {"COLDROUTE_WORKERS": "1", "COLDROUTE_TILE_URL": "", "COLDROUTE_API_KEY": KEY}
    ).start()
    yield started
    started.close()


@pytest.fixture
def page(server):
    options = {"viewport": {"width": 1500, "height": 1100}, "accept_downloads": True}
    with offline_tab(server.url, **options) as (opened, outside, errors):
        yield opened, outside
        assert errors == [], f"the page threw: {errors}"


def shot(tab: Page, name: str) -> None:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    tab.screenshot(path=ARTIFACTS / f"{name}.png", full_page=True)


def fill_day(tab: Page, csv_text: str, vans: int, tmp_path: Path, name: str = "stops.csv") -> None:
    path = tmp_path / name
    path.write_text(csv_text, encoding="utf-8")
    tab.get_by_test_id("api-key").fill(KEY)
    tab.get_by_test_id("api-key").dispatch_event("change")  # the vans are listed with the key
    expect(tab.locator("#van-kind option[value='preset:ev-van-3.5t-reefer']")).to_have_count(1)
    tab.get_by_test_id("stops-csv").set_input_files(str(path))
    tab.fill("#date", "2026-07-15")
    tab.fill("#depot", "48.1703, 16.4207")
    tab.select_option("#van-kind", "preset:ev-van-3.5t-reefer")
    tab.get_by_test_id("van-count").fill(str(vans))
    tab.fill("#time-limit", "2")


def overlapping(markers) -> list[tuple[int, int]]:
    """The pairs of ``markers`` whose boxes on screen overlap by more than a pixel."""
    boxes = [markers.nth(k).bounding_box() for k in range(markers.count())]
    return [
        (i, j)
        for i, a in enumerate(boxes)
        for j, b in enumerate(boxes[:i])
        if min(a["x"] + a["width"], b["x"] + b["width"]) - max(a["x"], b["x"]) > 1
        and min(a["y"] + a["height"], b["y"] + b["height"]) - max(a["y"], b["y"]) > 1
    ]


def shown_stops(tab: Page) -> int:
    """The stops on the map: each marker drawn alone, and each cluster's count."""
    clustered = tab.locator(".marker-cluster span").all_text_contents()
    return tab.get_by_test_id("stop-marker").count() + sum(int(n) for n in clustered)


def test_a_csv_day_for_three_vans_on_the_map_and_in_the_charts(server, page, tmp_path):
    tab, outside = page
    tab.goto(f"{server.url}/viewer")
    stops = vienna_round()
    fill_day(tab, as_csv(stops, ";"), 3, tmp_path)  # a spreadsheet's export: ; and 48,2
    shot(tab, "1-filled")
    tab.get_by_test_id("plan").click()
    expect(tab.get_by_test_id("route-line").first).to_be_visible(timeout=60_000)
    shot(tab, "2-planned")

    answer = tab.evaluate("JSON.stringify(window.coldroute.answer())")
    routes = json.loads(answer)["routes"]
    assert tab.get_by_test_id("route-line").count() == len(routes) >= 2
    served = sum(len(r["stops"]) for r in routes)
    assert shown_stops(tab) == served == len(stops) - 1
    # each route's stops numbered in its order, clustered or not
    numbers = tab.evaluate("window.coldroute.markers()")
    assert numbers == {r["vehicle_id"]: list(range(1, len(r["stops"]) + 1)) for r in routes}
    # Three charts per route, each drawing the route's day minute by minute: the state of
    # charge with the reserve, each consumer's energy and the total, the box's air
    charts = tab.evaluate("window.coldroute.charts()")
    for route in routes:
        drawn = {c["testid"]: c for c in charts if c["vehicle"] == route["vehicle_id"]}
        minutes = len(route["profile"]["time"])
        assert {c["points"] for c in drawn.values()} == {minutes}
        assert drawn["soc-chart"]["series"] == ["state of charge", "reserve 10 %"]
        assert drawn["energy-chart"]["series"] == [
            "traction", "auxiliaries", "cabin", "refrigeration", "total"
        ]  # fmt: skip
        assert drawn["box-chart"]["series"][0] == "air"
    for name in ("soc-chart", "energy-chart", "box-chart"):
        assert tab.get_by_test_id(name).count() == len(routes)
    legend = tab.get_by_test_id("map-legend").inner_text()
    assert all(r["vehicle_id"] in legend for r in routes) and "not served" in legend
    unassigned = tab.get_by_test_id("unassigned")
    assert unassigned.count() == 1
    assert TOO_HEAVY in unassigned.inner_text() and "capacity" in unassigned.inner_text()
    assert tab.get_by_test_id("scale-bar").count() == 1

    with tab.expect_download() as download:
        tab.get_by_test_id("export-csv").click()
    rows = list(csv.DictReader(io.StringIO(Path(download.value.path()).read_text())))
    assert len(rows) == served and {r["vehicle_id"] for r in rows} == {
        r["vehicle_id"] for r in routes
    }
    assert [r["stop_id"] for r in rows if FORMULA in r["stop_id"]] == [f"'{FORMULA}"]
    assert not any(cell.startswith(("=", "+", "@")) for r in rows for cell in r.values())
    with tab.expect_download() as download:
        tab.get_by_test_id("export-geojson").click()
    features = json.loads(Path(download.value.path()).read_text())["features"]
    assert sum(f["properties"]["kind"] == "stop" for f in features) == served
    assert sum(f["properties"]["kind"] == "leg" for f in features) == sum(
        len(r["legs"]) for r in routes
    )
    assert outside == [], f"the viewer asked other hosts: {outside}"


def test_a_large_day_runs_as_a_job_and_reopens_by_its_url(server, page, tmp_path):
    tab, outside = page
    tab.goto(f"{server.url}/viewer")
    fill_day(tab, as_csv(vienna_round(70)), 4, tmp_path)  # beyond a synchronous answer
    tab.get_by_test_id("plan").click()
    expect(tab.get_by_test_id("status")).to_contain_text("Job", timeout=30_000)
    expect(tab.get_by_test_id("route-line").first).to_be_visible(timeout=120_000)
    assert "?job=" in tab.url
    answer = json.loads(tab.evaluate("JSON.stringify(window.coldroute.answer())"))
    lines = tab.get_by_test_id("route-line").count()
    markers = shown_stops(tab)
    assert lines == len(answer["routes"]) >= 2
    assert markers == sum(len(r["stops"]) for r in answer["routes"])
    # 70 stops: no two numbers on the map overlap (stops close together are clustered, each
    # cluster saying how many it holds)
    assert not overlapping(tab.locator("[data-testid=stop-marker], .marker-cluster"))
    assert tab.get_by_test_id("unassigned").count() == len(answer["unassigned"])
    shot(tab, "3-job")

    tab.goto(tab.url)  # a colleague opens the link, and types the key when asked
    expect(tab.get_by_test_id("error").last).to_contain_text("API key", timeout=30_000)
    tab.get_by_test_id("api-key").fill(KEY)
    tab.get_by_test_id("api-key").dispatch_event("change")
    expect(tab.get_by_test_id("route-line").first).to_be_visible(timeout=30_000)
    assert tab.get_by_test_id("error").count() == 0
    assert tab.get_by_test_id("route-line").count() == lines
    assert shown_stops(tab) == markers
    assert tab.get_by_test_id("unassigned").count() == len(answer["unassigned"])
    shot(tab, "4-reopened")
    assert outside == []


@pytest.mark.parametrize(
    ("line", "words"),
    [
        ("shop-03,48.2x,16.37,5,2,10,,", ["Row 3", "lat", "48.2x"]),
        ("shop-03,48.2,16.37,5,2,10,09:00,", ["Row 3", "window_end"]),
        ("shop-03,48.2,16.37,5,2,10,9 am,10:00", ["Row 3", "window_start"]),
        ("shop-01,48.2,16.37,5,2,10,,", ["Row 3", "id", "shop-01"]),
    ],
)
def test_a_bad_csv_row_is_named_by_row_and_column(server, page, tmp_path, line, words):
    tab, _ = page
    tab.goto(f"{server.url}/viewer")
    good = as_csv(vienna_round(4)).split("\r\n")
    bad = "\r\n".join([*good[:3], line, *good[4:]])
    fill_day(tab, bad, 2, tmp_path)
    tab.get_by_test_id("plan").click()
    error = tab.get_by_test_id("error").first
    expect(error).to_be_visible(timeout=10_000)
    for word in words:
        assert word in error.inner_text()
    assert tab.get_by_test_id("route-line").count() == 0
    shot(tab, f"5-bad-csv-{words[1]}")


def test_the_service_names_a_bad_field_and_the_key_is_sent(server, page, tmp_path):
    tab, outside = page
    tab.goto(f"{server.url}/viewer")
    fill_day(tab, as_csv(vienna_round(6)), 1, tmp_path)
    tab.fill("#timezone", "Europe")  # a folder of the zone database, not a zone
    tab.get_by_test_id("plan").click()
    error = tab.get_by_test_id("error").first
    expect(error).to_be_visible(timeout=30_000)
    assert error.inner_text().startswith("timezone")
    shot(tab, "6-bad-field")
    tab.fill("#timezone", "Europe/Vienna")
    tab.get_by_test_id("api-key").fill("wrong")
    tab.get_by_test_id("plan").click()
    expect(tab.get_by_test_id("error").first).to_contain_text("401", timeout=30_000)
    assert outside == []


def test_the_page_allows_only_its_own_host_and_the_tiles():
    tiles = "https://{s}.tiles.example/{z}/{x}/{y}.png"
    client = CheckedClient(create_app(Settings(tile_url=tiles)))  # no lifespan: no workers
    page = client.get("/viewer")
    policy = page.headers["content-security-policy"]
    assert "script-src 'self';" in policy and "connect-src 'self';" in policy
    assert "img-src 'self' data: https://*.tiles.example;" in policy
    assert f'data-tile-url="{tiles}"' in page.text
    script = client.get("/viewer/static/viewer.js")
    assert script.status_code == 200 and "text/javascript" in script.headers["content-type"]
    # the libraries vendored with their licences; the page loads each from this host
    for library, licence in [
        ("vendor/leaflet/leaflet.js", "BSD 2-Clause"),
        ("vendor/leaflet.markercluster/leaflet.markercluster.js", "MIT"),
        ("vendor/uplot/uPlot.iife.min.js", "MIT"),
    ]:
        assert f'src="/viewer/static/{library}"' in page.text
        assert client.get(f"/viewer/static/{library}").status_code == 200
        folder = library.rsplit("/", 1)[0]
        assert licence in client.get(f"/viewer/static/{folder}/LICENSE").text
    icon = client.get("/viewer/static/vendor/leaflet/images/layers.png")
    assert icon.headers["content-type"] == "image/png" and icon.content[:4] == b"\x89PNG"
    for name in ("secrets.py", "../routers/viewer.py", "vendor/../../settings.py", "__init__.py"):
        assert client.get(f"/viewer/static/{name}").status_code == 404
    # the audit: a 10 kB name echoed whole, and answers a browser might sniff
    missing = client.get("/viewer/static/" + "a" * 10_000 + ".js")
    assert missing.status_code == 404 and len(missing.content) < 1_000
    for answer in (page, script, missing):
        assert answer.headers["x-content-type-options"] == "nosniff"
    assert "(/viewer)" in client.get("/openapi.json").json()["info"]["description"]
    with pytest.raises(ValidationError):
        Settings(tile_url="javascript:alert(1)")


def test_a_pasted_plan_on_real_roads_draws_the_roads_and_a_run_sheet(osrm_url, tmp_path):
    """OSRM on the Monaco extract: each route line follows the road (many more points than
    stops), the pasted body of /v1/plans is planned as it is, and the run sheet prints."""
    roads = Server(
        {"COLDROUTE_WORKERS": "1", "COLDROUTE_OSRM_URL": osrm_url, "COLDROUTE_TILE_URL": ""}
    ).start()
    body = monaco_plan(["moneghetti", "casino", "palais", "larvotto", "port-hercule"])
    try:
        with offline_tab(roads.url) as (tab, outside, errors):
            tab.goto(f"{roads.url}/viewer")
            tab.locator("details summary").first.click()
            tab.get_by_test_id("request-json").fill(json.dumps(body))
            tab.get_by_test_id("plan").click()
            line = tab.get_by_test_id("route-line")
            expect(line).to_have_count(1, timeout=60_000)
            points = int(line.get_attribute("data-points"))
            assert points > 5 * (len(body["stops"]) + 2)  # the roads, not straight legs
            assert "straight line" not in tab.get_by_test_id("map-legend").inner_text()
            assert shown_stops(tab) == len(body["stops"])
            assert "OpenStreetMap" in tab.get_by_test_id("map").text_content()  # OSRM's credit
            shot(tab, "7-roads")

            tab.get_by_test_id("run-sheet").click()
            tab.emulate_media(media="print")
            sheet = tab.locator("#print-area")
            expect(sheet).to_be_visible()
            for stop in body["stops"]:
                assert stop["id"] in sheet.inner_text()
            shot(tab, "8-run-sheet")
            assert outside == [] and errors == []
    finally:
        roads.close()
