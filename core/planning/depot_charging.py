"""Back to the depot to charge: a round whose battery would run below its reserve comes back
between stops, as often as it needs, and charges what the rest needs (partial recharge).

The round's order stays; the returns split it into trips. Each pass simulates the day in full
(:func:`core.planning.verify.simulate_route`) and

1. cuts the first trip that runs below the reserve after the stop from which the van can
   still reach the depot with its reserve (the driven energy per metre of the simulated day,
   with :data:`RETURN_ENERGY_FACTOR`, prices the way back), choosing among those the stop
   whose return adds the least distance; the new charge first fills the battery;
2. fits every charge to what the simulation says the next trip takes: up to the reserve plus
   that trip's drop plus :data:`PARTIAL_CHARGE_MARGIN` (or to full with
   ``battery.charge_to_full``), the minutes from the charging curve
   (:mod:`core.physics.charging`) at the state of charge the van arrives with.

The consumption of a trip does not depend on how full the battery is, so the fitted charges
hold when simulated again; the verdict is the final simulation's.
"""

from __future__ import annotations

import datetime as dt
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

from core.params import Depot
from core.physics.battery import JOULES_PER_KWH
from core.physics.charging import WATTS_PER_KW, charge_curve
from core.planning.model import PlanProblem, PlanResult, Solved
from core.planning.scene import Scene
from core.planning.timeline import DepotCharge, Windows
from core.planning.verify import simulate_route
from core.routing.roads import LegRoute

#: State of charge charged beyond what the next trip needs and its reserve [–]: the trip is
#: simulated again after the charge and may start a little later, in other weather.
PARTIAL_CHARGE_MARGIN = 0.03
#: The way back to the depot takes this much more energy per metre than the day's mean
#: drive (it is not simulated before it is chosen; the simulation then checks it).
RETURN_ENERGY_FACTOR = 1.25

Roads = Callable[[list[int]], list[LegRoute] | None]
#: A trip's places (the depot first and last) in a better order, the depot still first and last.
Reorder = Callable[[list[int]], list[int]]


def with_depot_charges(
    problem: PlanProblem,
    scene: Scene,
    order: list[int],
    start: dt.datetime,
    roads: Roads,
    solved: Solved,
    windows_s: Sequence[Windows] | None = None,
    reorder: Reorder | None = None,
) -> PlanResult:
    """The round in ``order`` simulated, with returns to the depot's charger between stops
    where the battery would not last (none when it does, or without a charger). With
    ``reorder``, each trip is then put in its own best order, kept when the day holds and is
    better on the round's objective."""
    day = _Round(problem, scene, start, roads, solved, windows_s)
    result = day.simulate(order)
    charger = problem.depot.charger
    if charger is None or result.battery.feasible:
        return result
    charges: dict[int, DepotCharge] = {}
    curve = charge_curve(
        problem.van.battery,
        charger.power_kw * WATTS_PER_KW,
        result.battery.usable_capacity_kwh / problem.van.battery.usable_capacity_kwh,
    )
    for _ in range(len(order)):
        trip = _first_short_trip(problem, order, result)
        if trip is None:
            break
        found = _return_after(problem, scene, order, result, trip)
        if found is None:
            break
        cut, back_soc = found
        full = DepotCharge(charger.plug_minutes * 60, curve.time_s(back_soc, 1.0), charger.power_kw)
        order = [*order[: cut + 1], 0, *order[cut + 1 :]]
        charges = {q + (q > cut): c for q, c in charges.items()} | {cut + 1: full}
        for fitting in range(2):  # fill, then fit every charge to what the next trip takes
            result = day.simulate(order, charges)
            if fitting == 0:
                order, charges = _without_idle(order, _fitted(problem, order, result, charges))
    if reorder is not None and charges and result.battery.feasible:
        result = _with_trips_reordered(day, order, charges, reorder, result)
    if not result.battery.feasible:
        leg = result.first_infeasible_leg
        where = f" on the way to '{result.legs[leg].to_id}'" if leg is not None else ""
        warning = (
            f"even with charges at the depot the battery runs below its reserve{where}: no "
            "stop before it lets the van come back to charge with its reserve (no charger "
            "within reach)"
        )
        result = replace(result, warnings=[*result.warnings, warning])
    return result


@dataclass(frozen=True)
class _Round:
    """What every simulation of the round shares; :meth:`simulate` drives one order."""

    problem: PlanProblem
    scene: Scene
    start: dt.datetime
    roads: Roads
    solved: Solved
    windows_s: Sequence[Windows] | None

    def simulate(
        self, order: list[int], charges: dict[int, DepotCharge] | None = None
    ) -> PlanResult:
        return simulate_route(
            self.problem,
            self.scene,
            order,
            self.start,
            self.roads(order),
            self.solved,
            self.windows_s,
            charges=charges,
        )


def _with_trips_reordered(
    day: _Round,
    order: list[int],
    charges: dict[int, DepotCharge],
    reorder: Reorder,
    result: PlanResult,
) -> PlanResult:
    """The day with each trip in its own best order (the returns stay where they are, every
    trip keeps its stops), its charges fitted again; ``result`` when that is not better on
    the objective."""
    depots = _depot_positions(order)
    trips = [
        reorder(order[a : b + 1]) if order[a] == 0 else order[a : b + 1]  # not from under way
        for a, b in itertools.pairwise(depots)
    ]
    shorter = [order[0], *(place for trip in trips for place in trip[1:])]
    if shorter == order:
        return result
    first = day.simulate(shorter, charges)
    shorter, fitted = _without_idle(shorter, _fitted(day.problem, shorter, first, charges))
    again = day.simulate(shorter, fitted)
    better = again.battery.feasible and _measure(again) < _measure(result)
    return again if better else result


