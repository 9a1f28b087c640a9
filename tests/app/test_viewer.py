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
import re
from pathlib import Path

import pytest
from playwright.sync_api import Page, expect
from pydantic import ValidationError

from app.main import create_app
from app.settings import Settings
from testbed.services import Server
from tests.app.invariants import CheckedClient
from tests.app.test_browser import offline_tab
from tests.app.test_jobs import BIG_STUDY
from tests.app.test_roads import monaco_plan

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

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
    # a route's card, line and legend entry lit together; the other routes fade
    first = routes[0]["vehicle_id"]
    tab.get_by_test_id("route").first.hover()
    lines = tab.get_by_test_id("route-line")
    faded = {
        lines.nth(k).get_attribute("data-vehicle"): lines.nth(k).get_attribute("stroke-opacity")
        for k in range(lines.count())
    }
    assert faded == {
        r["vehicle_id"]: "0.85" if r["vehicle_id"] == first else "0.15" for r in routes
    }
    assert "active" in (
        tab.locator(f".legend-route[data-vehicle='{first}']").get_attribute("class")
    )
    shot(tab, "2b-one-route-lit")
    tab.get_by_test_id("export-csv").hover()
    expect(lines.last).to_have_attribute("stroke-opacity", "0.85")
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


# --- a dispatcher's own CSV, its assumptions and its errors in view ---------------------------

DISPATCH_HEADER = "id,lat,lon,service_min,door_min,kg,window_start,window_end,address,notes"


def dispatch_csv(rows: list[str]) -> str:
    return "\r\n".join([DISPATCH_HEADER, *rows]) + "\r\n"


#: Six shops as a dispatcher's export has them: an address and notes beside the columns the
#: viewer reads, windows as H:MM and HH:MM:SS; one opens only at 11:00, long after the van
#: could be there (the van waits).
DISPATCH_ROWS = [
    "shop-a,48.2006,16.3862,6,2,30,7:00,10:00,Praterstraße 1,ring twice",
    "shop-b,48.1951,16.3712,6,2,30,,,Landstraßer Hauptstraße 9,",
    "shop-c,48.2101,16.3589,6,2,30,06:30:00,12:00:00,Wipplingerstraße 3,back door",
    "shop-d,48.1845,16.4012,6,2,30,,,Simmeringer Hauptstraße 5,",
    "shop-e,48.1762,16.4150,6,2,30,11:00,11:30,Geiselbergstraße 2,opens at 11",
    "shop-f,48.2150,16.4100,6,2,30,,,Ausstellungsstraße 7,",
]


def plan_day(tab: Page, csv_text: str, tmp_path: Path, name: str, vans: int = 1) -> None:
    fill_day(tab, csv_text, vans, tmp_path, name)
    tab.get_by_test_id("plan").click()


def test_a_dispatchers_csv_keeps_its_columns_and_the_run_sheet_reads_as_a_day(
    server, page, tmp_path
):
    tab, outside = page
    tab.goto(f"{server.url}/viewer")
    tab.fill("#t-min", "-8")  # a winter day: the door lets cold in, never "-0.00"
    tab.fill("#t-max", "-2")
    plan_day(tab, dispatch_csv(DISPATCH_ROWS), tmp_path, "dispatch.csv")
    expect(tab.get_by_test_id("route-line")).to_have_count(1, timeout=60_000)
    answer = tab.evaluate("window.coldroute.answer()")
    # the plan's assumptions in view: the weather given, straight lines and the speeds assumed
    assumptions = tab.get_by_test_id("assumptions").inner_text()
    route = answer["routes"][0]
    assert f"{route['weather']['t_min_c']:.1f} to {route['weather']['t_max_c']:.1f} °C" in (
        assumptions
    )
    assert "straight lines" in assumptions and "km/h" in assumptions
    assert "1 × preset ev-van-3.5t-reefer" in assumptions
    # the run sheet: every stop with its address and notes, the wait for shop-e's window
    # and its service start, kg to unload; no negative zero anywhere
    tab.get_by_test_id("route").locator("details summary").click()
    sheet = tab.get_by_test_id("route").get_by_test_id("run-table")
    text = sheet.inner_text()
    for row in DISPATCH_ROWS:
        *_, address, notes = row.split(",")
        assert address in text and notes in text
    late = next(s for s in route["stops"] if s["id"] == "shop-e")
    assert late["wait_s"] > 60 and late["service_start"][11:16] == "11:00"
    cells = sheet.locator("tr", has_text="shop-e").locator("td").all_inner_texts()
    assert cells[4] == f"{late['wait_s'] / 60:.0f} min" and cells[5] == "11:00"
    assert cells[7] == "30 kg"
    assert "-0" not in text and "−0" not in text
    shot(tab, "9-dispatch-day")
    # the kept columns go out with the CSV export
    with tab.expect_download() as download:
        tab.get_by_test_id("export-csv").click()
    rows = list(csv.DictReader(io.StringIO(Path(download.value.path()).read_text())))
    assert {r["stop_id"]: r["address"] for r in rows}["shop-c"] == "Wipplingerstraße 3"
    assert outside == []


