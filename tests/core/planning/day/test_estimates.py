"""The solvers' estimates: the learned driving times by their one rule, a kind of van's costs
and budget by hand."""

from __future__ import annotations

import numpy as np
import pytest

from core.physics.battery import JOULES_PER_KWH
from core.planning.day.estimates import LEARNED_RATIO_QUANTILE, LearnedTimes, energy_matrix_j
from tests.utils.fleets import day_of, fleet, two_clusters, van


def times() -> LearnedTimes:
    duration = np.array([[0.0, 100.0, 200.0], [100.0, 0.0, 50.0], [200.0, 50.0, 0.0]])
    finite = np.ones((3, 3), dtype=bool)
    finite[1, 2] = False
    return LearnedTimes(np.where(finite, duration, 0.0), finite, horizon_s=1000)


def test_until_something_is_driven_the_matrix_is_the_estimate():
    learned = times()
    assert learned.matrix()[0, 1] == 100 and learned.matrix()[2, 0] == 200
    assert learned.matrix()[1, 2] == 1001  # no road: longer than the day


def test_a_driven_arc_takes_what_it_took_and_the_rest_scale_by_the_ratio():
    learned = times()
    learned.learn([((0, 1), 150.4)])
    assert learned.matrix()[0, 1] == 151  # rounded up: a window planned on it holds
    assert learned.matrix()[2, 0] == 301  # 200 s × 1.504 = 300.8
    learned.learn([((1, 0), 110.0)])  # faster than expected: the ratio does not fall
    assert learned.ratio == pytest.approx(1.504)
    assert learned.matrix()[1, 0] == 110 and learned.matrix()[0, 2] == 301


def test_the_ratio_is_a_high_quantile_not_the_slowest_hop():
    duration = np.full((11, 11), 100.0)
    np.fill_diagonal(duration, 0)
    learned = LearnedTimes(duration, np.ones((11, 11), dtype=bool), 10_000)
    learned.learn([((0, k), 100.0 * k) for k in range(1, 11)])  # ratios 1, 2, …, 10
    assert learned.ratio == pytest.approx(np.quantile(np.arange(1, 11), LEARNED_RATIO_QUANTILE))
    assert learned.ratio == pytest.approx(9.1)


def test_a_van_kind_budget_costs_and_stop_energy():
    stops, matrix = two_clusters()
    day = day_of(fleet(stops, [van("a"), van("b")], matrix=matrix))
    kind = day.estimates[0]
    assert day.estimates[1] is kind  # the same van at the same time: one kind
    # The paper van's 40 kWh from full to its 10 % reserve.
    assert kind.budget_j == pytest.approx(0.9 * 40 * JOULES_PER_KWH)
    # Distance objective: metres, exactly (10 + 2 + 2 + 10 min at 500 m/min).
    assert kind.route_cost([1, 2, 3]) == pytest.approx(24 * 500)
    # Each arc carries the service (and door heat) of the stop it leaves; the depot's is 0.
    shift = day.shifts[0]
    arcs = energy_matrix_j(shift.problem, day.scene.legs, shift.start)
    stop_j = kind.energy_j - arcs
    assert stop_j[0, 1] == pytest.approx(0.0, abs=1e-6)
    assert stop_j[1, 0] == pytest.approx(stop_j[1, 2]) and stop_j[1, 0] > 0
    assert kind.route_energy_j([1]) == pytest.approx(arcs[0, 1] + arcs[1, 0] + stop_j[1, 0])
