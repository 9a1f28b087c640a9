"""Weather forecasts over HTTP, against the local stand-in of an Open-Meteo-compatible API."""

from __future__ import annotations

import copy
import datetime as dt
import time

import pytest
from fastapi.testclient import TestClient

from app.examples import PLAN_EXAMPLE, SIMULATE_EXAMPLE
from tests.app.apps import app_client
from tools.osrm import free_port

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

# Forecasts are for days to come; the archive answers for days gone.
TOMORROW = (dt.datetime.now(dt.UTC).date() + dt.timedelta(days=1)).isoformat()
ROUND = {k: v for k, v in PLAN_EXAMPLE.items() if k != "weather"} | {
    "keep_order": True,
    "date": TOMORROW,
}


def client_for(url: str | None, **settings) -> TestClient:
    return app_client(weather_url=url, **settings)


def test_plans_use_the_hourly_forecast(weather_stub):
    weather_stub.requests.clear()
    body = client_for(f"{weather_stub.url}/hot").post("/v1/plans", json=ROUND).json()
    assert body["weather"]["source"] == "forecast" and body["warnings"] == []
    assert body["weather"]["days"] == [{"date": TOMORROW, "t_min_c": 33.0, "t_max_c": 33.0}]
    ((path, query),) = weather_stub.requests
    assert path == "/hot/v1/forecast"
    assert query["timezone"] == "UTC" and query["start_date"] == TOMORROW
    assert query["hourly"].split(",") == [
        "temperature_2m",
        "direct_radiation",
        "diffuse_radiation",
        "cloud_cover",
        "wind_speed_10m",
        "wind_direction_10m",
    ]
    assert float(query["latitude"]) == pytest.approx(PLAN_EXAMPLE["depot"]["lat"], abs=1e-4)


def test_the_forecast_changes_the_energy(weather_stub):
    hot = client_for(f"{weather_stub.url}/hot").post("/v1/plans", json=ROUND).json()
    cold = client_for(f"{weather_stub.url}/cold").post("/v1/plans", json=ROUND).json()
    # 33 °C in full sun: the unit works; −8 °C: the cab heater does
    assert (
        hot["totals"]["energy_kwh"]["refrigeration"]
        > 3 * cold["totals"]["energy_kwh"]["refrigeration"]
    )
    assert cold["totals"]["energy_kwh"]["cabin"] > hot["totals"]["energy_kwh"]["cabin"]


def test_wind_costs_traction_on_a_round_trip(weather_stub):
    # 15 m/s from the north: drag grows with the square of the airspeed, so the headwind
    # legs cost more than the tailwind legs save
    windy = client_for(f"{weather_stub.url}/windy").post("/v1/plans", json=ROUND).json()
    calm = (
        client_for(None)
        .post("/v1/plans", json=ROUND | {"weather": {"t_min_c": 15, "t_max_c": 15}})
        .json()
    )
    assert (
        windy["totals"]["energy_kwh"]["traction"] > 1.02 * calm["totals"]["energy_kwh"]["traction"]
    )


def test_past_dates_come_from_the_archive(weather_stub):
    weather_stub.requests.clear()
    body = (
        client_for(f"{weather_stub.url}/cold")
        .post("/v1/plans", json=ROUND | {"date": "2020-01-15"})
        .json()
    )
    assert body["weather"]["source"] == "archive"
    assert weather_stub.requests[0][0] == "/cold/v1/archive"


def test_the_requests_own_weather_wins(weather_stub):
    weather_stub.requests.clear()
    body = client_for(f"{weather_stub.url}/hot").post("/v1/plans", json=PLAN_EXAMPLE).json()
    assert body["weather"]["source"] == "request" and weather_stub.requests == []


@pytest.mark.parametrize("mode", ["error", "garbage", "broken"])
def test_a_failing_service_falls_back_to_the_climatology_and_says_so(weather_stub, mode):
    response = client_for(f"{weather_stub.url}/{mode}").post("/v1/plans", json=ROUND)
    assert response.status_code == 200
    body = response.json()
    assert body["weather"]["source"] == "climatology"
    assert len(body["warnings"]) == 1 and "weather service unavailable" in body["warnings"][0]


def test_an_unreachable_or_slow_service_falls_back_in_time(weather_stub):
    closed = client_for(f"http://127.0.0.1:{free_port()}")
    assert closed.post("/v1/plans", json=ROUND).json()["weather"]["source"] == "climatology"
    slow = client_for(f"{weather_stub.url}/slow", weather_timeout_s=1.0)
    started = time.monotonic()
    body = slow.post("/v1/plans", json=ROUND).json()
    assert body["weather"]["source"] == "climatology" and "in time" in body["warnings"][0]
    assert time.monotonic() - started < 3.5


def test_simulation_uses_the_forecast_too(weather_stub):
    request = copy.deepcopy(SIMULATE_EXAMPLE)
    request.pop("weather")
    request["start"] = f"{TOMORROW}T11:00:00+02:00"
    body = client_for(f"{weather_stub.url}/hot").post("/v1/simulate", json=request).json()
    assert body["weather"]["source"] == "forecast" and body["weather"]["t_max_c"] == 33.0
    down = client_for(f"{weather_stub.url}/error").post("/v1/simulate", json=request).json()
    assert down["weather"]["source"] == "climatology" and down["warnings"]
