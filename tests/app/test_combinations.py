"""Every combination of a day's rules on both endpoints (issue: one engine for the day): time
windows, returns to reload, a van under way, the depot's charger and one on the way, drivers'
breaks and shifts, planned together and checked against the answer's own simulated day — each
stop inside a window, no trip heavier than the payload, the tour from where the van is."""

from __future__ import annotations

import datetime as dt
from typing import Any

import pytest

from app.examples import EN_ROUTE_CHARGING_EXAMPLE, FLEET_PLAN_EXAMPLE, PLAN_EXAMPLE

WINDOWS = {
    "spar-wieden": [{"start": "09:00", "end": "11:00"}],
    "billa-landstrasse": [{"start": "10:00", "end": "12:00"}],
    "billa-leopoldstadt": [{"start": "12:00", "end": "15:00"}],
}
#: 8 stops of 120 kg: 960 kg, more than any one load below.
STOPS = [
    stop
    | {"delivery_kg": 120}
    | ({"time_windows": WINDOWS[stop["id"]]} if stop["id"] in WINDOWS else {})
    for stop in PLAN_EXAMPLE["stops"]
]
DEPOT = PLAN_EXAMPLE["depot"] | {
    "charger": {"power_kw": 22, "points": 1, "price_per_kwh": 0.3, "plug_minutes": 2}
}
CHARGERS = EN_ROUTE_CHARGING_EXAMPLE["chargers"][:1]
UNDER_WAY = {
    "lat": 48.2006,
    "lon": 16.3862,
    "time": "2026-07-15T09:30:00+02:00",
    "soc": 0.6,
    "payload_kg": 200,
}


def check_rules(
    route: dict[str, Any], body_stops: list[dict[str, Any]], payload_kg: float, aboard_kg: float
) -> None:
    """The answer keeps the rules it was given: each stop served inside one of its windows,
    no trip (between returns to the depot) delivering more than the van carries on it — what
    is aboard for the first, its payload after each reload —, the battery never below its
    reserve."""
    by_id = {stop["id"]: stop for stop in body_stops}
    for stop in route["stops"]:
        windows = by_id[stop["id"]].get("time_windows")
        if windows:
            start = dt.datetime.fromisoformat(stop["service_start"]).time()
            assert any(
                dt.time.fromisoformat(w["start"]) <= start <= dt.time.fromisoformat(w["end"])
                for w in windows
            ), (stop["id"], start)
    reloaded = {reload["arrive"] for reload in route["reloads"]}
    trips: list[float] = [0.0]
    for place, leg in zip(route["tour"][1:-1], route["legs"], strict=False):
        if leg["arrive"] in reloaded:  # back at the depot to reload
            trips.append(0.0)
        elif place in by_id:
            trips[-1] += by_id[place]["delivery_kg"]
    assert trips[0] <= aboard_kg and all(trip <= payload_kg for trip in trips[1:]), trips
    assert len(trips) == len(route["reloads"]) + 1
    assert route["battery"]["feasible"]
    assert route["battery"]["min_soc"] >= route["battery"]["reserve_soc"] - 1e-9
    check_visits(route)


def check_visits(route: dict[str, Any]) -> None:
    """The day as one list agrees with its stops, charges, reloads and breaks: each in time
    order, at the same moments and states of charge, and the driving so far is the legs'."""
    visits = route["visits"]
    assert [v["arrive"] for v in visits] == sorted(v["arrive"] for v in visits)
    by_kind = {
        kind: [v for v in visits if v["kind"] == kind]
        for kind in ("stop", "charge", "reload", "break")
    }
    stops = [
        {
            "id": s["id"],
            "arrive": s["arrival"],
            "start": s["service_start"],
            "depart": s["departure"],
            "soc_arrival": s["soc_arrival"],
            "soc_departure": s["soc_departure"],
            "payload_after_kg": s["payload_after_kg"],
        }
        for s in route["stops"]
    ]
    assert [{k: v[k] for k in stops[0]} for v in by_kind["stop"]] == stops
    charges = [(c["charger_id"], c["arrive"], c["depart"]) for c in route["charges"]]
    assert [(v["id"], v["arrive"], v["depart"]) for v in by_kind["charge"]] == charges
    reloaded = {v["arrive"] for v in by_kind["reload"]} | {
        v["arrive"]
        for v in by_kind["charge"]
        if v["arrive"] in {r["arrive"] for r in route["reloads"]}
    }
    assert sorted(reloaded) == sorted(r["arrive"] for r in route["reloads"])
    assert [(v["arrive"], v["depart"]) for v in by_kind["break"]] == [
        (b["start"], b["end"]) for b in route["breaks"]
    ]
    for visit in by_kind["stop"]:
        driven = sum(leg["duration_s"] for leg in route["legs"] if leg["arrive"] <= visit["arrive"])
        assert visit["driving_s"] == pytest.approx(driven)


@pytest.fixture
def round_body() -> dict[str, Any]:
    return PLAN_EXAMPLE | {
        "stops": STOPS,
        "depot": DEPOT,
        "chargers": CHARGERS,
        "max_trips": 3,
        "payload_kg": 400,
        "reload_minutes": 15,
        "battery": {"usable_capacity_kwh": 20, "initial_soc": 0.95, "min_soc": 0.15},
        "breaks": "eu-561",
    }


