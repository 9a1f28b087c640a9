"""POST /v1/fleet-plans and time windows on /v1/plans, as a dispatcher's software calls them."""

from __future__ import annotations

import copy
import datetime as dt

import pytest

from app.examples import FLEET_PLAN_EXAMPLE, PLAN_EXAMPLE
from core.planning.model import default_work_s
from tests.app.apps import app_client

PROBLEM = "application/problem+json"


def hhmm(text: str) -> dt.time:
    return dt.time.fromisoformat(text)


def assert_routes_hold(body: dict, request: dict) -> None:
    """Every route of the answer keeps every rule, as its own simulation reports it."""
    stops = {s["id"]: s for s in request["stops"]}
    vans = {v["id"]: v for v in request["vehicles"]}
    served = []
    for route in body["routes"]:
        van = vans[route["vehicle_id"]]
        assert route["battery"]["feasible"] is True
        depart = dt.datetime.fromisoformat(route["legs"][0]["depart"]).time()
        back = dt.datetime.fromisoformat(route["legs"][-1]["arrive"]).time()
        assert hhmm(van.get("shift_start", "08:00")) <= depart
        assert back <= hhmm(van.get("shift_end", "18:00"))
        for stop in route["stops"]:
            served.append(stop["id"])
            windows = stops[stop["id"]].get("time_windows", [])
            start = dt.datetime.fromisoformat(stop["service_start"]).time()
            assert not windows or any(
                hhmm(w["start"]) <= start <= hhmm(w["end"]) for w in windows
            ), stop
    left = [u["id"] for u in body["unassigned"]]
    assert sorted(served + left) == sorted(stops)


def test_the_swagger_example_runs_as_is(client):
    response = client.post("/v1/fleet-plans", json=FLEET_PLAN_EXAMPLE)
    assert response.status_code == 200, response.text
    body = response.json()
    assert_routes_hold(body, FLEET_PLAN_EXAMPLE)
    assert body["unassigned"] == []
    assert body["totals"]["vehicles_used"] == len(body["routes"]) >= 1
    assert body["solver"]["status"] == "feasible" and body["solver"]["verification_rounds"] >= 1
    route = body["routes"][0]
    # Each route is a full /v1/plans answer with its van's id.
    assert route["vehicle_id"] == "van-1" and route["tour"][0] == route["tour"][-1]
    assert set(route) >= {"legs", "stops", "totals", "battery", "weather", "solver", "box"}
    assert body["totals"]["energy_kwh"]["total"] == pytest.approx(
        sum(r["totals"]["energy_kwh"]["total"] for r in body["routes"])
    )
    # The cafe takes goods 07:00–08:00 only: served inside, waiting if early.
    cafe = next(s for r in body["routes"] for s in r["stops"] if s["id"] == "cafe-innere-stadt")
    assert "07:00" <= cafe["service_start"][11:16] <= "08:00"


def windowed_plan(windows: dict[str, list[dict]]) -> dict:
    body = copy.deepcopy(PLAN_EXAMPLE)
    for stop in body["stops"]:
        if stop["id"] in windows:
            stop["time_windows"] = windows[stop["id"]]
    return body


