import copy
import datetime as dt
import itertools

import pytest

from app.examples import PLAN_EXAMPLE

PROBLEM = "application/problem+json"


def test_swagger_example_runs_as_is(client):
    response = client.post("/v1/plans", json=PLAN_EXAMPLE)
    assert response.status_code == 200
    body = response.json()
    ids = [s["id"] for s in PLAN_EXAMPLE["stops"]]
    assert body["tour"][0] == body["tour"][-1] == "depot-simmering"
    assert sorted(body["tour"][1:-1]) == sorted(ids)
    assert len(body["legs"]) == 9 and len(body["stops"]) == 8
    leg = body["legs"][0]
    assert set(leg) >= {
        "from_id",
        "to_id",
        "depart",
        "arrive",
        "distance_m",
        "duration_s",
        "street_type",
        "grade",
        "energy_kwh",
        "soc_start",
        "soc_end",
    }
    assert leg["depart"] == "2026-07-15T09:00:00+02:00"
    assert set(leg["energy_kwh"]) == {"traction", "auxiliaries", "cabin", "refrigeration", "total"}
    totals = body["totals"]["energy_kwh"]
    assert totals["total"] == pytest.approx(
        sum(leg["energy_kwh"]["total"] for leg in body["legs"])
        + sum(stop["energy_kwh"]["total"] for stop in body["stops"])
    )
    assert body["battery"]["feasible"] is True and body["battery"]["first_infeasible_leg"] is None
    assert body["weather"] == {
        "t_min_c": 18,
        "t_max_c": 31,
        "source": "request",
        "days": [{"date": "2026-07-15", "t_min_c": 18, "t_max_c": 31}],
    }
    assert body["distance_source"] == "estimate" and body["attribution"] is None
    assert body["warnings"] == [] and body["totals"]["grid_kwh"] > 0
    assert all(leg["geometry"] is None for leg in body["legs"])
    assert body["solver"]["status"] == "optimal" and body["solver"]["objective"] == "energy"
    assert body["stops"][-1]["payload_after_kg"] == pytest.approx(550 - 210)


def test_overrides_change_the_answer(client):
    heavy = copy.deepcopy(PLAN_EXAMPLE) | {"keep_order": True}
    light = heavy | {"vehicle": {"preset": "paper-generic", "mass_kg": 1200}}
    a = client.post("/v1/plans", json=heavy).json()
    b = client.post("/v1/plans", json=light).json()
    assert b["totals"]["energy_kwh"]["traction"] < a["totals"]["energy_kwh"]["traction"]
    assert a["solver"]["status"] == "fixed_order"


def test_small_battery_is_reported_infeasible(client):
    body = client.post(
        "/v1/plans", json=PLAN_EXAMPLE | {"battery": {"usable_capacity_kwh": 4, "min_soc": 0.2}}
    ).json()
    assert body["battery"]["feasible"] is False
    assert isinstance(body["battery"]["first_infeasible_leg"], int)
    assert body["battery"]["required_capacity_kwh"] > 4


def _stops(n):
    return [{"id": f"S{i}", "lat": 48.2 + i * 1e-3, "lon": 16.37} for i in range(n)]


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"depot": {"lat": 200, "lon": 16}}, "depot.lat"),
        ({"stops": []}, "stops"),
        (
            {
                "stops": [
                    {"id": "A", "lat": 48.2, "lon": 16.3},
                    {"id": "A", "lat": 48.3, "lon": 16.3},
                ]
            },
            "stops[1].id",
        ),
        ({"vehicle": {"mass_kg": -5}}, "vehicle.mass_kg"),
        ({"vehicle": {"preset": "tesla-semi"}}, "vehicle.preset"),
        ({"vehicle": {"drivetrain_efficiency": 1.5}}, "vehicle.drivetrain_efficiency"),
        ({"cargo_box": {"setpoint_c": 10}}, "cargo_box.product_limit_c"),
        ({"battery": {"initial_soc": 0.1, "min_soc": 0.2}}, "battery.min_soc"),
        ({"date": "2026-13-45"}, "date"),
        ({"start_time": "25:00"}, "start_time"),
        ({"timezone": "Mars/Olympus"}, "timezone"),
        ({"objective": "fun"}, "objective"),
        ({"payload_kg": -1}, "payload_kg"),
        ({"vehicle": {"preset": "ev-van-3.5t-reefer"}, "payload_kg": 40_000}, "payload_kg"),
        ({"vehicle": {"gross_mass_kg": 2000}, "payload_kg": 321}, "payload_kg"),
        ({"vehicle": {"gross_mass_kg": 1500}}, "vehicle.gross_mass_kg"),
        ({"weather": {"t_min_c": 30, "t_max_c": 10}}, "weather.t_max_c"),
        (
            {
                "stops": [
                    {"id": "A", "lat": 48.2, "lon": 16.3, "service_time_s": 60, "door_open_s": 90}
                ]
            },
            "stops[0].door_open_s",
        ),
        ({"matrix": {"distances_m": [[0]], "durations_s": [[0]]}}, "matrix.distances_m"),
        ({"unknown_field": 1}, "unknown_field"),
    ],
)
def test_bad_plans_get_a_problem_naming_the_field(client, change, field):
    response = client.post("/v1/plans", json=PLAN_EXAMPLE | change)
    assert response.status_code == 422
    assert response.headers["content-type"] == PROBLEM
    body = response.json()
    assert body["status"] == 422 and body["title"] and body["detail"]
    assert any(e["field"] == field for e in body["errors"]), body["errors"]


