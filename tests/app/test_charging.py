"""Charging at the depot over HTTP: the Swagger example of a day longer than the battery, and
the chargers and charging curves a client may get wrong."""

import pytest

from app.examples import CHARGING_PLAN_EXAMPLE, FLEET_PLAN_EXAMPLE, PLAN_EXAMPLE

PROBLEM = "application/problem+json"


def test_the_charging_example_comes_back_to_charge_and_holds_its_reserve(client):
    no_charger = {k: v for k, v in CHARGING_PLAN_EXAMPLE["depot"].items() if k != "charger"}
    flat = client.post("/v1/plans", json=CHARGING_PLAN_EXAMPLE | {"depot": no_charger})
    assert flat.status_code == 200 and flat.json()["battery"]["feasible"] is False
    response = client.post("/v1/plans", json=CHARGING_PLAN_EXAMPLE)
    assert response.status_code == 200
    body = response.json()
    assert body["battery"]["feasible"] is True
    charges = body["charges"]
    assert charges and body["tour"].count("depot-centre") == 2 + len(charges)
    charge = charges[0]
    assert set(charge) == {
        "charger_id",
        "arrive",
        "depart",
        "soc_before",
        "soc_after",
        "grid_kwh",
        "battery_kwh",
        "minutes",
        "cost",
    }
    assert charge["charger_id"] == "depot"
    assert charge["soc_before"] < charge["soc_after"] < 1.0
    assert charge["cost"] == pytest.approx(0.3 * charge["grid_kwh"])
    # every stop served once, the lowest charge at or above the 10 % reserve
    served = [s for s in body["tour"] if s != "depot-centre"]
    assert sorted(served) == sorted(s["id"] for s in CHARGING_PLAN_EXAMPLE["stops"])
    assert body["battery"]["min_soc"] >= 0.1


def test_a_fleet_with_a_depot_charger_says_it_does_not_charge(client):
    depot = FLEET_PLAN_EXAMPLE["depot"] | {"charger": {"power_kw": 22}}
    response = client.post("/v1/fleet-plans", json=FLEET_PLAN_EXAMPLE | {"depot": depot})
    assert response.status_code == 200
    assert any("charger is not used" in w for w in response.json()["warnings"])


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"depot": PLAN_EXAMPLE["depot"] | {"charger": {"power_kw": 0}}}, "depot.charger.power_kw"),
        (
            {"depot": PLAN_EXAMPLE["depot"] | {"charger": {"power_kw": -22}}},
            "depot.charger.power_kw",
        ),
        (
            {"depot": PLAN_EXAMPLE["depot"] | {"charger": {"power_kw": 22, "points": 0}}},
            "depot.charger.points",
        ),
        (
            {"depot": PLAN_EXAMPLE["depot"] | {"charger": {"power_kw": "NaN"}}},
            "depot.charger.power_kw",
        ),
        (
            {"depot": PLAN_EXAMPLE["depot"] | {"charger": {"power_kw": 22, "plug_minutes": 1e9}}},
            "depot.charger.plug_minutes",
        ),
        (
            {
                "battery": PLAN_EXAMPLE["battery"]
                | {
                    "charging_curve": [
                        {"soc": 0.0, "power_kw": 40},
                        {"soc": 0.8, "power_kw": 50},
                    ]
                }
            },
            "battery.charging_curve[1].power_kw",
        ),
        (
            {
                "battery": PLAN_EXAMPLE["battery"]
                | {"charging_curve": [{"soc": 0.0, "power_kw": 40}, {"soc": 1.5, "power_kw": 5}]}
            },
            "battery.charging_curve[1].soc",
        ),
        (
            {"battery": PLAN_EXAMPLE["battery"] | {"max_charge_power_kw": 0}},
            "battery.max_charge_power_kw",
        ),
    ],
)
def test_bad_chargers_and_curves_are_422_naming_the_field(client, change, field):
    response = client.post("/v1/plans", json=PLAN_EXAMPLE | change)
    assert response.status_code == 422
    assert response.headers["content-type"] == PROBLEM
    assert any(e["field"] == field for e in response.json()["errors"]), response.json()["errors"]


def test_the_map_shows_each_charge_at_the_depot(client):
    response = client.post(
        "/v1/plans", json=CHARGING_PLAN_EXAMPLE, headers={"Accept": "application/geo+json"}
    )
    assert response.status_code == 200
    features = response.json()["features"]
    charges = [f for f in features if f["properties"]["kind"] == "charge"]
    depot = CHARGING_PLAN_EXAMPLE["depot"]
    assert charges and all(
        f["geometry"]["coordinates"] == [depot["lon"], depot["lat"]] for f in charges
    )
    assert charges[0]["properties"]["soc_after"] > charges[0]["properties"]["soc_before"]