def test_a_round_with_windows_reloads_chargers_and_breaks(client, round_body):
    """960 kg on a 400 kg van with three windows: it comes back to reload twice (each trip
    three stops at most) and serves every stop in its window; these were a 422."""
    response = client.post("/v1/plans", json=round_body)
    assert response.status_code == 200, response.text[:400]
    plan = response.json()
    assert sorted(s["id"] for s in plan["stops"]) == sorted(s["id"] for s in STOPS)
    assert len(plan["reloads"]) == 2
    check_rules(plan, STOPS, 400, 400)


def test_a_round_under_way_with_windows_comes_back_to_reload(client, round_body):
    """From the van's position with 200 kg aboard (one stop's worth and a bit), the rest of
    the day: the first trip carries what is aboard, later ones a full load."""
    body = round_body | {"stops": STOPS[1:], "start_state": UNDER_WAY}
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 200, response.text[:400]
    plan = response.json()
    assert plan["tour"][0] == "start" and plan["tour"][-1] == DEPOT["id"]
    assert sorted(s["id"] for s in plan["stops"]) == sorted(s["id"] for s in STOPS[1:])
    assert plan["reloads"]
    check_rules(plan, STOPS, 400, 400)


def test_a_round_under_way_refuses_what_its_trips_cannot_carry(client, round_body):
    body = round_body | {"start_state": UNDER_WAY, "max_trips": 2}  # 200 + 400 < 960 kg
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 422
    (error,) = response.json()["errors"]
    assert error["field"] == "stops" and "2 trips" in error["message"]


def test_a_fleet_with_windows_reloads_a_van_under_way_shifts_breaks_and_chargers(client):
    """The same stops for two vans: one from the depot with two trips of 300 kg and EU breaks,
    one under way with 200 kg aboard and three trips of 250 kg, both with shifts, the depot's
    charger and one on the way."""
    first, second = FLEET_PLAN_EXAMPLE["vehicles"]
    vans = [
        first
        | {"max_trips": 2, "payload_kg": 300, "breaks": "eu-561"}
        | {"battery": {"usable_capacity_kwh": 30}},
        second
        | {"max_trips": 3, "payload_kg": 250, "start_state": UNDER_WAY}
        | {"battery": {"usable_capacity_kwh": 30, "min_soc": 0.15}},
    ]
    body = FLEET_PLAN_EXAMPLE | {
        "stops": STOPS,
        "depot": DEPOT,
        "chargers": CHARGERS,
        "vehicles": vans,
        "time_limit_s": 3,
    }
    response = client.post("/v1/fleet-plans", json=body)
    assert response.status_code == 200, response.text[:400]
    answer = response.json()
    assert answer["unassigned"] == []
    routes = {route["vehicle_id"]: route for route in answer["routes"]}
    assert sorted(s["id"] for r in routes.values() for s in r["stops"]) == sorted(
        s["id"] for s in STOPS
    )
    assert routes["van-2"]["tour"][0] == "start"
    for route in answer["routes"]:
        van = next(v for v in vans if v["id"] == route["vehicle_id"])
        aboard = van.get("start_state", {}).get("payload_kg", van["payload_kg"])
        check_rules(route, STOPS, van["payload_kg"], aboard)
        back = dt.datetime.fromisoformat(route["legs"][-1]["arrive"]).time()
        assert back <= dt.time.fromisoformat(van["shift_end"])
    # 960 kg on 300 × 2 + 200 + 250 × 2 kg: both vans come back to reload
    assert all(route["reloads"] for route in routes.values())


def test_a_fleet_that_must_charge_and_reload_serves_every_stop(client):
    """The same fleet with 10 kWh batteries: neither van lasts the day without charging, and
    both come back to reload — the charging search plans the trips, the charges and the
    returns together (a return to reload beside a charge at the depot is one stop)."""
    first, second = FLEET_PLAN_EXAMPLE["vehicles"]
    vans = [
        first
        | {"max_trips": 2, "payload_kg": 300, "breaks": "eu-561"}
        | {"battery": {"usable_capacity_kwh": 10}},
        second
        | {"max_trips": 3, "payload_kg": 250, "start_state": UNDER_WAY}
        | {"battery": {"usable_capacity_kwh": 10, "min_soc": 0.15}},
    ]
    body = FLEET_PLAN_EXAMPLE | {
        "stops": STOPS,
        "depot": DEPOT,
        "chargers": CHARGERS,
        "vehicles": vans,
        "time_limit_s": 3,
    }
    response = client.post("/v1/fleet-plans", json=body)
    assert response.status_code == 200, response.text[:400]
    answer = response.json()
    assert answer["unassigned"] == []
    assert sum(len(route["charges"]) for route in answer["routes"]) >= 1
    for route in answer["routes"]:
        van = next(v for v in vans if v["id"] == route["vehicle_id"])
        aboard = van.get("start_state", {}).get("payload_kg", van["payload_kg"])
        check_rules(route, STOPS, van["payload_kg"], aboard)