def test_a_fleet_of_one_plans_the_round_plans_plans(client_default):
    client = client_default  # time to do the same work for both, see below
    plan_body = windowed_plan(
        {
            "spar-wieden": [{"start": "10:30", "end": "11:00"}],
            "cafe-innere-stadt": [{"start": "09:00", "end": "09:30"}],
        }
    )
    # The same work for both, and time to do it: a busy machine's clock cuts neither search.
    limits = {"time_limit_s": 60, "work_s": default_work_s(1.0)}
    single = client.post("/v1/plans", json=plan_body | limits).json()
    fleet_body = (
        limits
        | {
            key: plan_body[key]
            for key in ("date", "timezone", "depot", "stops", "weather", "objective")
        }
        | {
            "vehicles": [
                {
                    "id": "only",
                    "vehicle": plan_body["vehicle"],
                    "battery": plan_body["battery"],
                    "payload_kg": plan_body["payload_kg"],
                    "shift_start": plan_body["start_time"],
                    "shift_end": "23:59",
                }
            ],
            "driver_aggressiveness": plan_body["driver_aggressiveness"],
        }
    )
    fleet = client.post("/v1/fleet-plans", json=fleet_body).json()
    assert single["solver"]["stopped_by"] == fleet["solver"]["stopped_by"] == "work"
    route = fleet["routes"][0]
    assert route["tour"] == single["tour"]
    assert [s["service_start"] for s in route["stops"]] == [
        s["service_start"] for s in single["stops"]
    ]
    assert route["totals"]["energy_kwh"] == pytest.approx(single["totals"]["energy_kwh"])
    cafe = next(s for s in single["stops"] if s["id"] == "cafe-innere-stadt")
    assert "09:00" <= cafe["service_start"][11:16] <= "09:30"


def test_plans_name_the_stop_no_order_reaches_in_time(client):
    # The depot is 20 minutes from Josefstadt: a window closing at 09:05 cannot be met.
    body = windowed_plan({"bio-josefstadt": [{"start": "08:00", "end": "09:05"}]})
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 422 and response.headers["content-type"] == PROBLEM
    index = [s["id"] for s in body["stops"]].index("bio-josefstadt")
    assert [e["field"] for e in response.json()["errors"]] == [f"stops[{index}].time_windows"]
    assert "09:05" in response.json()["detail"]


def test_plans_in_the_clients_order_that_miss_a_window_are_a_422(client):
    body = windowed_plan({"billa-landstrasse": [{"start": "08:00", "end": "09:10"}]})
    body["keep_order"] = True
    body["stops"].append(body["stops"].pop(0))  # billa-landstrasse last: reached far too late
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 422
    assert response.json()["errors"][0]["field"] == f"stops[{len(body['stops']) - 1}].time_windows"


def test_stops_no_van_can_serve_are_listed_not_errors(client):
    body = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    body["stops"][0]["delivery_kg"] = 5000
    body["stops"][1]["time_windows"] = [{"start": "04:00", "end": "05:00"}]
    response = client.post("/v1/fleet-plans", json=body)
    assert response.status_code == 200
    unassigned = {u["id"]: u["reason"] for u in response.json()["unassigned"]}
    assert unassigned == {body["stops"][0]["id"]: "capacity", body["stops"][1]["id"]: "time_window"}
    assert_routes_hold(response.json(), body)
    assert response.json()["solver"]["status"] == "feasible"


def test_a_fleet_that_serves_no_stop_says_so(client):
    body = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    for stop in body["stops"]:
        stop["time_windows"] = [{"start": "04:00", "end": "05:00"}]  # before every shift
    answer = client.post("/v1/fleet-plans", json=body).json()
    assert answer["routes"] == [] and len(answer["unassigned"]) == len(body["stops"])
    assert answer["solver"]["status"] == "no_solution"


@pytest.mark.slow
def test_more_vans_than_the_server_plans_is_a_413_naming_vehicles():
    body = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    small = app_client(max_vehicles=1)
    response = small.post("/v1/fleet-plans", json=body)
    assert response.status_code == 413
    assert response.json()["errors"][0]["field"] == "vehicles"
    assert "at most 1" in response.json()["detail"]


