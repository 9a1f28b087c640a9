"""Planning the rest of a day over HTTP: from the van's state to the depot, and the states a
client may get wrong."""

import pytest

from app.examples import PLAN_EXAMPLE

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
