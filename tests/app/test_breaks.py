"""Drivers' breaks over HTTP: the answer's breaks[], and the breaks a client may get wrong."""

import copy

import pytest

from app.examples import CHARGING_PLAN_EXAMPLE, FLEET_PLAN_EXAMPLE, PLAN_EXAMPLE

LUNCH = {"earliest": "12:00", "latest": "13:00", "minutes": 30}


@pytest.mark.slow
def test_a_round_with_a_lunch_break_answers_it_in_the_timeline(client):
    body = CHARGING_PLAN_EXAMPLE | {"breaks": [LUNCH], "battery": {"usable_capacity_kwh": 120}}
    response = client.post("/v1/plans", json=body)
    assert response.status_code == 200
    breaks = response.json()["breaks"]
    assert len(breaks) == 1 and breaks[0]["kind"] == "fixed"
    assert "T12:" in breaks[0]["start"] and set(breaks[0]) == {"start", "end", "kind"}


def test_a_round_has_no_breaks_unless_asked(client):
    assert client.post("/v1/plans", json=PLAN_EXAMPLE).json()["breaks"] == []


@pytest.mark.parametrize(
    ("breaks", "field"),
    [
        ([LUNCH | {"latest": "11:00"}], "breaks[0].latest"),
        ([LUNCH | {"minutes": 0}], "breaks[0].minutes"),
        ([LUNCH | {"minutes": "NaN"}], "breaks[0].minutes"),
        ([LUNCH | {"earliest": "25:00"}], "breaks[0].earliest"),
        ("eu-999", "breaks"),
        # the audit: 5,000 one-minute breaks stretched a round to 3½ days
        ([LUNCH | {"minutes": 1}] * 500, "breaks"),
        ([LUNCH] * 13, "breaks"),
        # the second cannot begin by 12:10 when the first lasts until 12:30
        ([LUNCH, LUNCH | {"latest": "12:10"}], "breaks"),
    ],
)
def test_bad_breaks_of_a_round_are_422_naming_the_field(client, breaks, field):
    response = client.post("/v1/plans", json=PLAN_EXAMPLE | {"breaks": breaks})
    assert response.status_code == 422
    assert any(e["field"].startswith(field) for e in response.json()["errors"]), response.json()


def test_a_fixed_break_longer_than_the_shift_is_422(client):
    fleet = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    fleet["vehicles"][1] |= {"shift_start": "08:00", "shift_end": "09:00"}
    fleet["vehicles"][1]["breaks"] = [
        LUNCH | {"earliest": "08:00", "latest": "08:30"} | {"minutes": 90}
    ]
    response = client.post("/v1/fleet-plans", json=fleet)
    assert response.status_code == 422
    errors = response.json()["errors"]
    assert any(e["field"] == "vehicles[1].breaks" for e in errors), errors
    assert "longer than the 60 min shift" in response.text


def test_two_breaks_one_after_another_are_taken_and_an_impossible_pair_is_named(client):
    morning = {"earliest": "09:30", "latest": "10:00", "minutes": 15}
    body = CHARGING_PLAN_EXAMPLE | {
        "breaks": [morning, LUNCH],
        "battery": {"usable_capacity_kwh": 120},
    }
    taken = client.post("/v1/plans", json=body).json()["breaks"]
    assert [b["kind"] for b in taken] == ["fixed", "fixed"]
    clash = client.post("/v1/plans", json=body | {"breaks": [LUNCH, morning]})
    assert clash.status_code == 422
    assert "breaks[1] must begin by 10:00" in clash.json()["errors"][0]["message"]


def test_a_round_that_ends_on_a_later_day_says_so(client):
    body = PLAN_EXAMPLE | {"start_time": "23:00"}
    answer = client.post("/v1/plans", json=body).json()
    assert answer["legs"][-1]["arrive"].startswith("2026-07-16")
    assert any("the round ends on 2026-07-16" in w for w in answer["warnings"])
    same_day = client.post("/v1/plans", json=PLAN_EXAMPLE).json()
    assert not any("the round ends on" in w for w in same_day["warnings"])
