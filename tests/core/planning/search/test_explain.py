"""Why a stop is left out, rule by rule."""

from __future__ import annotations

import numpy as np

from core.params import Stop
from core.planning.day.verify import Failure
from core.planning.search.explain import explain
from core.planning.search.feasibility import Feasibility
from tests.utils.fleets import day_of, fleet, two_clusters, van


def rules_for(problem) -> Feasibility:
    day = day_of(problem)
    return Feasibility(
        day, np.rint(day.duration_s).astype(np.int64), [e.budget_j for e in day.estimates]
    )


def test_a_stop_every_van_refuses_alone_gets_the_reason_most_vans_give():
    stops, matrix = two_clusters()
    stops[0] = Stop(id="heavy", lat=48.2, lon=16.4, delivery_kg=700)
    # Two vans carry 550 kg, one 800 kg but its shift is too short to get there and back.
    vans = [van("a"), van("b"), van("c", "08:00", "08:15", payload_kg=800)]
    why = explain(rules_for(fleet(stops, vans, matrix=matrix)), 1, None, [[], [], []])
    assert (why.id, why.reason) == ("heavy", "capacity")


def test_a_stop_the_simulation_removed_says_so():
    stops, matrix = two_clusters()
    rules = rules_for(fleet(stops, [van("a")], matrix=matrix))
    why = explain(rules, 2, Failure("battery", None, "below its reserve"), [[1]])
    assert why.reason == "battery" and why.detail == "left out after simulation: below its reserve"


def test_a_full_fleet_names_the_rule_that_keeps_the_stop_out():
    stops, matrix = two_clusters(delivery_kg=100)
    rules = rules_for(fleet(stops, [van("a", payload_kg=500)], matrix=matrix))
    # Five stops of 100 kg fill the van: the sixth fits nowhere by payload.
    why = explain(rules, 6, None, [[1, 2, 3, 4, 5]])
    assert why.reason == "capacity" and "full" in why.detail


def test_a_stop_that_fits_a_route_by_every_rule_was_left_by_the_time_limit():
    # Issue #21: a search out of time left stops that fitted, and the answer said "shift".
    stops, matrix = two_clusters(delivery_kg=100)
    rules = rules_for(fleet(stops, [van("a", payload_kg=800)], matrix=matrix))
    why = explain(rules, 6, None, [[1, 2]])
    assert why.reason == "time_limit" and "time_limit_s" in why.detail
    assert rules.violations(0, [1, 2, 6]) == []  # it does fit: the reason is not a rule
