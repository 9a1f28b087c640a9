"""POST /v1/studies/electrification as a fleet manager calls it: the example's routes over a
year, every verdict agreeing with the answer's own numbers, the limits (a 413 naming the
limit, a synchronous one pointing to jobs) and bad input named by its field."""

from __future__ import annotations

import copy
import datetime as dt

import pytest

from app.examples import ELECTRIFICATION_EXAMPLE
from tests.app.apps import app_client

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

PATH = "/v1/studies/electrification"


@pytest.fixture(scope="module")
def answer():
    response = app_client().post(PATH, json=ELECTRIFICATION_EXAMPLE)
    assert response.status_code == 200, response.text
    return response.json()


def test_the_example_covers_each_route_with_the_battery_its_days_need(answer):
    """Mondays, Wednesdays, Fridays of 2026 are 156 days, Tuesdays and Thursdays 105; each
    candidate covers a route on the days whose need its battery holds."""
    routes = {r["id"]: r for r in answer["routes"]}
    assert [c["days_total"] for c in routes["inner-city"]["candidates"]] == [156, 156]
    assert [c["days_total"] for c in routes["long-day"]["candidates"]] == [105, 105]
    assert answer["route_days"] == 261 and answer["weather_source"] == "climatology"
    for route in answer["routes"]:
        for outcome in route["candidates"]:
            capacity = int(outcome["id"].split("-")[1])  # reefer-40, reefer-70
            all_year = outcome["days_feasible"] == outcome["days_total"]
            assert all_year == (outcome["required_kwh_max"] <= capacity)
            assert outcome["share_feasible"] == outcome["days_feasible"] / outcome["days_total"]
            assert outcome["required_kwh_p95"] <= outcome["required_kwh_max"]
            assert outcome["days_feasible"] <= outcome["days_feasible_with_charging"]
            assert (outcome["lacking_kwh_max"] == 0) == all_year
            worst = outcome["worst_days"]
            assert len(worst) == 5 and worst == sorted(worst, key=lambda w: w["min_soc"])
            assert all(dt.date.fromisoformat(w["date"]).year == 2026 for w in worst)
    # the long day needs more than 40 kWh every day (the lunch charge covers it) and less
    # than 70: the 70 kWh van drives both routes all year
    fleet = {f["id"]: f for f in answer["fleet"]}
    assert fleet["reefer-40"]["routes_all_year"] == 1
    assert fleet["reefer-40"]["routes_all_year_with_charging"] == 2
    assert fleet["reefer-70"]["routes_all_year"] == 2
    long_40 = routes["long-day"]["candidates"][0]
    assert long_40["days_feasible"] == 0 and long_40["worst_days"][0]["reason"] == "distance"
    # winter is the worst for these routes: cab heating and the battery's cold
    assert routes["long-day"]["candidates"][1]["worst_days"][0]["reason"] == "cold"
    # the depot recharges only the days driven on one charge: more with the larger battery
    assert fleet["reefer-70"]["depot_kwh_max_day"] > fleet["reefer-40"]["depot_kwh_max_day"]


def test_the_same_request_gives_the_same_answer(answer):
    again = app_client().post(PATH, json=ELECTRIFICATION_EXAMPLE).json()
    timing = ("runtime_s", "route_days_per_s")
    assert {k: v for k, v in again.items() if k not in timing} == {
        k: v for k, v in answer.items() if k not in timing
    }


def test_a_candidate_without_its_own_strategy_takes_the_studys():
    body = copy.deepcopy(ELECTRIFICATION_EXAMPLE)
    body["routes"] = body["routes"][:1]
    body["routes"][0]["days"] = ["2026-07-15"]
    body["candidates"] = body["candidates"][:1]
    thermostat = app_client().post(PATH, json=body).json()
    body["refrigeration"] = {"strategy": "optimal"}
    optimal = app_client().post(PATH, json=body).json()

    def unit_kwh(answer):
        return answer["routes"][0]["candidates"][0]["energy_kwh_mean"]["refrigeration"]

    assert unit_kwh(optimal) < unit_kwh(thermostat)


def test_more_route_days_than_the_server_takes_is_a_413_naming_the_limit():
    small = app_client(max_route_days=100)
    response = small.post(PATH, json=ELECTRIFICATION_EXAMPLE)
    assert response.status_code == 413
    assert response.json()["errors"][0]["field"] == "routes"
    assert "522 route-days × candidates" in response.json()["detail"]
    assert "at most 100" in response.json()["detail"]
    sync = app_client(max_sync_route_days=100).post(PATH, json=ELECTRIFICATION_EXAMPLE)
    assert sync.status_code == 413 and "type electrification" in sync.json()["detail"]