def _measure(result: PlanResult) -> float:
    """The round on its objective, as simulated: metres, seconds or kWh."""
    if result.objective == "duration":
        return result.duration_s
    if result.objective == "energy":
        return result.energy_kwh["total"]
    return result.distance_m


def charging_not_planned(depot: Depot) -> list[str]:
    """The warning of a plan that does not charge although the depot has a charger (a fleet,
    or a round with time windows: their searches do not plan returns yet)."""
    if depot.charger is None:
        return []
    return [
        "the depot's charger is not used: returns to charge are planned for rounds without "
        "time windows (POST /v1/plans); this plan's battery verdict is without charging"
    ]


def _depot_positions(order: list[int]) -> list[int]:
    """Where the trips of ``order`` begin and end: its start (the depot, or the van's position
    when it starts under way), each return to the depot, its end."""
    return [0, *(q for q in range(1, len(order)) if order[q] == 0)]


def _trip_low(result: PlanResult, first: int, last: int) -> float:
    """The lowest state of charge over legs ``first`` to ``last − 1`` (a trip) [–]."""
    legs = result.legs[first:last]
    return min(min(leg.soc_start, leg.soc_end) for leg in legs)


def _first_short_trip(
    problem: PlanProblem, order: list[int], result: PlanResult
) -> tuple[int, int] | None:
    """The first trip (from one depot position to the next) that runs below the reserve."""
    reserve = problem.van.battery.min_soc
    depots = _depot_positions(order)
    for first, last in itertools.pairwise(depots):
        if _trip_low(result, first, last) < reserve - 1e-9:
            return first, last
    return None


def _return_after(
    problem: PlanProblem, scene: Scene, order: list[int], result: PlanResult, trip: tuple[int, int]
) -> tuple[int, float] | None:
    """The position in ``order`` after which the van best comes back to charge within
    ``trip``, and its estimated state of charge at the depot; None when no stop of the trip
    lets it reach the depot with its reserve.

    Of the stops it can come back from, the return that adds the least distance among those
    after which one charge covers the rest of the trip; when none does, the last (the next
    charge then comes as late as it can).
    """
    reserve = problem.van.battery.min_soc
    distance = scene.legs.distance_m
    capacity_j = result.battery.usable_capacity_kwh * JOULES_PER_KWH
    driven_j = sum(leg.energy_kwh["traction"] for leg in result.legs) * JOULES_PER_KWH
    per_metre_j = max(driven_j, 0.0) / max(result.distance_m, 1.0) * RETURN_ENERGY_FACTOR
    stops = {stop.id: stop for stop in result.stops}
    usable_j = (1.0 - reserve - PARTIAL_CHARGE_MARGIN) * capacity_j
    covered: tuple[float, int, float] | None = None
    last: tuple[int, float] | None = None
    for p in range(trip[0] + 1, trip[1] - 1):
        here, onward = order[p], order[p + 1]
        leaving = stops[scene.places[here].id].soc_departure
        back = leaving - per_metre_j * distance[here, 0] / capacity_j
        if leaving < reserve or back < reserve + PARTIAL_CHARGE_MARGIN / 2:
            continue
        last = (p, back)
        rest_j = per_metre_j * distance[0, onward] + _energy_j(result, scene, order, p + 1, trip[1])
        detour = distance[here, 0] + distance[0, onward] - distance[here, onward]
        if rest_j <= usable_j and (covered is None or detour < covered[0]):
            covered = (detour, p, back)
    return (covered[1], covered[2]) if covered is not None else last


def _energy_j(result: PlanResult, scene: Scene, order: list[int], first: int, end: int) -> float:
    """What the round takes from position ``first`` of ``order`` to position ``end``: its
    stops and the legs between them, as simulated [J]."""
    stops = {stop.id: stop for stop in result.stops}
    standing = sum(stops[scene.places[order[q]].id].energy_kwh["total"] for q in range(first, end))
    driving = sum(leg.energy_kwh["total"] for leg in result.legs[first:end])
    return (standing + driving) * JOULES_PER_KWH


def _fitted(
    problem: PlanProblem, order: list[int], result: PlanResult, charges: dict[int, DepotCharge]
) -> dict[int, DepotCharge]:
    """Every charge fitted to the trip after it, from what ``result`` simulated: the state of
    charge each trip drops by does not depend on where it starts."""
    battery = problem.van.battery
    share = result.battery.usable_capacity_kwh / battery.usable_capacity_kwh
    depots = _depot_positions(order)
    fitted: dict[int, DepotCharge] = {}
    leaving = result.legs[0].soc_start
    for k in range(1, len(depots) - 1):
        came, here, goes = depots[k - 1], depots[k], depots[k + 1]
        arriving = leaving - (result.legs[came].soc_start - result.legs[here - 1].soc_end)
        drop = result.legs[here].soc_start - _trip_low(result, here, goes)
        target = (
            1.0
            if battery.charge_to_full
            else min(battery.min_soc + drop + PARTIAL_CHARGE_MARGIN, 1.0)
        )
        visit = charges[here]
        curve = charge_curve(battery, visit.power_kw * WATTS_PER_KW, share)
        fitted[here] = DepotCharge(visit.plug_s, curve.time_s(arriving, target), visit.power_kw)
        leaving = max(arriving, target)
    return fitted


def _without_idle(
    order: list[int], charges: dict[int, DepotCharge]
) -> tuple[list[int], dict[int, DepotCharge]]:
    """``order`` and ``charges`` without the returns that have nothing to charge (an earlier
    charge covers their trip too)."""
    idle = {q for q, visit in charges.items() if visit.charge_s <= 0}
    kept = [place for q, place in enumerate(order) if q not in idle]
    moved = {q - sum(i < q for i in idle): visit for q, visit in charges.items() if q not in idle}
    return kept, moved
