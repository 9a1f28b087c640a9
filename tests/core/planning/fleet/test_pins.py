"""Stops pinned to a van: no other van serves them, through every engine of the fleet's
search (PyVRP, OR-Tools, the E-VRPTW search with charging), the pinned van's own reason when it
cannot take them, and the pins' ids checked."""

from __future__ import annotations

import pytest

from core.exceptions import CoreError
from core.params import ChargePoint
from core.planning.fleet.planner import plan_fleet
from core.planning.search.charging.fleet_charging import charging_instance
from tests.core.planning.fleet.test_fleet import assert_holds
from tests.utils.fleets import DEPOT, day_of, fleet, two_clusters, van


def pinned(vehicle_id: str, stops: list[str], **changes):
    return van(vehicle_id, **changes).model_copy(update={"pinned_stops": stops})


def served_by(result) -> dict[str, str]:
    return {s.id: r.vehicle_id for r in result.routes for s in r.plan.stops}


def test_with_fewest_vans_first_the_pinned_van_drives_the_whole_day():
    """Unpinned, van a (listed first) drives both clusters alone (58 min, test_fleet). W1
    pinned to b: one van still does, and it can only be b."""
    stops, matrix = two_clusters()
    problem = fleet(stops, [van("a"), pinned("b", ["W1"])], matrix=matrix)
    result = plan_fleet(problem)
    assert_holds(result, problem)
    assert set(served_by(result).values()) == {"b"} and result.unassigned == []
    assert result.distance_m == pytest.approx(58 * 500, rel=1e-3)


def test_a_pinned_stop_goes_to_its_van_and_the_rest_follow_the_objective():
    """By distance alone, two vans drive a cluster each (48 min, test_fleet); unpinned, a
    (listed first) drives west. W1 pinned to b turns the split round: b drives west, a east,
    2 × (10 + 2 + 2 + 10) = 48 min, rather than b driving W1 and the east
    (10 + 30 + 2 + 2 + 10 = 54 min) and a the rest (10 + 2 + 10 = 22 min)."""
    stops, matrix = two_clusters()
    vehicles = [van("a"), van("b")]
    unpinned = plan_fleet(fleet(stops, vehicles, matrix=matrix, minimize_vehicles=False))
    assert served_by(unpinned)["W1"] == "a"
    vehicles[1] = pinned("b", ["W1"])
    problem = fleet(stops, vehicles, matrix=matrix, minimize_vehicles=False)
    result = plan_fleet(problem)
    assert_holds(result, problem)
    by = served_by(result)
    assert result.unassigned == []
    assert {by[s] for s in ("W1", "W2", "W3")} == {"b"}
    assert {by[s] for s in ("E1", "E2", "E3")} == {"a"}
    assert result.distance_m == pytest.approx(48 * 500, rel=1e-3)


def test_a_stop_pinned_to_a_van_that_cannot_take_it_is_left_out_with_that_vans_reason():
    """E1 takes 60 kg, pinned to b with 50 kg of payload: a (200 kg) could carry it but may
    not, so E1 is left out for capacity, and the detail names the pin and b's payload."""
    stops, matrix = two_clusters()
    stops[0] = stops[0].model_copy(update={"delivery_kg": 60.0})
    problem = fleet(
        stops, [van("a", payload_kg=200), pinned("b", ["E1"], payload_kg=50)], matrix=matrix
    )
    result = plan_fleet(problem)
    assert_holds(result, problem)
    (left,) = result.unassigned
    assert left.id == "E1" and left.reason == "capacity"
    assert left.detail.startswith("pinned to b: ") and "largest payload 50 kg" in left.detail
    assert "E1" not in served_by(result)


def test_the_charging_search_keeps_the_pins():
    """The E-VRPTW instance of a fleet with pins: the vans that may not serve a pinned stop
    are a kind of their own that forbids it, and the pinned van's kind does not."""
    stops, matrix = two_clusters()
    depot = DEPOT.model_copy(update={"charger": ChargePoint(power_kw=22, points=2)})
    problem = fleet(
        stops, [van("a"), van("b"), pinned("c", ["W1", "E2"])], matrix=matrix
    ).model_copy(update={"depot": depot})
    day = day_of(problem)
    charging = charging_instance(day, day.duration_s, True).instance
    w1, e2 = 4, 2
    forbidden = sorted(sorted(kind.forbidden) for kind in charging.kinds)
    assert forbidden == [[], [e2, w1]]
    assert [kind.count for kind in charging.kinds if kind.forbidden] == [2]


@pytest.mark.parametrize(
    ("pins", "field", "words"),
    [
        ({"b": ["X9"]}, "vehicles[1].pinned_stops[0]", "no stop has the id 'X9'"),
        ({"a": ["E1"], "b": ["W1", "E1"]}, "vehicles[1].pinned_stops[1]", "pinned twice"),
        ({"b": ["W1", "W1"]}, "vehicles[1].pinned_stops[1]", "pinned twice"),
    ],
)
def test_pins_that_name_no_stop_or_one_twice_are_named(pins, field, words):
    stops, matrix = two_clusters()
    vehicles = [pinned(v, pins.get(v, [])) for v in ("a", "b")]
    with pytest.raises(CoreError) as caught:
        plan_fleet(fleet(stops, vehicles, matrix=matrix))
    assert caught.value.field == field and words in caught.value.message