def test_a_failed_csv_after_a_good_plan_clears_it_and_says_why_in_view(server, page, tmp_path):
    tab, _ = page
    tab.goto(f"{server.url}/viewer")
    plan_day(tab, dispatch_csv(DISPATCH_ROWS), tmp_path, "good.csv")
    expect(tab.get_by_test_id("route-line")).to_have_count(1, timeout=60_000)
    bad = dispatch_csv([*DISPATCH_ROWS[:2], "shop-x,48.2,16.37,5,2,10,9 am,10:00,,"])
    tab.get_by_test_id("stops-csv").set_input_files(
        files=[{"name": "bad.csv", "mimeType": "text/csv", "buffer": bad.encode()}]
    )
    tab.get_by_test_id("plan").click()
    error = tab.get_by_test_id("error").first
    expect(error).to_contain_text("Row 3")
    expect(error).to_be_in_viewport()
    # the earlier plan is gone: nothing on the map, no route, nothing to export
    assert tab.get_by_test_id("route-line").count() == 0
    assert tab.get_by_test_id("route").count() == 0
    expect(tab.get_by_test_id("export-csv")).to_be_disabled()
    assert tab.evaluate("window.coldroute.answer()") is None
    shot(tab, "10-failed-after-good")


def test_swapped_coordinates_are_refused_and_a_far_stop_is_flagged_and_warned(
    server, page, tmp_path
):
    tab, _ = page
    tab.goto(f"{server.url}/viewer")
    swapped = [*DISPATCH_ROWS[:3], "shop-s,16.3950,48.2050,6,2,30,,,Taborstraße 8,"]
    plan_day(tab, dispatch_csv(swapped), tmp_path, "swapped.csv")
    error = tab.get_by_test_id("error").first
    expect(error).to_contain_text("Row 4")
    assert "look swapped" in error.inner_text() and "shop-s" in error.inner_text()
    assert tab.get_by_test_id("route-line").count() == 0
    # Berlin, some 520 km from the Vienna depot: planned, flagged before and warned after
    berlin = [*DISPATCH_ROWS[:3], "shop-berlin,52.5200,13.4050,6,2,30,,,Unter den Linden 1,"]
    tab.get_by_test_id("stops-csv").set_input_files(
        files=[{"name": "far.csv", "mimeType": "text/csv", "buffer": dispatch_csv(berlin).encode()}]
    )
    tab.get_by_test_id("plan").click()
    expect(tab.get_by_test_id("route-line").first).to_be_visible(timeout=60_000)
    flagged = tab.get_by_test_id("flag").first.inner_text()
    assert "Row 4" in flagged and "shop-berlin" in flagged and "km from the depot" in flagged
    warned = tab.get_by_test_id("warnings").inner_text()
    assert "'shop-berlin') is 5" in warned and "from the depot" in warned
    shot(tab, "11-far-stop")


def test_charts_read_the_plans_local_clock_whatever_the_browsers_zone(server, tmp_path):
    options = {"viewport": {"width": 1500, "height": 1100}, "timezone_id": "America/New_York"}
    with offline_tab(server.url, **options) as (tab, outside, errors):
        tab.goto(f"{server.url}/viewer")
        plan_day(tab, dispatch_csv(DISPATCH_ROWS), tmp_path, "clock.csv")
        expect(tab.get_by_test_id("route-line")).to_have_count(1, timeout=60_000)
        leaves = tab.evaluate("window.coldroute.answer()")["routes"][0]["legs"][0]["depart"]
        charts = tab.evaluate("window.coldroute.charts()")
        assert {c["start"] for c in charts} == {leaves[11:16]}  # Vienna's, not New York's
        assert errors == [] and outside == []


def test_tiles_that_cannot_be_loaded_leave_a_note_not_broken_images(tmp_path):
    tiles = "http://tiles.invalid/{z}/{x}/{y}.png"
    served = Server({"COLDROUTE_WORKERS": "1", "COLDROUTE_TILE_URL": tiles}).start()
    try:
        with offline_tab(served.url, viewport={"width": 1500, "height": 1100}) as (
            tab,
            outside,
            errors,
        ):
            tab.goto(f"{served.url}/viewer")
            note = tab.get_by_test_id("map-note")
            expect(note).to_contain_text("could not be loaded from tiles.invalid")
            assert tab.locator("img.leaflet-tile").count() == 0
            assert outside and all(url.startswith("http://tiles.invalid/") for url in outside)
            assert tab.get_by_test_id("scale-bar").is_visible()
            shot(tab, "12-no-tiles")
            assert errors == []
    finally:
        served.close()


