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
        # the audit: 40 t aboard a van that left with 550 kg was simulated
        ({"payload_kg": 40_000}, "start_state.payload_kg"),
        ({"driving_since_break_s": -1}, "start_state.driving_since_break_s"),
        # the audit: the nanoseconds were cut without a word
        ({"time": "2026-07-15T12:10:00.123456789+02:00"}, "start_state.time"),
    ],
)
def test_bad_start_states_are_422_naming_the_field(client, change, field):
    body = PLAN_EXAMPLE | {"start_state": STATE | change}
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 422
    errors = response.json()["errors"]
    assert any(e["field"] == field for e in errors), errors
    # a job is refused at submission as the endpoint refuses it, not 2 s later
    job = client.post("/v1/jobs", json={"type": "plan", "request": body})
    assert job.status_code == 422, job.text[:300]
    assert any(e["field"] == f"request.{field}" for e in job.json()["errors"]), job.json()


@pytest.mark.parametrize("where", ["stops", "depot"])
def test_no_place_of_a_round_under_way_is_called_start(client, where):
    """The audit: a stop called "start" made the tour read ["start", "start", …]."""
    body = PLAN_EXAMPLE | {"start_state": STATE}
    if where == "stops":
        body["stops"] = [PLAN_EXAMPLE["stops"][0] | {"id": "start"}, *PLAN_EXAMPLE["stops"][1:]]
        field = "stops[0].id"
    else:
        body["depot"] = PLAN_EXAMPLE["depot"] | {"id": "start"}
        field = "depot.id"
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 422
    assert [e["field"] for e in response.json()["errors"]] == [field]
    fleet = fleet_from_noon({}) | {"stops": body["stops"], "depot": body["depot"]}
    refused = client.post("/v1/fleet-plans", json=fleet)
    assert refused.status_code == 422 and refused.json()["errors"][0]["field"] == field
    # without a start state the name is free
    plain = {key: value for key, value in body.items() if key != "start_state"}
    assert client.post("/v1/plans", json=plain).status_code == 200


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


def test_a_fleet_van_under_way_that_cannot_reach_the_depot_says_so(client):
    """The one fleet route below its reserve: a van already under way too far from the depot
    for its charge. The README promises no route below the reserve: the answer says why."""
    body = fleet_from_noon({"soc": 0.165, "lat": 48.05, "lon": 16.10})
    response = client.post("/v1/fleet-plans", json=body)
    assert response.status_code == 200, response.text[:300]
    answer = response.json()
    stranded = {r["vehicle_id"]: r for r in answer["routes"]}["van-2"]
    assert not stranded["battery"]["feasible"]
    assert any("van-2 is under way with too little charge" in w for w in answer["warnings"])


def test_reloads_under_way_count_what_is_aboard(client):
    """A van under way with 300 kg aboard and max_trips 3 of 550 kg carries 1,400 kg: stops
    taking 2,400 kg are refused naming the stops and the trips (the audit: it was told a
    round with time windows does not reload); taking 1,300 kg it comes back to reload."""
    heavy = [stop | {"delivery_kg": 300} for stop in PLAN_EXAMPLE["stops"]]
    body = PLAN_EXAMPLE | {"stops": heavy, "max_trips": 3, "start_state": STATE}
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 422
    (error,) = response.json()["errors"]
    assert error["field"] == "stops" and "1400 kg 3 trips carry" in error["message"]
    fitting = [stop | {"delivery_kg": 260} for stop in PLAN_EXAMPLE["stops"][:5]]
    planned = client.post("/v1/plans", json=body | {"stops": fitting})
    assert planned.status_code == 200, planned.text[:300]
    assert len(planned.json()["reloads"]) == 2  # 260 | 520 | 520 kg