def test_more_stops_than_the_server_plans_is_a_413_naming_stops(client):
    response = client.post("/v1/plans", json=PLAN_EXAMPLE | {"stops": _stops(41)})
    assert response.status_code == 413
    assert response.json()["errors"][0]["field"] == "stops"
    assert "at most 40" in response.json()["detail"]


def test_nan_and_malformed_json(client):
    nan = client.post(
        "/v1/plans",
        content=b'{"date": "2026-07-15", "depot": {"lat": NaN, '
        b'"lon": 16}, "stops": [{"id": "a", "lat": 48, "lon": 16}]}',
        headers={"content-type": "application/json"},
    )
    assert nan.status_code == 422 and nan.json()["errors"][0]["field"] == "depot.lat"
    broken = client.post(
        "/v1/plans", content=b'{"date": ', headers={"content-type": "application/json"}
    )
    assert broken.status_code == 422 and broken.headers["content-type"] == PROBLEM


def test_oversized_body_is_413(client):
    huge = PLAN_EXAMPLE | {"stops": _stops(10_000)}  # > 200 kB, the test limit
    response = client.post("/v1/plans", json=huge)
    assert response.status_code == 413 and response.json()["title"] == "Request too large"


def test_time_limit_is_capped_by_the_server(client):
    body = client.post("/v1/plans", json=PLAN_EXAMPLE | {"time_limit_s": 500}).json()
    assert body["solver"]["runtime_s"] < 0.5 + 0.2


def test_the_day_profile_is_the_simulation_minute_by_minute(client):
    """include_profile: a point a minute from departure to return, the state of charge of the
    legs at their ends, the energy summed to the totals, the dynamic box's temperature."""
    body = copy.deepcopy(PLAN_EXAMPLE) | {"include_profile": True}
    body["vehicle"] = {"preset": "ev-van-3.5t-reefer"}  # a dynamic box
    body["battery"] = {"min_soc": 0.12}
    answer = client.post("/v1/plans", json=body).json()
    profile = answer["profile"]
    times = [dt.datetime.fromisoformat(t) for t in profile["time"]]
    assert times[0] == dt.datetime.fromisoformat(answer["legs"][0]["depart"])
    assert times[-1] == dt.datetime.fromisoformat(answer["legs"][-1]["arrive"])
    steps = {b - a for a, b in itertools.pairwise(times[:-1])}
    assert steps == {dt.timedelta(minutes=1)}
    assert len(profile["soc"]) == len(profile["box_temperature_c"]) == len(times)
    assert profile["soc"][0] == pytest.approx(answer["legs"][0]["soc_start"])
    assert profile["soc"][-1] == pytest.approx(answer["battery"]["final_soc"])
    assert min(profile["soc"]) == pytest.approx(answer["battery"]["min_soc"], abs=2e-3)
    for consumer, total in answer["totals"]["energy_kwh"].items():
        assert profile["energy_kwh"][consumer][-1] == pytest.approx(total, rel=1e-6)
    for consumer in ("auxiliaries", "cabin", "refrigeration"):  # traction regenerates
        series = profile["energy_kwh"][consumer]
        assert all(b >= a - 1e-12 for a, b in itertools.pairwise(series))
    assert max(profile["box_temperature_c"]) == pytest.approx(
        answer["box"]["max_temperature_c"], abs=0.05
    )
    assert answer["battery"]["reserve_soc"] == 0.12
    assert answer["box"]["product_limit_c"] == 7.0
    assert client.post("/v1/plans", json=PLAN_EXAMPLE).json()["profile"] is None