AXE = Path(__file__).parent / "vendor" / "axe-core" / "axe.min.js"  # axe-core 4.14.1, MPL-2.0


def test_the_page_is_keyboard_operable_and_axe_finds_nothing_serious(server, tmp_path):
    # the CSP is bypassed only to inject axe-core itself (vendored beside the tests); a
    # screen of twice the pixels, as a laptop's (the screenshot shows the charts at 2×)
    options = {"viewport": {"width": 1500, "height": 1100}, "bypass_csp": True}
    options["device_scale_factor"] = 2
    with offline_tab(server.url, **options) as (tab, outside, errors):
        tab.goto(f"{server.url}/viewer")
        # keyboard only: the key, then Tab through the form to the Plan button
        tab.get_by_test_id("api-key").focus()
        tab.keyboard.type(KEY)
        tab.keyboard.press("Tab")
        fill_day(tab, dispatch_csv(DISPATCH_ROWS), 2, tmp_path, "keys.csv")
        tab.get_by_test_id("plan").focus()
        tab.keyboard.press("Enter")
        expect(tab.get_by_test_id("route-line").first).to_be_visible(timeout=60_000)
        # a stop marker takes the focus and names itself
        marker = tab.locator(".leaflet-marker-icon[role=button]").first
        marker.focus()
        assert tab.evaluate("document.activeElement.getAttribute('aria-label')")
        tab.add_script_tag(path=str(AXE))
        found = tab.evaluate(
            "axe.run(document, {resultTypes: ['violations']})"
            ".then(r => r.violations.map(v => ({id: v.id, impact: v.impact, nodes: v.nodes.length,"
            " target: v.nodes[0].target.join(' ')})))"
        )
        serious = [v for v in found if v["impact"] in ("serious", "critical")]
        assert serious == [], serious
        shot(tab, "13-keyboard-2x")
        assert errors == [] and outside == []


# --- working with a plan: save and reopen, move a stop and re-simulate, compare ---------------


def test_a_plan_saved_reopens_by_its_link_and_a_moved_stop_is_re_simulated_and_compared(
    server, page, tmp_path
):
    tab, outside = page
    tab.goto(f"{server.url}/viewer")
    fill_day(tab, dispatch_csv(DISPATCH_ROWS), 2, tmp_path, "work.csv")
    tab.fill("#payload-kg", "120")  # 180 kg of deliveries: both vans drive
    tab.get_by_test_id("plan").click()
    expect(tab.get_by_test_id("route-line").first).to_be_visible(timeout=60_000)
    first = tab.evaluate("window.coldroute.answer()")
    assert len(first["routes"]) == 2, "the day needs both vans for this test"
    # from the fuller van to the other, which has room for 30 kg more
    routes = sorted(first["routes"], key=lambda r: -len(r["stops"]))
    # saved: a link that reopens the same plan (the same request planned again, as a job)
    tab.get_by_test_id("save").click()
    link = tab.get_by_test_id("saved-link")
    expect(link).to_be_visible(timeout=30_000)
    href = link.get_attribute("href")
    assert href.startswith("/viewer?job=")

    # the last stop of the first van moved to the second van's front, by keyboard and list
    moved = routes[0]["stops"][-1]["id"]
    tab.locator(f"[data-testid=route][data-vehicle='{routes[0]['vehicle_id']}'] summary").click()
    row = tab.locator(f"table[data-vehicle='{routes[0]['vehicle_id']}'] tr[data-stop='{moved}']")
    row.get_by_test_id("move-to").select_option(routes[1]["vehicle_id"])
    target = tab.locator(f"table[data-vehicle='{routes[1]['vehicle_id']}'] tr[data-stop]")
    expect(target.last).to_have_attribute("data-stop", moved)
    mine = tab.locator(f"table[data-vehicle='{routes[1]['vehicle_id']}'] tr[data-stop='{moved}']")
    for _ in range(len(routes[1]["stops"])):
        mine.get_by_test_id("move-up").click()  # to the front, one place at a time
    expect(target.first).to_have_attribute("data-stop", moved)
    expect(tab.get_by_test_id("edit-status")).to_contain_text("2 route(s) changed")
    tab.get_by_test_id("resimulate").click()
    expect(tab.get_by_test_id("compare")).to_contain_text("(edited)", timeout=60_000)
    assert tab.get_by_test_id("error").count() == 0
    edited = tab.evaluate("window.coldroute.answer()")
    after = {r["vehicle_id"]: r for r in edited["routes"]}
    assert [s["id"] for s in after[routes[1]["vehicle_id"]]["stops"]] == [moved] + [
        s["id"] for s in routes[1]["stops"]
    ]
    assert moved not in [s["id"] for s in after[routes[0]["vehicle_id"]]["stops"]]
    # each changed route planned in the order given (keep_order), and simulated in full
    assert {r["solver"]["status"] for r in edited["routes"]} == {"fixed_order"}
    assert tab.get_by_test_id("route-line").count() == 2
    # the two plans side by side: the one planned and the one edited by hand
    table = tab.get_by_test_id("compare")
    expect(table).to_contain_text("Plan 1")
    expect(table).to_contain_text("(edited)")
    distance = table.locator("tr", has_text="Distance").locator("td").all_inner_texts()
    total_km = sum(r["totals"]["distance_m"] for r in edited["routes"]) / 1000
    assert distance[1] == f"{total_km:.1f} km" and distance[0] != distance[1]
    shot(tab, "14-edited-and-compared")

    # a colleague opens the saved link: the first plan, as it was
    tab.goto(f"{server.url}{href}")
    tab.get_by_test_id("api-key").fill(KEY)
    tab.get_by_test_id("api-key").dispatch_event("change")
    expect(tab.get_by_test_id("route-line").first).to_be_visible(timeout=60_000)
    reopened = tab.evaluate("window.coldroute.answer()")
    assert reopened["routes"] == first["routes"] or [
        [s["id"] for s in r["stops"]] for r in reopened["routes"]
    ] == [[s["id"] for s in r["stops"]] for r in first["routes"]]
    shot(tab, "15-saved-reopened")
    assert outside == []


