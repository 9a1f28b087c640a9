"""Planning the rest of a day over HTTP: from the van's state to the depot, and the states a
client may get wrong."""

import pytest

from app.examples import FLEET_PLAN_EXAMPLE, PLAN_EXAMPLE

STATE = {
    "lat": 48.2006,
    "lon": 16.3862,
    "time": "2026-07-15T12:10:00+02:00",
    "soc": 0.6,
    "box_temperature_c": 5.5,
    "payload_kg": 300,
    "driving_since_break_s": 3600,
}


def test_the_rest_of_the_day_from_the_van(client):
    body = PLAN_EXAMPLE | {"stops": PLAN_EXAMPLE["stops"][1:], "start_state": STATE}
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 200
    plan = response.json()
    assert plan["tour"][0] == "start" and plan["tour"][-1] == PLAN_EXAMPLE["depot"]["id"]
    assert plan["legs"][0]["depart"] == "2026-07-15T12:10:00+02:00"
    assert plan["legs"][0]["soc_start"] == pytest.approx(0.6)
    assert plan["totals"]["grid_kwh"] == 0.0


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"soc": 1.5}, "start_state.soc"),
        ({"soc": "NaN"}, "start_state.soc"),
        ({"soc": 0.155}, "start_state.soc"),  # within 0.01 of the example's reserve 0.15
        ({"time": "2026-07-16T12:10:00+02:00"}, "start_state.time"),
        ({"time": "2026-07-15T12:10:00"}, "start_state.time"),  # no UTC offset
        ({"lat": 91}, "start_state.lat"),
        ({"payload_kg": 10}, "start_state.payload_kg"),
        ({"driving_since_break_s": -1}, "start_state.driving_since_break_s"),
    ],
)
def test_bad_start_states_are_422_naming_the_field(client, change, field):
    body = PLAN_EXAMPLE | {"start_state": STATE | change}
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 422
    errors = response.json()["errors"]
    assert any(e["field"] == field for e in errors), errors


def fleet_from_noon(change: dict) -> dict:
    """The fleet example with its second van under way at noon."""
    (first, second) = FLEET_PLAN_EXAMPLE["vehicles"]
    state = STATE | {"payload_kg": 200, "time": "2026-07-15T10:10:00+02:00"} | change
    return FLEET_PLAN_EXAMPLE | {"vehicles": [first, second | {"start_state": state}]}


def test_a_fleet_van_plans_the_rest_of_its_day_from_where_it_is(client):
    response = client.post("/v1/fleet-plans", json=fleet_from_noon({}))
    assert response.status_code == 200
    routes = {route["vehicle_id"]: route for route in response.json()["routes"]}
    under_way = routes["van-2"]
    assert (
        under_way["tour"][0] == "start"
        and under_way["tour"][-1] == FLEET_PLAN_EXAMPLE["depot"]["id"]
    )
    assert under_way["legs"][0]["depart"] == "2026-07-15T10:10:00+02:00"
    assert under_way["legs"][0]["soc_start"] == pytest.approx(0.6)
    if "van-1" in routes:  # the other leaves the depot
        assert routes["van-1"]["tour"][0] == FLEET_PLAN_EXAMPLE["depot"]["id"]


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"time": "2026-07-15T15:00:00+02:00"}, "time"),  # after the shift's 14:30
        ({"time": "2026-07-15T05:00:00+02:00"}, "time"),
        ({"soc": 0.155}, "soc"),
        ({"soc": 2}, "soc"),
        ({"payload_kg": 401}, "payload_kg"),  # the van carries 400
        ({"lat": "NaN"}, "lat"),
    ],
)
def test_bad_fleet_start_states_are_422_naming_the_van(client, change, field):
    response = client.post("/v1/fleet-plans", json=fleet_from_noon(change))
    assert response.status_code == 422
    errors = response.json()["errors"]
    assert any(e["field"] == f"vehicles[1].start_state.{field}" for e in errors), errors
