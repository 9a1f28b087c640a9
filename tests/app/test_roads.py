"""Real roads: the service against a real osrm-routed on the Monaco extract."""

from __future__ import annotations

import os
import signal
import time

import httpx
import numpy as np
import pytest
from fastapi.testclient import TestClient

from app.connectors.osrm import OsrmRouter
from app.examples import SCENARIOS_EXAMPLE
from core.exceptions import NoRouteError
from core.params import Place
from core.planning.model import default_work_s
from core.planning.search.day import leg_roads
from tests.app.apps import app_client
from tools import osrm

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

PLACES = {
    "moneghetti": (43.7380, 7.4148),
    "casino": (43.7397, 7.4274),
    "palais": (43.7314, 7.4198),
    "stade-louis-ii": (43.7277, 7.4155),
    "port-hercule": (43.7347, 7.4235),
    "larvotto": (43.7446, 7.4340),
    "jardin-exotique": (43.7311, 7.4122),
    "gare": (43.7390, 7.4206),
    "condamine": (43.7355, 7.4205),
}
GEOJSON = "application/geo+json"


def monaco_plan(names, **changes):
    depot, *stops = names
    body = {
        "date": "2026-07-15",
        "start_time": "09:00",
        "timezone": "Europe/Monaco",
        "depot": {"id": depot, "lat": PLACES[depot][0], "lon": PLACES[depot][1]},
        "stops": [
            {"id": n, "lat": PLACES[n][0], "lon": PLACES[n][1], "delivery_kg": 20} for n in stops
        ],
        "weather": {"t_min_c": 20, "t_max_c": 29},
    }
    return body | changes


def client_for(url: str, **settings) -> TestClient:
    return app_client(osrm_url=url, **settings)


@pytest.fixture(scope="module")
def roads(osrm_url):
    return client_for(osrm_url)


def _route(url, a, b):
    (lat1, lon1), (lat2, lon2) = PLACES[a], PLACES[b]
    return httpx.get(
        f"{url}/route/v1/driving/{lon1},{lat1};{lon2},{lat2}", params={"overview": "false"}
    ).json()["routes"][0]


def test_every_leg_is_the_road_osrm_routes(roads, osrm_url):
    body = roads.post("/v1/plans", json=monaco_plan(list(PLACES))).json()
    assert body["distance_source"] == "osrm"
    assert "OpenStreetMap" in body["attribution"]
    for leg in body["legs"]:
        # OSRM rounds a route's distance to 0.1 m; the leg sums its exact segments
        assert leg["distance_m"] == pytest.approx(
            _route(osrm_url, leg["from_id"], leg["to_id"])["distance"], abs=0.06
        )
    assert sum(leg["distance_m"] for leg in body["legs"]) == pytest.approx(
        body["totals"]["distance_m"]
    )
    # every stop is snapped to the road, a few metres to a few hundred away
    assert all(0 <= stop["snap_distance_m"] < 500 for stop in body["stops"])
    # Monaco is city driving: every leg is urban by its speeds
    assert {leg["street_type"] for leg in body["legs"]} <= {"urban", "highway"}


def test_the_tour_follows_the_asymmetric_matrix(roads, osrm_url):
    # One-way streets: Moneghetti → casino → palace → back is 9.3 km, the other way 6.3 km.
    names = ["moneghetti", "casino", "palais"]
    coordinates = ";".join(f"{PLACES[n][1]},{PLACES[n][0]}" for n in names)
    table = httpx.get(
        f"{osrm_url}/table/v1/driving/{coordinates}", params={"annotations": "distance"}
    ).json()["distances"]
    clockwise = table[0][1] + table[1][2] + table[2][0]
    counter = table[0][2] + table[2][1] + table[1][0]
    assert abs(clockwise - counter) > 1000
    body = roads.post("/v1/plans", json=monaco_plan(names)).json()
    assert body["solver"]["status"] == "optimal"
    assert body["solver"]["objective_value"] == pytest.approx(min(clockwise, counter), abs=2)
    expected = (
        ["moneghetti", "casino", "palais"]
        if clockwise < counter
        else [
            "moneghetti",
            "palais",
            "casino",
        ]
    )
    assert body["tour"][:-1] == expected