def _with(change) -> dict:
    body = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    change(body)
    return body


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda b: b["vehicles"][1].update(shift_end="06:00"), "vehicles[1].shift_end"),
        (lambda b: b["vehicles"][0].update(shift_start="7:00"), "vehicles[0].shift_start"),
        (lambda b: b["vehicles"][0].update(shift_start=700), "vehicles[0].shift_start"),
        (lambda b: b["vehicles"][1].update(id="van-1"), "vehicles[1].id"),
        (  # 40 t in a 3.5 t van: its rated payload is 600 kg
            lambda b: b["vehicles"][1].update(
                vehicle={"preset": "ev-van-3.5t-reefer"}, payload_kg=40_000
            ),
            "vehicles[1].payload_kg",
        ),
        (
            lambda b: b["vehicles"][0]["vehicle"].update(preset="tesla"),
            "vehicles[0].vehicle.preset",
        ),
        (
            lambda b: b["vehicles"][1]["battery"].update(min_soc=1.5),
            "vehicles[1].battery.min_soc",
        ),
        (lambda b: b.update(vehicles=[]), "vehicles"),
        (lambda b: b.update(vehicles=b["vehicles"] * 501), "vehicles"),  # over 1,000
        (
            lambda b: b["stops"][2].update(time_windows=[{"start": "10:00", "end": "09:00"}]),
            "stops[2].time_windows[0].end",
        ),
        (
            lambda b: b["stops"][2].update(
                time_windows=[
                    {"start": "08:00", "end": "10:00"},
                    {"start": "09:00", "end": "11:00"},
                ]
            ),
            "stops[2].time_windows[1].start",
        ),
        (
            lambda b: b["stops"][2].update(time_windows=[{"start": "08:00", "end": "24:00"}]),
            "stops[2].time_windows[0].end",
        ),
        (lambda b: b["stops"][3].update(id=b["stops"][0]["id"]), "stops[3].id"),
        (lambda b: b.update(stops=[]), "stops"),
        (lambda b: b.update(minimize_vehicles="yes"), "minimize_vehicles"),
        (lambda b: b.update(time_limit_s=0), "time_limit_s"),
        (lambda b: b.update(date="2026-02-30"), "date"),
        (
            lambda b: b["vehicles"][1].update(pinned_stops=["nowhere"]),
            "vehicles[1].pinned_stops[0]",
        ),
        (
            lambda b: [v.update(pinned_stops=[b["stops"][0]["id"]]) for v in b["vehicles"]],
            "vehicles[1].pinned_stops[0]",
        ),
        (lambda b: b["vehicles"][0].update(pinned_stops=[""]), "vehicles[0].pinned_stops[0]"),
        (lambda b: b["vehicles"][0].update(pinned_stops="spar-wieden"), "vehicles[0].pinned_stops"),
    ],
)
def test_bad_fleet_plans_name_the_field(client, change, field):
    response = client.post("/v1/fleet-plans", json=_with(change))
    assert response.status_code == 422, response.text
    assert response.headers["content-type"] == PROBLEM
    assert field in [e["field"] for e in response.json()["errors"]], response.json()


def test_a_dst_gap_shift_start_is_named(client):
    body = _with(lambda b: b.update(date="2026-03-29"))
    body["vehicles"][0]["shift_start"] = "02:30"
    response = client.post("/v1/fleet-plans", json=body)
    assert response.status_code == 422
    assert response.json()["errors"][0]["field"] == "vehicles[0].shift_start"


def test_stops_pinned_to_the_second_van_are_its_own(client):
    """The example's day is one van's (van-1, listed first); two stops pinned to van-2 make it
    drive them, and only them or more — van-1 serves neither."""
    unpinned = client.post("/v1/fleet-plans", json=FLEET_PLAN_EXAMPLE).json()
    assert [r["vehicle_id"] for r in unpinned["routes"]] == ["van-1"]
    pins = ["spar-wieden", "bio-josefstadt"]
    body = _with(lambda b: b["vehicles"][1].update(pinned_stops=pins))
    response = client.post("/v1/fleet-plans", json=body)
    assert response.status_code == 200, response.text
    answer = response.json()
    assert_routes_hold(answer, body)
    by = {s["id"]: r["vehicle_id"] for r in answer["routes"] for s in r["stops"]}
    assert [by[p] for p in pins] == ["van-2", "van-2"] and answer["unassigned"] == []