def test_a_round_of_several_days_counts_once_for_each_day_it_lasts():
    """An audit's: 1,200 cells of a 5.8-day round were taken like 1,200 of an hour's. One
    route on 20 dates, one candidate: 20 route-days of an hour; of six days, 120 — above a
    limit of 100 (its stops' service alone lasts 5.8 days)."""
    limited = app_client(max_route_days=100)

    def study(service_s: float) -> dict:
        return _with(
            lambda b: (
                b.update(candidates=b["candidates"][:1], routes=b["routes"][:1]),
                b["routes"][0].update(
                    days=[f"2026-07-{d:02d}" for d in range(1, 21)],
                    stops=[s | {"service_time_s": service_s} for s in b["routes"][0]["stops"]],
                ),
            )
        )

    stops = len(ELECTRIFICATION_EXAMPLE["routes"][0]["stops"])
    short = limited.post(PATH, json=study(600.0))
    assert short.status_code == 200, short.text
    long = limited.post(PATH, json=study(5.8 * 86_400 / stops))
    assert long.status_code == 413, long.text
    assert "120 route-days × candidates" in long.json()["detail"]


def _with(change) -> dict:
    body = copy.deepcopy(ELECTRIFICATION_EXAMPLE)
    change(body)
    return body


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda b: b["routes"][0].update(days=["2026-03-02", "2026-03-01"]), "routes[0].days"),
        (lambda b: b["routes"][0].update(days=["2025-03-02"]), "routes[0].days[0]"),
        (lambda b: b["routes"][0].update(days={"weekdays": ["mon", "mo"]}), "routes[0].days"),
        (lambda b: b["routes"][0].update(days=[]), "routes[0].days"),
        (lambda b: b["routes"][0].update(start_time="25:00"), "routes[0].start_time"),
        (lambda b: b["routes"][1].update(id="inner-city"), "routes[1].id"),
        (lambda b: b["routes"][0]["stops"][1].update(lat=91), "routes[0].stops[1].lat"),
        (lambda b: b["routes"][0].update(stops=[]), "routes[0].stops"),
        (lambda b: b.update(candidates=[]), "candidates"),
        (lambda b: b["candidates"][1].update(id="reefer-40"), "candidates[1].id"),
        (
            lambda b: b["candidates"][0]["vehicle"].update(preset="tesla"),
            "candidates[0].vehicle.preset",
        ),
        (
            lambda b: b["candidates"][0]["battery"].update(usable_capacity_kwh=-1),
            "candidates[0].battery.usable_capacity_kwh",
        ),
        (lambda b: b["chargers"][0].update(power_kw=0), "chargers[0].power_kw"),
        (lambda b: b["chargers"][0].update(where="roof"), "chargers[0].where"),
        (lambda b: b.update(weather={"source": "radar"}), "weather.source"),
        (lambda b: b.update(year=1800), "year"),
        (lambda b: b.update(timezone="Mars/Olympus"), "timezone"),
        (lambda b: b.update(routes=[]), "routes"),
        (
            lambda b: (
                b.update(refrigeration={"strategy": "optimal"}),
                [c.pop("cargo_box") for c in b["candidates"]],
            ),
            "refrigeration",  # the strategy as sent (routes[0].product was not sent)
        ),
    ],
)
def test_bad_studies_name_the_field(change, field):
    response = app_client().post(PATH, json=_with(change))
    assert response.status_code == 422, response.text
    assert response.headers["content-type"] == "application/problem+json"
    assert field in [e["field"] for e in response.json()["errors"]], response.json()


def test_every_day_is_listed_when_asked_and_agrees_with_the_summary():
    body = _with(lambda b: b.update(include_days=True))
    answer = app_client().post(PATH, json=body).json()
    for route in answer["routes"]:
        for outcome in route["candidates"]:
            days = outcome["days"]
            assert len(days) == outcome["days_total"]
            assert [d["date"] for d in days] == sorted(d["date"] for d in days)
            assert sum(d["margin_kwh"] >= 0 for d in days) == outcome["days_feasible"]
            assert (
                sum(d["covered_with_charging"] for d in days)
                == (outcome["days_feasible_with_charging"])
            )
            assert max(d["required_kwh"] for d in days) == outcome["required_kwh_max"]
            assert min(d["min_soc"] for d in days) == outcome["worst_days"][0]["min_soc"]
    assert all(
        c["days"] is None
        for r in app_client().post(PATH, json=ELECTRIFICATION_EXAMPLE).json()["routes"]
        for c in r["candidates"]
    )


