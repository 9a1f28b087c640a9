"""Routes made to hold: cut to what the estimates accept before a re-solve (:func:`fitting`),
and stripped of stops until the simulation accepts them when the budget is spent
(:func:`repair`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from core.planning.day.estimates import VanEstimates
from core.planning.day.verify import Failure
from core.planning.model import PlanResult
from core.planning.search.feasibility import Feasibility
from core.routing.vrp import trips_tidied


def fitting(rules: Feasibility, v: int, route: list[int]) -> list[int]:
    """The route less its last stops until the estimates accept it."""
    route = list(route)
    while route and rules.violations(v, route):
        route = trips_tidied(route[:-1], rules.day.starts[v] != 0)
    return route


def costliest(estimates: VanEstimates, route: list[int]) -> int:
    """The stop whose removal saves the most estimated energy (not a return to reload)."""
    energy = estimates.energy_j
    order = [estimates.start, *route, 0]
    savings = [
        energy[order[k - 1], order[k]]
        + energy[order[k], order[k + 1]]
        - energy[order[k - 1], order[k + 1]]
        if order[k]
        else -np.inf
        for k in range(1, len(order) - 1)
    ]
    return route[int(np.argmax(savings))]


@dataclass(frozen=True)
class Repaired:
    """A route after repair, its simulation (None when no stop is left) and the stops it lost
    with the rule that made each go."""

    route: list[int]
    result: PlanResult | None
    removed: dict[int, Failure]


def repair(
    route: list[int],
    failure: Failure,
    simulate: Callable[[list[int]], PlanResult],
    check: Callable[[list[int], PlanResult], Failure | None],
    estimates: VanEstimates,
) -> Repaired:
    """Drop stops from a route the simulation rejects until it holds: the stop a failure
    names, else the costliest by the estimates; ``simulate`` and ``check`` simulate a route
    and say what it breaks."""
    removed: dict[int, Failure] = {}
    route = list(route)
    result: PlanResult | None = None
    current: Failure | None = failure
    while route and current is not None:
        node = current.node if current.node is not None else costliest(estimates, route)
        route = trips_tidied([n for n in route if n != node], estimates.start != 0)
        removed[node] = current
        if not route:
            return Repaired(route, None, removed)
        result = simulate(route)
        current = check(route, result)
    return Repaired(route, result, removed)