def test_a_stop_pinned_to_another_van_is_planned_on_it(server, page, tmp_path):
    tab, outside = page
    tab.goto(f"{server.url}/viewer")
    fill_day(tab, dispatch_csv(DISPATCH_ROWS), 2, tmp_path, "pins.csv")
    tab.fill("#payload-kg", "120")  # 180 kg of deliveries: both vans drive
    tab.get_by_test_id("plan").click()
    expect(tab.get_by_test_id("route-line").first).to_be_visible(timeout=60_000)
    first = tab.evaluate("window.coldroute.answer()")
    assert len(first["routes"]) == 2, "the day needs both vans for this test"
    source, target = (r["vehicle_id"] for r in first["routes"])
    pinned = first["routes"][0]["stops"][0]["id"]
    expect(tab.get_by_test_id("replan")).to_be_disabled()

    # moved to the other van, then pinned there: the fleet planned again keeps it there
    tab.locator(f"[data-testid=route][data-vehicle='{source}'] summary").click()
    row = tab.locator(f"table[data-vehicle='{source}'] tr[data-stop='{pinned}']")
    row.get_by_test_id("move-to").select_option(target)
    pin = tab.locator(f"table[data-vehicle='{target}'] tr[data-stop='{pinned}']").get_by_test_id(
        "pin"
    )
    pin.click()
    expect(pin).to_have_attribute("aria-pressed", "true")
    expect(tab.get_by_test_id("pin-status")).to_contain_text(f"{pinned} → {target}")
    tab.get_by_test_id("replan").click()
    expect(tab.get_by_test_id("compare")).to_contain_text("(pinned)", timeout=60_000)
    assert tab.get_by_test_id("error").count() == 0
    again = tab.evaluate("window.coldroute.answer()")
    by = {s["id"]: r["vehicle_id"] for r in again["routes"] for s in r["stops"]}
    assert by[pinned] == target
    request = tab.evaluate("window.coldroute.request()")
    pins = {v["id"]: v["pinned_stops"] for v in request["vehicles"]}
    assert pins == {source: [], target: [pinned]}
    # the new plan's table shows the pin, and unpinning it empties the list
    tab.locator(f"[data-testid=route][data-vehicle='{target}'] summary").click()
    shown = tab.locator(f"table[data-vehicle='{target}'] tr[data-stop='{pinned}']")
    expect(shown.get_by_test_id("pin")).to_have_attribute("aria-pressed", "true")
    shot(tab, "16-pinned-and-planned-again")
    shown.get_by_test_id("pin").click()
    expect(tab.get_by_test_id("replan")).to_be_disabled()
    assert outside == []


