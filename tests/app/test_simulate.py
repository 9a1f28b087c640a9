import itertools

import pytest

from app.examples import SIMULATE_EXAMPLE, SIMULATE_TRACE_EXAMPLE


def test_cycle_example_runs_as_is(client):
    body = client.post("/v1/simulate", json=SIMULATE_EXAMPLE).json()
    assert body["distance_m"] == pytest.approx(8000)
    per_km = body["consumption_wh_per_km"]
    assert per_km["total"] == pytest.approx(body["energy_kwh"]["total"] * 1e6 / 8000)
    assert body["series"] is None and body["weather"]["source"] == "request"


def test_trace_example_with_series(client):
    body = client.post("/v1/simulate", json=SIMULATE_TRACE_EXAMPLE).json()
    series = body["series"]
    n = len(SIMULATE_TRACE_EXAMPLE["speed_mps"])
    assert len(series["time_s"]) == len(series["soc"]) == len(series["power_w"]["traction"]) == n
    assert series["power_w"]["auxiliaries"] == [0.0] + [400.0] * (n - 1)
    # distance: trapezoid of the samples, 1 s apart
    speeds = SIMULATE_TRACE_EXAMPLE["speed_mps"]
    assert body["distance_m"] == pytest.approx(
        sum((a + b) / 2 for a, b in itertools.pairwise(speeds))
    )
    assert series["soc"][0] == 1.0 and series["soc"][-1] < 1.0


def test_almost_standing_still_has_no_consumption_per_km(client):
    body = client.post(
        "/v1/simulate", json=SIMULATE_TRACE_EXAMPLE | {"speed_mps": [0, 1e-300, 0]}
    ).json()
    assert body["consumption_wh_per_km"] == {
        "traction": None,
        "auxiliaries": None,
        "cabin": None,
        "refrigeration": None,
        "total": None,
    }


def test_standstill_has_no_consumption_per_km(client):
    body = client.post(
        "/v1/simulate", json=SIMULATE_TRACE_EXAMPLE | {"speed_mps": [0, 0, 0]}
    ).json()
    assert body["consumption_wh_per_km"]["total"] is None
    assert body["energy_kwh"]["traction"] == 0


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"speed_mps": [0, -1, 0]}, "speed_mps[1]"),
        ({"speed_mps": [0, 1e9, 0]}, "speed_mps[1]"),
        ({"speed_mps": [0]}, "speed_mps"),
        ({"speed_mps": [0.0] * 5001}, "speed_mps"),
        ({"grade": [0, 0.1]}, "grade"),
        ({"grade": 0.9}, "grade[0]"),
        ({"dt_s": 0}, "dt_s"),
        ({"start": "2026-01-20T08:30:00"}, "start"),
        ({"location": {"lat": 91, "lon": 0}}, "location.lat"),
        ({"cycle": {"distance_m": 1000}}, "cycle"),
        ({"door_openings": [{"start_s": 100, "duration_s": 5}]}, "door_openings[0].start_s"),
    ],
)
def test_bad_traces_name_the_field(client, change, field):
    response = client.post("/v1/simulate", json=SIMULATE_TRACE_EXAMPLE | change)
    assert response.status_code == 422
    assert any(e["field"] == field for e in response.json()["errors"]), response.json()


def test_generated_trace_over_the_limit(client):
    response = client.post(
        "/v1/simulate",
        json=SIMULATE_EXAMPLE | {"cycle": {"street_type": "urban", "distance_m": 900_000}},
    )
    assert response.status_code == 422
    assert response.json()["errors"][0]["field"] == "cycle.distance_m"
