"""What the estimates say a van can do, checked by hand on the two-cluster matrix: 10 min from
the depot to every stop, 2 min within a cluster, 30 min across; 5 min of service."""

from __future__ import annotations

import numpy as np
import pytest

from core.params import BatteryParams, Stop
from core.planning.search.feasibility import Feasibility
from tests.utils.fleets import day_of, fleet, two_clusters, van, window


def rules_for(problem, budgets=None) -> Feasibility:
    day = day_of(problem)
    travel = np.rint(day.duration_s).astype(np.int64)  # a client matrix is driven as it says
    return Feasibility(day, travel, budgets or [e.budget_j for e in day.estimates])


def test_a_route_that_fits_breaks_nothing():
    stops, matrix = two_clusters()
    rules = rules_for(fleet(stops, [van("a")], matrix=matrix))
    assert rules.violations(0, [1, 2, 3]) == []


def test_back_after_the_shift():
    # 08:00 + 10 min + 3 × 5 min service + 2 × 2 min + 10 min back = 08:39 > 08:30.
    stops, matrix = two_clusters()
    rules = rules_for(fleet(stops, [van("a", "08:00", "08:30")], matrix=matrix))
    assert rules.violations(0, [1, 2, 3]) == ["shift"]
    assert rules.violations(0, [1]) == []  # 08:25 back


def test_a_window_closed_on_arrival():
    # E1 is reached at 08:10; its window closed at 08:05. E2's window opens at 09:00: wait.
    stops, matrix = two_clusters()
    stops[0] = stops[0].model_copy(update={"time_windows": [window("08:00", "08:05")]})
    stops[1] = stops[1].model_copy(update={"time_windows": [window("09:00", "09:30")]})
    rules = rules_for(fleet(stops, [van("a", "08:00", "09:20")], matrix=matrix))
    assert rules.violations(0, [1]) == ["time_window"]
    # E2 served at 09:00 (waited), back at 09:15: inside the shift.
    assert rules.violations(0, [2]) == []
    # E3 first (08:10–08:15), E2 at 08:17, waits for 09:00, back 09:15.
    assert rules.violations(0, [3, 2]) == []


def test_payload_and_battery():
    stops, matrix = two_clusters(delivery_kg=60)
    problem = fleet(stops, [van("a", payload_kg=100)], matrix=matrix)
    rules = rules_for(problem)
    assert rules.violations(0, [1, 2]) == ["capacity"]  # 120 kg > 100 kg
    energy = rules.day.estimates[0].route_energy_j([1])
    tight = rules_for(problem, budgets=[energy * 0.99])
    assert tight.violations(0, [1]) == ["battery"]
    reported = rules_for(problem, budgets=[None])  # a battery only reported is no rule
    assert reported.violations(0, [1]) == []


@pytest.mark.parametrize(
    ("stop", "vehicle", "reason", "words"),
    [
        (Stop(id="heavy", lat=48.2, lon=16.4, delivery_kg=900), van("a"), "capacity", "900 kg"),
        (
            Stop(id="early", lat=48.2, lon=16.4, time_windows=[window("06:00", "06:30")]),
            van("a"),
            "time_window",
            "06:30",
        ),
        (Stop(id="far", lat=48.2, lon=16.4), van("a", "08:00", "08:15"), "shift", "08:25"),
        (
            Stop(id="costly", lat=48.2, lon=16.4),
            van("a", battery=BatteryParams(usable_capacity_kwh=0.1, min_soc=0.1)),
            "battery",
            "kWh",
        ),
    ],
)
def test_why_a_stop_cannot_be_served_alone(stop, vehicle, reason, words):
    stops, matrix = two_clusters()
    stops[0] = stop.model_copy(update={"service_time_s": 300.0})
    rules = rules_for(fleet(stops, [vehicle], matrix=matrix))
    why = rules.alone(0, 1)
    assert why is not None and (why.reason, why.node) == (reason, 1)
    assert words in why.detail
    # The stop's own rule (weight, window) leaves the others servable; the van's does not.
    assert (rules.alone(0, 2) is None) == (reason in ("capacity", "time_window"))


def test_the_earliest_arrival_and_return_of_any_van():
    # Vans leave at 08:00 and 09:00; E1 is 10 min away, 5 min of service, 10 min back.
    stops, matrix = two_clusters()
    rules = rules_for(fleet(stops, [van("a", "09:00"), van("b", "08:00")], matrix=matrix))
    assert rules.day.clock(rules.earliest(1)) == "08:10"
    assert rules.day.clock(rules.earliest_back(1)) == "08:25"