def test_geometry_and_geojson(roads):
    names = ["moneghetti", "casino", "gare", "palais"]
    body = roads.post("/v1/plans", json=monaco_plan(names, include_geometry=True)).json()
    for leg in body["legs"]:
        line = leg["geometry"]
        assert line["type"] == "LineString" and len(line["coordinates"]) >= 2
        lon, lat = line["coordinates"][0]
        assert 7.40 < lon < 7.45 and 43.72 < lat < 43.76
    first = body["legs"][0]["geometry"]["coordinates"][0]
    assert first == pytest.approx([PLACES["moneghetti"][1], PLACES["moneghetti"][0]], abs=0.002)

    response = roads.post("/v1/plans", json=monaco_plan(names), headers={"Accept": GEOJSON})
    assert response.status_code == 200
    assert response.headers["content-type"] == GEOJSON
    collection = response.json()
    assert (
        collection["type"] == "FeatureCollection" and "OpenStreetMap" in collection["attribution"]
    )
    kinds = [f["properties"]["kind"] for f in collection["features"]]
    assert kinds.count("depot") == 1 and kinds.count("stop") == 3 and kinds.count("leg") == 4
    stop = next(f for f in collection["features"] if f["properties"]["kind"] == "stop")
    assert stop["geometry"]["type"] == "Point"
    assert {"id", "arrival", "door_heat_kwh", "soc_arrival"} <= set(stop["properties"])
    leg = next(f for f in collection["features"] if f["properties"]["kind"] == "leg")
    assert leg["geometry"]["type"] == "LineString"
    assert set(leg["properties"]["energy_kwh"]) >= {"traction", "cabin", "refrigeration", "total"}
    assert {"soc_start", "soc_end"} <= set(leg["properties"])
    # JSON stays the default, and an explicit preference for JSON wins
    both = roads.post(
        "/v1/plans",
        json=monaco_plan(names),
        headers={"Accept": f"application/json, {GEOJSON};q=0.5"},
    )
    assert both.headers["content-type"] == "application/json"


def test_a_stop_in_the_sea_is_named(roads):
    body = monaco_plan(["moneghetti", "casino", "palais"])
    body["stops"].append({"id": "at-sea", "lat": 43.70, "lon": 7.45})
    response = roads.post("/v1/plans", json=body)
    assert response.status_code == 422
    error = response.json()["errors"][0]
    assert error["field"] == "stops[2]" and "nearest road" in error["message"]


def test_a_charger_in_the_sea_is_named(roads):
    body = monaco_plan(["moneghetti", "casino", "palais"])
    at_sea = {"id": "sea-charger", "lat": 43.70, "lon": 7.45, "power_kw": 50}
    on_land = at_sea | {
        "id": "casino-charger",
        "lat": PLACES["casino"][0],
        "lon": PLACES["casino"][1],
    }
    response = roads.post("/v1/plans", json=body | {"chargers": [on_land, at_sea]})
    assert response.status_code == 422
    error = response.json()["errors"][0]
    assert error["field"] == "chargers[1]" and "nearest road" in error["message"]
    # on a street it is a place the round may charge at, not a stop: the tour leaves it out
    planned = roads.post("/v1/plans", json=body | {"chargers": [on_land]})
    assert planned.status_code == 200
    assert "casino-charger" not in planned.json()["tour"] and planned.json()["charges"] == []


def test_a_van_in_the_sea_is_named_as_its_start_state(roads):
    at_sea = {"lat": 43.70, "lon": 7.45, "time": "2026-07-15T12:00:00+02:00", "soc": 0.8}
    body = monaco_plan(["moneghetti", "casino", "palais"], start_state=at_sea)
    response = roads.post("/v1/plans", json=body)
    assert response.status_code == 422
    error = response.json()["errors"][0]
    assert error["field"] == "start_state" and "nearest road" in error["message"]
    # from a street, the rest of the day drives on OSRM's roads
    on_land = at_sea | {"lat": PLACES["casino"][0], "lon": PLACES["casino"][1]}
    planned = roads.post(
        "/v1/plans", json=monaco_plan(["moneghetti", "palais"], start_state=on_land)
    )
    assert planned.status_code == 200
    assert planned.json()["tour"][0] == "start"
    assert planned.json()["distance_source"] == "osrm"


def test_a_fleet_van_in_the_sea_is_named_and_one_on_a_street_drives_on_roads(roads):
    at_sea = {"lat": 43.70, "lon": 7.45, "time": "2026-07-15T10:00:00+02:00", "soc": 0.8}
    body = monaco_plan(["moneghetti", "casino", "palais", "gare"])
    body.pop("start_time")
    body["vehicles"] = [
        {"id": "van-0", "shift_start": "09:00", "shift_end": "12:00"},
        {"id": "van-1", "shift_start": "09:00", "shift_end": "12:00", "start_state": at_sea},
    ]
    response = roads.post("/v1/fleet-plans", json=body)
    assert response.status_code == 422
    error = response.json()["errors"][0]
    assert error["field"] == "vehicles[1].start_state" and "nearest road" in error["message"]
    on_land = at_sea | {"lat": PLACES["condamine"][0], "lon": PLACES["condamine"][1]}
    body["vehicles"][1]["start_state"] = on_land
    planned = roads.post("/v1/fleet-plans", json=body)
    assert planned.status_code == 200, planned.text
    (under_way,) = [r for r in planned.json()["routes"] if r["vehicle_id"] == "van-1"]
    assert under_way["tour"][0] == "start" and under_way["distance_source"] == "osrm"
    assert under_way["legs"][0]["depart"] == "2026-07-15T10:00:00+02:00"


