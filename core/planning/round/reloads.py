"""Several trips of one van: a round whose stops take more than the van carries comes back to
the depot to reload (``max_trips``, ``reload_minutes``).

Without time windows the round trip's order stays: walking it from the depot (or from the van's
position when it is under way, with what it carries), the van comes back to reload before the
first stop whose delivery it no longer carries (the payload back to ``payload_kg``), as often
as it must; each trip is then put in its own best order. With time windows the fleet search
with this one van places the reloads (:mod:`core.planning.round.planner`). More trips than
``max_trips`` is an error naming the stops. The timeline stands the van at the depot, parked, for
``reload_minutes`` (:meth:`core.planning.day.timeline._Builder.reload`).
"""

from __future__ import annotations

from collections.abc import Callable

from core.exceptions import InvalidStopsError
from core.planning.day.start_state import start_payload_kg
from core.planning.model import PlanProblem
from core.routing.units import payload_units_down, payload_units_up

#: A trip's places (the depot first and last) in a better order, the depot still first and last.
Reorder = Callable[[list[int]], list[int]]


def reloads_allowed(problem: PlanProblem) -> bool:
    """Whether the round may come back to reload: more than one trip."""
    return problem.max_trips > 1


def check_payload(problem: PlanProblem) -> None:
    """What the stops take fits the van: in one load, or with reloads in ``max_trips`` loads
    each stop within one; else an error naming the stops or the stop. In the solver's units,
    so that a round accepted here fits the solver's payload too."""
    weights = payload_units_up([stop.delivery_kg for stop in problem.stops])
    capacity = payload_units_down(problem.van.payload_kg)
    delivered = sum(stop.delivery_kg for stop in problem.stops)
    payload = problem.van.payload_kg
    if not reloads_allowed(problem):
        if int(weights.sum()) > capacity:
            raise InvalidStopsError(
                f"the stops' delivery_kg add up to {delivered:g} kg, more than the payload "
                f"{payload:g} kg (with max_trips above 1 the round comes back to reload)",
                "stops",
            )
        return
    for index, weight in enumerate(weights):
        if weight > capacity:
            raise InvalidStopsError(
                f"delivery_kg {problem.stops[index].delivery_kg:g} is more than the payload "
                f"{payload:g} kg: no trip carries it",
                f"stops[{index}].delivery_kg",
            )
    aboard = payload_units_down(start_payload_kg(problem))
    if int(weights.sum()) > aboard + capacity * (problem.max_trips - 1):
        carried = start_payload_kg(problem) + payload * (problem.max_trips - 1)
        raise InvalidStopsError(
            f"the stops' delivery_kg add up to {delivered:g} kg, more than the "
            f"{carried:g} kg {problem.max_trips} trips carry (payload_kg {payload:g})",
            "stops",
        )


def with_reloads(problem: PlanProblem, order: list[int], reorder: Reorder | None) -> list[int]:
    """The round ``order`` (place indices from the depot, or the van's position when it is
    under way, to the depot) with a return to the depot before each stop the van no longer
    carries, each trip in its own best order (``reorder``; None keeps the client's order);
    ``order`` when one load carries it all."""
    if not reloads_allowed(problem):
        return order
    weights = payload_units_up([stop.delivery_kg for stop in problem.stops])
    capacity = payload_units_down(problem.van.payload_kg)
    trips: list[list[int]] = [[order[0]]]
    aboard = payload_units_down(start_payload_kg(problem))
    for place in order[1:-1]:
        weight = int(weights[place - 1])
        if weight > aboard:
            trips[-1].append(0)
            trips.append([0])
            aboard = capacity
        trips[-1].append(place)
        aboard -= weight
    trips[-1].append(0)
    if len(trips) > problem.max_trips:
        raise InvalidStopsError(
            f"in the planned order the stops take {len(trips)} trips, more than max_trips "
            f"{problem.max_trips}",
            "stops",
        )
    if reorder is not None and len(trips) > 1:
        trips = [reorder(trip) for trip in trips]
    return [order[0], *(place for trip in trips for place in trip[1:])]
