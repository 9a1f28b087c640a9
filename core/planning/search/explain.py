"""Why a stop is left out: no road, a rule that stops every van even on a round of its own, the
simulation that made it go, or the rule that keeps it from joining any van's route."""

from __future__ import annotations

from collections import Counter

from core.planning.day.verify import Failure
from core.planning.model import Unassigned, UnassignedReason
from core.planning.search.feasibility import Feasibility

#: Which reason names a stop that vans refuse for different reasons, when as many refuse it for
#: each.
REASON_ORDER: tuple[UnassignedReason, ...] = ("capacity", "time_window", "shift", "battery")
_FULL_DETAIL: dict[UnassignedReason, str] = {
    "capacity": "the fleet is full: no van has payload left for it",
    "battery": "the fleet's batteries are spent: on any van's route it would take the charge "
    "below the reserve",
    "time_window": "no van can reach it inside its windows alongside its other stops",
    "shift": "no van's shift has time left for it alongside its other stops",
}


def _most_shared(counts: Counter[UnassignedReason]) -> UnassignedReason:
    """The reason most vans give (ties: the first of :data:`REASON_ORDER`)."""
    return max(REASON_ORDER, key=lambda r: (counts[r], -REASON_ORDER.index(r)))


def explain(
    rules: Feasibility, node: int, failure: Failure | None, routes: list[list[int]]
) -> Unassigned:
    """Why the stop at ``node`` is not served: ``failure`` if the simulation removed it,
    ``routes`` the vans' final routes."""
    day = rules.day
    stop_id = day.scene.places[node].id
    if node in day.unreachable:
        depot = day.scene.places[0].id
        return Unassigned(
            id=stop_id, reason="unreachable", detail=f"no road links it with the depot '{depot}'"
        )
    pinned = day.pinned_to.get(node)
    said = "" if pinned is None else f"pinned to {day.shifts[pinned].id}: "
    alone = [rules.alone(v, node) for v in day.vans_for(node)]
    if all(why is not None for why in alone):
        refusals = [why for why in alone if why is not None]
        reason = _most_shared(Counter(why.reason for why in refusals))
        detail = next(w.detail for w in refusals if w.reason == reason)
        return Unassigned(id=stop_id, reason=reason, detail=said + detail)
    if failure is not None:
        detail = f"{said}left out after simulation: {failure.detail}"
        return Unassigned(id=stop_id, reason=failure.reason, detail=detail)
    reason, detail = _full(rules, node, routes)
    return Unassigned(id=stop_id, reason=reason, detail=said + detail)


def _full(rules: Feasibility, node: int, routes: list[list[int]]) -> tuple[UnassignedReason, str]:
    """A stop some van could serve on a round of its own, left out because the fleet is full:
    the rule that stops it from joining any van's route at its best place, the one most vans
    share. A van with no route that would serve it alone has been given it (or its
    simulation said why not, :func:`core.planning.search.fleet.search`): the vans without a route
    refuse it alone, and their reason comes first."""
    vans = rules.day.vans_for(node)
    idle = [why for v in vans if not routes[v] and (why := rules.alone(v, node))]
    if idle:
        reason = _most_shared(Counter(why.reason for why in idle))
        detail = next(why.detail for why in idle if why.reason == reason)
        return reason, f"the vans without a route cannot serve it on a round of its own: {detail}"
    refusals: Counter[UnassignedReason] = Counter()
    for v in vans:
        route = routes[v]
        options = [
            rules.violations(v, [*route[:k], node, *route[k:]]) for k in range(len(route) + 1)
        ]
        refusals.update(min(options, key=len)[:1])
    if not refusals:  # every van could take it by the estimates: the search ran out of time
        return (
            "time_limit",
            "the search's work (work_s) or its time limit ended before it found a place for it "
            "on a route; more work (work_s, a longer time_limit_s, or a job) may find one",
        )
    reason = _most_shared(refusals)
    return reason, _FULL_DETAIL[reason]