# Two road islands 3 km apart with no road between them, as OpenStreetMap XML (osrm-extract
# reads .osm as well as .osm.pbf).
ISLANDS_OSM = """<?xml version="1.0" encoding="UTF-8"?>
<osm version="0.6" generator="coldroute-tests">
  <node id="1" version="1" lat="43.7300" lon="7.4000"/>
  <node id="2" version="1" lat="43.7300" lon="7.4040"/>
  <node id="3" version="1" lat="43.7300" lon="7.4080"/>
  <node id="4" version="1" lat="43.7300" lon="7.4120"/>
  <node id="11" version="1" lat="43.7500" lon="7.4400"/>
  <node id="12" version="1" lat="43.7500" lon="7.4440"/>
  <node id="13" version="1" lat="43.7500" lon="7.4480"/>
  <way id="100" version="1">
    <nd ref="1"/><nd ref="2"/><nd ref="3"/><nd ref="4"/><tag k="highway" v="residential"/>
  </way>
  <way id="200" version="1">
    <nd ref="11"/><nd ref="12"/><nd ref="13"/><tag k="highway" v="residential"/>
  </way>
</osm>
"""
ISLAND_A = [("depot", 43.7300, 7.4020), ("west", 43.7300, 7.4080)]
ISLAND_B = ("island", 43.7500, 7.4450)


@pytest.fixture(scope="module")
def islands_url(tmp_path_factory):
    """A real osrm-routed on the two islands."""
    folder = tmp_path_factory.mktemp("islands")
    (folder / "islands.osm").write_text(ISLANDS_OSM)
    with osrm.running(osrm.prepare(folder / "islands.osm")) as url:
        yield url


def island_places():
    return [Place(id=n, lat=lat, lon=lon) for n, lat, lon in [*ISLAND_A, ISLAND_B]]


def test_a_stop_no_road_reaches_is_named(islands_url):
    (depot, *stops) = [p.model_dump() for p in island_places()]
    body = {"date": "2026-07-15", "timezone": "Europe/Monaco", "depot": depot, "stops": stops}
    response = client_for(islands_url).post("/v1/plans", json=body)
    assert response.status_code == 422
    error = response.json()["errors"][0]
    assert error["field"] == "stops[1]" and "no road" in error["message"]


def test_a_fleet_leaves_out_a_stop_no_road_reaches(islands_url):
    (depot, *stops) = [p.model_dump() for p in island_places()]
    body = {
        "date": "2026-07-15",
        "timezone": "Europe/Monaco",
        "depot": depot,
        "stops": stops,
        "vehicles": [{"id": "van"}],
    }
    response = client_for(islands_url).post("/v1/fleet-plans", json=body)
    assert response.status_code == 200
    answer = response.json()
    assert [(u["id"], u["reason"]) for u in answer["unassigned"]] == [("island", "unreachable")]
    assert answer["routes"][0]["tour"] == ["depot", "west", "depot"]


def test_osrm_no_route_between_islands_is_named_by_its_destination(islands_url):
    router = OsrmRouter(islands_url, 5, 100, 500)
    table = router.table(island_places())
    assert np.isnan(table.distance_m[0, 2]) and np.isnan(table.duration_s[2, 1])
    assert table.distance_m[0, 1] > 0
    with pytest.raises(NoRouteError) as caught:
        leg_roads(router, island_places(), [0, 1, 2, 0])
    assert caught.value.field == "stops[1]"


def test_a_stopped_router_is_a_503_naming_it(monaco_osrm):
    with osrm.running(monaco_osrm) as url:
        client = client_for(url)
        names = ["moneghetti", "casino", "palais"]
        assert client.post("/v1/plans", json=monaco_plan(names)).status_code == 200
    response = client.post("/v1/plans", json=monaco_plan(names))
    assert response.status_code == 503
    assert response.headers["content-type"] == "application/problem+json"
    assert response.json()["service"] == "osrm" and "Retry-After" in response.headers