@pytest.mark.slow
def test_a_stop_far_from_the_depot_is_planned_with_a_warning_naming_it(client):
    from app.examples import FLEET_PLAN_EXAMPLE
    from tests.app.apps import app_client

    # Vienna's lat and lon swapped put a shop at 16.4 °N, 48.2 °E: about 4,100 km away (great
    # circle from the depot at 48.17 °N, 16.42 °E, by the haversine)
    stops = copy.deepcopy(PLAN_EXAMPLE["stops"])
    stops[3] |= {"lat": stops[3]["lon"], "lon": stops[3]["lat"]}
    answer = client.post("/v1/plans", json=PLAN_EXAMPLE | {"stops": stops}).json()
    far = [w for w in answer["warnings"] if "from the depot" in w]
    assert len(far) == 1 and far[0].startswith(f"stops[3] ('{stops[3]['id']}') is 4,")
    assert "more than 300 km" in far[0]
    fleet = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    fleet["stops"][0] |= {"lat": 16.4, "lon": 48.2}
    warned = client.post("/v1/fleet-plans", json=fleet).json()["warnings"]
    assert [w[:9] for w in warned if "from the depot" in w] == ["stops[0] "]
    # the day as it is, nothing to warn of; a server that expects stops within 2 km warns
    # of each farther one
    plain = client.post("/v1/plans", json=PLAN_EXAMPLE).json()["warnings"]
    assert not any("from the depot" in w for w in plain)
    near = app_client(far_stop_km=2.0).post("/v1/plans", json=PLAN_EXAMPLE).json()["warnings"]
    assert 0 < sum("from the depot" in w for w in near) <= len(PLAN_EXAMPLE["stops"])


@pytest.mark.parametrize("usable_kwh", [0.1, 2.0])
def test_a_battery_that_runs_empty_says_where_when_and_what_it_lacks(client, usable_kwh):
    """An audit read min_soc −18.2 on a 0.1 kWh battery: a battery that cannot exist. Where
    the charge reaches 0 — the leg or the visit, the moment by its fall — and the energy the
    day lacks are said beside it (a figure of the answer's own: −min_soc × the capacity)."""
    body = PLAN_EXAMPLE | {"battery": {"usable_capacity_kwh": usable_kwh}}
    battery = client.post("/v1/plans", json=body).json()
    empty = battery["battery"]["runs_empty"]
    legs, min_soc = battery["legs"], battery["battery"]["min_soc"]
    assert min_soc < 0 and empty is not None
    assert empty["missing_kwh"] == pytest.approx(
        -min_soc * battery["battery"]["usable_capacity_kwh"]
    )
    # the first leg or visit whose charge ends below 0, at its moment by linear interpolation
    spans = [(g["depart"], g["arrive"], g["soc_start"], g["soc_end"], g) for g in legs] + [
        (v["arrive"], v["depart"], v["soc_arrival"], v["soc_departure"], v)
        for v in battery["visits"]
    ]
    begin, end, soc_0, soc_1, where = min(
        (s for s in spans if s[3] < 0), key=lambda s: dt.datetime.fromisoformat(s[0])
    )
    first, last, at = (dt.datetime.fromisoformat(t) for t in (begin, end, empty["at"]))
    assert first <= at <= last
    if soc_0 > 0:
        share = soc_0 / (soc_0 - soc_1)
        assert (at - first).total_seconds() == pytest.approx(
            (last - first).total_seconds() * share, abs=1e-3
        )
    expected = (
        f"between '{where['from_id']}' and '{where['to_id']}'" if "from_id" in where
        else f"at '{where['id']}'"
    )  # fmt: skip
    assert empty["where"] == expected


def test_a_battery_that_holds_a_charge_has_no_empty_moment(client):
    answer = client.post("/v1/plans", json=PLAN_EXAMPLE).json()
    assert answer["battery"]["min_soc"] > 0 and answer["battery"]["runs_empty"] is None