def test_the_electrification_study_shows_its_heat_map_and_coverage_curve(server, page):
    tab, outside = page
    tab.goto(f"{server.url}/viewer")
    tab.get_by_test_id("api-key").fill(KEY)
    tab.get_by_test_id("api-key").dispatch_event("change")
    tab.get_by_test_id("study-example").click()
    expect(tab.get_by_test_id("study-json")).to_have_value(re.compile("long-day"))
    tab.get_by_test_id("study-run").click()
    expect(tab.get_by_test_id("study-status")).to_contain_text("261 route-days", timeout=120_000)
    answer = tab.evaluate("window.coldrouteStudy.answer()")
    heat = tab.get_by_test_id("study-heatmap")
    # one row per route, one cell per day driven, coloured as the answer's own days say
    for route in answer["routes"]:
        outcome = route["candidates"][0]  # the first candidate is shown first
        row = heat.locator(f"tr[data-route='{route['id']}']")
        assert row.locator(".day").count() == outcome["days_total"]
        assert row.locator(".day.covered").count() == outcome["days_feasible"]
        charged = outcome["days_feasible_with_charging"] - outcome["days_feasible"]
        assert row.locator(".day.charged").count() == charged
    expect(tab.get_by_test_id("study-fleet")).to_contain_text("reefer-40: 1 of 2 route(s)")
    shot(tab, "17-electrification-study")
    # the larger battery: every day of both routes on one charge, the curve reaching 100 %
    tab.get_by_test_id("study-candidate").select_option("reefer-70")
    expect(tab.get_by_test_id("study-fleet")).to_contain_text("reefer-70: 2 of 2 route(s)")
    assert heat.locator(".day.short").count() == 0
    capacities, covered = tab.evaluate("window.coldrouteStudy.coverage()")
    assert covered[-1] == 100 and capacities == sorted(capacities)
    assert capacities[-1] <= 70
    assert outside == []


def test_a_telematics_export_becomes_the_studys_days_in_the_viewer(server, page, tmp_path):
    tab, outside = page
    tab.goto(f"{server.url}/viewer")
    tab.get_by_test_id("api-key").fill(KEY)
    tab.get_by_test_id("api-key").dispatch_event("change")
    tab.get_by_test_id("study-example").click()
    expect(tab.get_by_test_id("study-json")).to_have_value(re.compile("long-day"))
    export = tmp_path / "telematics.csv"
    export.write_text(
        "route_id,date,stop_id,lat,lon,arrival,departure,delivery_kg\n"
        "inner-city,2026-07-15,depot-simmering,48.1703,16.4207,,09:00,\n"
        "inner-city,2026-07-15,billa,48.2006,16.3862,09:20,09:29,30\n"
        "long-day,2026-07-16,depot-centre,48.21,16.37,,07:00,\n"
        "long-day,2026-07-16,spar,48.1925,16.3671,07:15,07:25,25\n"
        "long-day,2026-07-16,hofer,48.2036,16.3489,07:40,07:47,35\n",
        encoding="utf-8",
    )
    tab.get_by_test_id("study-csv").set_input_files(str(export))
    expect(tab.get_by_test_id("study-status")).to_contain_text("2 route-days read")
    study = json.loads(tab.get_by_test_id("study-json").input_value())
    assert [len(r["days"][0]["stops"]) for r in study["routes"]] == [1, 2]
    tab.get_by_test_id("study-run").click()
    expect(tab.get_by_test_id("study-status")).to_contain_text(
        "2 route-days studied", timeout=120_000
    )
    assert tab.get_by_test_id("study-heatmap").locator(".day").count() == 2
    assert outside == []


def test_a_running_study_shows_its_progress_and_is_cancelled_from_the_viewer(server, page):
    tab, outside = page
    tab.goto(f"{server.url}/viewer")
    tab.get_by_test_id("api-key").fill(KEY)
    tab.get_by_test_id("api-key").dispatch_event("change")
    tab.get_by_test_id("study-json").fill(json.dumps(BIG_STUDY))  # 3 parts of ~2,000
    tab.get_by_test_id("study-run").click()
    status = tab.get_by_test_id("study-status")
    expect(status).to_contain_text(
        re.compile(r"running: [\d,]+ of [\d,]+ route-days"), timeout=60_000
    )
    expect(status).to_contain_text(re.compile(r"[12] of 3 parts"), timeout=60_000)
    shot(tab, "18-electrification-progress")
    tab.get_by_test_id("study-cancel").click()
    expect(status).to_contain_text("cancelled", timeout=30_000)
    expect(tab.get_by_test_id("study-cancel")).to_be_hidden()
    expect(tab.get_by_test_id("study-run")).to_be_enabled()
    assert outside == []
