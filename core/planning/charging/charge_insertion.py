"""The stops still left out for their battery after the charging search
(:mod:`core.planning.charging.fleet_charging`), tried one at a time in the verified routes — the one
place where a van that reloads gets its charges, as the charging search plans single trips.

Each stop
left out for its battery is then tried in the vans' routes at its cheapest places by distance
on the objective (:data:`POSITIONS_TRIED` per van) and in a van not driving yet: the route
simulated with the charges it needs (:func:`core.planning.day.recharge.with_charges`, from the
charges it had: every later window and the shift's end kept, the charge points free only
between the other vans' charges). The first that holds — fewer charges by the estimates
first, then what the objective gains, a van already driving before a new one when the fleet
is to be small — takes the stop; its charges are booked on their charge points. A stop
no van can take so is left out as before, its detail saying that charging did not help (or,
when the work's tries, :data:`TRIES_PER_S` per reference second, ran out first, that it was
not tried everywhere).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from core.planning.charging.fleet_charging import Bookings
from core.planning.day.recharge import visits_of
from core.planning.day.scene import charge_points
from core.planning.day.timeline import ChargeVisit
from core.planning.day.verify import route_failure
from core.planning.model import PlanResult, Unassigned
from core.planning.search.day import FleetDay
from core.routing.effort import Effort, SearchEnd
from core.routing.vrp import trips_tidied

#: Places in each van's route a left-out stop is tried at, cheapest by distance first.
POSITIONS_TRIED = 3
#: Tries per reference second of work: each simulates a van's day with its charges fitted
#: (0.05–0.1 s on the reference machine for days of 20–40 stops).
TRIES_PER_S = 10.0


def serve_with_charging(
    day: FleetDay,
    routes: list[list[int]],
    results: dict[int, PlanResult],
    unassigned: list[Unassigned],
    minimize_vehicles: bool,
    effort: Effort,
) -> tuple[list[list[int]], dict[int, PlanResult], list[Unassigned], SearchEnd]:
    """The fleet's routes (stops per van), their simulations and the stops left out, with the
    stops left out for their battery served by vans that charge where they can; the rest of
    ``unassigned`` as it was; and how the tries ended: ``effort``'s work is
    :data:`TRIES_PER_S` tries per second of it, over the candidate places
    (:data:`POSITIONS_TRIED` per van) of the stops in turn; its deadline may cut them short."""
    places = day.scene.places
    bookings = Bookings(charge_points(day.shifts[0].problem, places))
    place_of = {place.id: k for k, place in enumerate(places)}
    for v, result in results.items():  # the charges the routes make already
        bookings.book(day.shifts[v].id, place_of, result)
    served: set[int] = set()
    untried: set[int] = set()  # the tries ran out before every place of the stop was tried
    ended: SearchEnd = "work"
    tries = max(int(effort.work_s * TRIES_PER_S), 1)
    for stop in unassigned:
        if stop.reason != "battery":
            continue
        node = place_of[stop.id]
        for insertion in _candidates(day, routes, node, minimize_vehicles):
            if effort.out_of_time():
                ended = "time_limit"
            if tries <= 0 or ended == "time_limit":
                untried.add(node)
                break
            tries -= 1
            v = insertion.v
            shift = day.shifts[v]
            order, charges = _with_stop(day, results.get(v), insertion)
            result = day.charged(v, order, charges, bookings.busy(shift.id))
            if route_failure(shift.id, shift.problem, places, result, shift.end, True) is None:
                routes[v], results[v] = insertion.route, result
                bookings.book(shift.id, place_of, result)
                served.add(node)
                break
    left = [
        replace(u, detail=f"{u.detail}; {_charging_said(place_of[u.id] in untried)}")
        if u.reason == "battery"
        else u
        for u in unassigned
        if place_of[u.id] not in served
    ]
    return routes, results, left, ended


def _charging_said(untried: bool) -> str:
    """What charging did for a stop left out for its battery."""
    if untried:
        return (
            "the search for a van to serve it with charging ended before it was tried at "
            "every place (a larger work_s tries more)"
        )
    return (
        "charging did not let a van serve it either (no charger within reach, or no time "
        "for the charge)"
    )


@dataclass(frozen=True)
class _Insertion:
    """Van ``v``'s ``route`` (stops, a 0 a return to reload) with ``placed`` — the stop, and
    a return to reload before or after it — at position ``k`` of its route before."""

    v: int
    route: list[int]
    k: int
    placed: list[int]


def _with_stop(
    day: FleetDay, driven: PlanResult | None, insertion: _Insertion
) -> tuple[list[int], dict[int, ChargeVisit]]:
    """The order the van drives its longer route in, keeping the chargers and charges of
    what it drove before (``driven``)."""
    v = insertion.v
    if driven is None:
        return day.order(v, insertion.route), {}
    problem = day.shifts[v].problem
    order, charges = visits_of(problem, day.scene.places, driven, day.starts[v])
    after = 0  # where the route's place before the insertion is in the order
    for place in insertion.route[: insertion.k]:
        after = order.index(place, after + 1)
    order = [*order[: after + 1], *insertion.placed, *order[after + 1 :]]
    shift = len(insertion.placed)
    return order, {q + shift * (q > after): c for q, c in charges.items()}


def _placings(route: list[int], node: int, under_way: bool) -> list[tuple[int, list[int]]]:
    """Where and how ``node`` may join ``route``: at each position, alone, or with a return
    to reload before or after it (when a trip would get too heavy for the van); never a
    return at an end (but the first of a van ``under_way``) or beside another."""
    out = []
    for k in range(len(route) + 1):
        for placed in ([node], [0, node], [node, 0]):
            longer = [*route[:k], *placed, *route[k:]]
            if trips_tidied(longer, under_way) == longer:
                out.append((k, placed))
    return out


def _candidates(
    day: FleetDay, routes: list[list[int]], node: int, minimize_vehicles: bool
) -> list[_Insertion]:
    """Each van's route with ``node`` at its cheapest places on the objective (the van
    carrying every trip), and ``node`` alone for a van not driving, best first: fewer charges
    by the estimates (the energy beyond the battery, in batteries), then what the objective
    gains; the vans not driving after the others when the fleet is to be small."""
    options: list[tuple[bool, int, float, int, _Insertion]] = []
    idle: set[tuple[int, tuple[float, float]]] = set()
    for v, route in enumerate(routes):
        estimates = day.estimates[v]
        kind = (id(estimates), day.shift_s[v])
        if not route and kind in idle:
            continue  # a van like one tried already
        if not route:
            idle.add(kind)
        before = estimates.route_cost(route)
        tried: list[tuple[float, int, _Insertion]] = []
        for k, placed in _placings(route, node, day.starts[v] != 0):
            longer = [*route[:k], *placed, *route[k:]]
            if day.carries(v, longer):
                extra = estimates.route_cost(longer) - before
                tried.append((extra, len(tried), _Insertion(v, longer, k, placed)))
        for extra, _, insertion in sorted(tried)[:POSITIONS_TRIED]:
            energy_j = estimates.route_energy_j(insertion.route)
            charges = max(math.ceil(energy_j / max(estimates.budget_j, 1.0) - 1.0), 0)
            options.append((minimize_vehicles and not route, charges, extra, v, insertion))
    options.sort(key=lambda o: o[:4])
    return [insertion for *_, insertion in options]