def test_a_slow_router_is_a_503_within_the_timeout(monaco_osrm):
    port = osrm.free_port()
    process = osrm.start(monaco_osrm, port)
    try:
        client = client_for(f"http://127.0.0.1:{port}", osrm_timeout_s=1.0)
        os.kill(process.pid, signal.SIGSTOP)  # the router hangs: accepts, never answers
        started = time.monotonic()
        response = client.post("/v1/plans", json=monaco_plan(["moneghetti", "casino"]))
        elapsed = time.monotonic() - started
        assert response.status_code == 503 and "in time" in response.json()["detail"]
        # it gave up on its timeout, not waited for the router: a hung router would never
        # answer (a bound of 3 s failed a fresh-clone CI run on a busy machine at 3.3 s)
        assert elapsed < 30.0
    finally:
        os.kill(process.pid, signal.SIGCONT)
        process.terminate()
        process.wait(timeout=10)


def test_a_router_answering_garbage_is_a_503(weather_stub):
    # The weather stand-in is an HTTP server that knows nothing of OSRM.
    response = client_for(f"{weather_stub.url}/hot").post(
        "/v1/plans", json=monaco_plan(["moneghetti", "casino"])
    )
    assert response.status_code == 503 and response.json()["service"] == "osrm"


def test_the_table_in_blocks_equals_one_call(osrm_url, monaco_osrm):
    places = [Place(id=n, lat=lat, lon=lon) for n, (lat, lon) in PLACES.items()]
    whole = OsrmRouter(osrm_url, 5, 100, 500).table(places)
    blocks = OsrmRouter(osrm_url, 5, 4, 500).table(places)  # 9 places: a last block of one
    assert blocks.distance_m == pytest.approx(whole.distance_m)
    assert blocks.duration_s == pytest.approx(whole.duration_s)
    assert blocks.snap_distance_m == pytest.approx(whole.snap_distance_m)
    # a server with a smaller limit than configured: the client halves its blocks
    with osrm.running(monaco_osrm, max_table_size=4) as small:
        limited = OsrmRouter(small, 5, 100, 500).table(places)
    assert limited.distance_m == pytest.approx(whole.distance_m)
    assert not np.allclose(whole.distance_m, whole.distance_m.T)  # one-way streets


def test_the_clients_matrix_wins_over_the_router(roads):
    names = ["moneghetti", "casino"]
    matrix = {"distances_m": [[0, 1000], [1100, 0]], "durations_s": [[0, 120], [130, 0]]}
    body = roads.post("/v1/plans", json=monaco_plan(names, matrix=matrix)).json()
    assert body["distance_source"] == "client" and body["attribution"] is None
    assert body["legs"][0]["distance_m"] == pytest.approx(1000)


def test_real_roads_cost_more_than_the_estimate(roads):
    names = list(PLACES)
    real = roads.post("/v1/plans", json=monaco_plan(names, keep_order=True)).json()
    guess = app_client().post("/v1/plans", json=monaco_plan(names, keep_order=True)).json()
    assert guess["distance_source"] == "estimate"
    assert real["totals"]["distance_m"] > 1.3 * guess["totals"]["distance_m"]
    assert real["totals"]["energy_kwh"]["traction"] > guess["totals"]["energy_kwh"]["traction"]


def test_scenarios_on_real_roads(roads):
    request = SCENARIOS_EXAMPLE | {"plan": monaco_plan(list(PLACES)[:5])}
    body = roads.post("/v1/studies/scenarios", json=request).json()
    assert len(body["cells"]) == 12 and body["tour"][0] == "moneghetti"


def test_a_fleet_on_real_roads_keeps_its_windows_as_driven(roads):
    # Monaco's roads are slow to drive in the simulation (about twice OSRM's free-flow times):
    # the windows must hold for the times the simulation drives, not the router's.
    names = list(PLACES)
    body = monaco_plan(names)
    for stop in body["stops"][:4]:
        stop["time_windows"] = [{"start": "09:20", "end": "09:40"}]
    body.pop("start_time")
    body["vehicles"] = [
        {"id": f"van-{k}", "shift_start": "09:00", "shift_end": "12:00"} for k in range(3)
    ]
    # a default request's work, and time to do it: a busy machine's clock (the router's calls
    # inside) once cut the search before it placed a stop
    body |= {"time_limit_s": 30, "work_s": default_work_s(1.0)}
    answer = roads.post("/v1/fleet-plans", json=body)
    assert answer.status_code == 200, answer.text
    fleet = answer.json()
    assert fleet["distance_source"] == "osrm" and fleet["attribution"]
    assert fleet["unassigned"] == []
    windowed = {s["id"] for s in body["stops"][:4]}
    for route in fleet["routes"]:
        assert route["battery"]["feasible"] and route["distance_source"] == "osrm"
        for stop in route["stops"]:
            if stop["id"] in windowed:
                assert "09:20:00" <= stop["service_start"][11:19] <= "09:40:00", stop
        assert route["legs"][-1]["arrive"][11:16] <= "12:00"