def test_the_studys_strategy_runs_with_each_routes_goods():
    """Candidates without goods in their box, routes that name theirs: the optimal strategy
    the study gives every candidate keeps each route's goods in band."""
    body = _with(
        lambda b: (
            b.update(refrigeration={"strategy": "optimal"}),
            [c.pop("cargo_box") for c in b["candidates"]],
            [r.update(product="chilled-dairy", days=["2026-07-15"]) for r in b["routes"]],
        )
    )
    response = app_client().post(PATH, json=body)
    assert response.status_code == 200, response.text
    for route in response.json()["routes"]:
        assert all(c["cold_chain_days_broken"] == 0 for c in route["candidates"])


def test_a_candidates_own_strategy_runs_with_each_routes_goods():
    """ "This van with a thermostat against optimal", done as documented: each candidate its
    own strategy, the goods from the routes (an audit's: a 422 "needs cargo_box.product" for
    the candidate's own, where the study's was accepted)."""
    body = _with(
        lambda b: (
            [c.pop("cargo_box") for c in b["candidates"]],
            b["candidates"].append(
                b["candidates"][0] | {"id": "optimal", "refrigeration": {"strategy": "optimal"}}
            ),
            [r.update(product="chilled-dairy", days=["2026-07-15"]) for r in b["routes"]],
        )
    )
    response = app_client().post(PATH, json=body)
    assert response.status_code == 200, response.text
    for route in response.json()["routes"]:
        thermostat, optimal = route["candidates"][0], route["candidates"][-1]
        assert optimal["id"] == "optimal"
        assert optimal["cold_chain_days_broken"] == 0
        unit = "refrigeration"
        assert optimal["energy_kwh_mean"][unit] < thermostat["energy_kwh_mean"][unit]


@pytest.mark.parametrize("whose", ["candidate", "study"])
def test_an_optimal_strategy_without_goods_names_the_strategy_sent(whose):
    """No route names its product and no candidate's box its goods: the field named is the
    strategy as sent — the candidate's or the study's — not routes[0].product, which the
    request does not have (an audit's)."""
    strategy = {"strategy": "optimal"}

    def change(b: dict) -> None:
        for c in b["candidates"]:
            c.pop("cargo_box", None)
        for r in b["routes"]:
            r.pop("product", None)
        if whose == "candidate":
            b["candidates"][1]["refrigeration"] = strategy
        else:
            b["refrigeration"] = strategy

    response = app_client().post(PATH, json=_with(change))
    assert response.status_code == 422, response.text
    field = "candidates[1].refrigeration" if whose == "candidate" else "refrigeration"
    assert [e["field"] for e in response.json()["errors"]] == [field], response.json()


def _archived(body: dict) -> dict:
    """The example in 2025 (archived: a year gone), on its first days, from the archive."""
    return body | {
        "year": 2025,
        "weather": {"source": "archive"},
        "routes": [r | {"days": ["2025-01-14", "2025-07-15"]} for r in body["routes"]],
    }


def test_a_year_from_the_weather_archive(weather_stub):
    """The stub's archive is 33 °C every hour: the winter day needs as much refrigeration as
    the summer one and more than the climatology's January; one request per place."""
    weather_stub.requests.clear()
    hot = app_client(weather_url=f"{weather_stub.url}/hot")
    body = _archived(ELECTRIFICATION_EXAMPLE) | {"include_days": True}
    archived = hot.post(PATH, json=body).json()
    assert archived["weather_source"] == "archive" and archived["warnings"] == []
    climate = app_client().post(PATH, json=body).json()
    assert climate["weather_source"] == "climatology"
    assert "no weather service is configured" in climate["warnings"][0]
    for served, typical in zip(archived["routes"], climate["routes"], strict=True):
        winter, summer = served["candidates"][0]["days"]
        assert winter["energy_kwh"] == pytest.approx(summer["energy_kwh"], rel=0.05)
        unit = [r["candidates"][0]["energy_kwh_mean"]["refrigeration"] for r in (served, typical)]
        assert unit[0] > unit[1]  # 33 °C in January too: the frozen box's unit works harder
    places = {(q["latitude"], q["longitude"]) for _, q in weather_stub.requests}
    assert len(places) == 2  # the two depots, each asked once for the whole year
    assert all(path.endswith("/v1/archive") for path, _ in weather_stub.requests)


def test_an_archive_that_fails_falls_back_to_the_climatology_and_says_so(weather_stub):
    failing = app_client(weather_url=f"{weather_stub.url}/error")
    answer = failing.post(PATH, json=_archived(ELECTRIFICATION_EXAMPLE)).json()
    assert answer["weather_source"] == "climatology"
    assert "weather archive is unavailable" in answer["warnings"][0]
