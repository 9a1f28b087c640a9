"""Charging on the day: a round whose battery would run below its reserve stops between
stops at a charger — the depot's or one on the way — as often as it needs, and charges what
the rest needs (partial recharge).

The charges split the round into stretches. Each pass simulates the day in full
(:func:`core.planning.day.verify.simulate_route`) and

1. for the first stretch that runs below the reserve, weighs every stop the van leaves with
   its reserve and every charger it reaches from there with its reserve (the simulated day's
   driven energy per metre, with :data:`RETURN_ENERGY_FACTOR`, and its standing draw per
   second price the way) and that is open long enough when it comes, by the time the day
   gains: the detour, the wait for the opening, the plug-in and the charge along the curve
   at the charger's power (when one charge cannot cover the rest of the stretch, the rest at
   another visit like it). The best of :data:`OPTIONS_TRIED` that the simulation confirms —
   the van gets there with its reserve and the day's lowest point is higher — is made; the
   new charge first fills the battery;
2. fits every charge to what the simulation says the next stretch takes: up to the reserve
   plus that stretch's drop plus :data:`PARTIAL_CHARGE_MARGIN` (or to full with
   ``battery.charge_to_full``), the minutes from the charging curve
   (:mod:`core.physics.charging`) at the state of charge the van arrives with (after any
   wait for the opening).

The consumption of a stretch does not depend on how full the battery is, so the fitted
charges hold when simulated again. When the order is the planner's, the round is then solved
again through the chargers it visits and each stretch put in its own best order; the best
that holds on the objective is kept. The verdict is always the final simulation's.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Protocol

from core.params import ChargePoint, Charger
from core.physics.battery import JOULES_PER_KWH
from core.physics.charging import WATTS_PER_KW, ChargeCurve, charge_curve
from core.planning.day.scene import charge_points
from core.planning.day.timeline import next_window, seconds_after
from core.planning.day.verify import Drive, simulate_route
from core.planning.itinerary import ChargeVisit, Itinerary, Windows
from core.planning.model import PlanProblem, PlanResult

#: State of charge charged beyond what the next stretch needs and its reserve [–]: the
#: stretch is simulated again after the charge and may start a little later, in other weather.
PARTIAL_CHARGE_MARGIN = 0.03
#: The way to a charger takes this much more energy per metre than the day's mean drive (it
#: is not simulated before it is chosen; the simulation then checks it).
RETURN_ENERGY_FACTOR = 1.25
#: Most places to charge simulated for one charge, best estimate first: a charger the
#: estimate wrongly thought within reach is skipped for the next.
OPTIONS_TRIED = 3
#: Longest charge planned [s] (a day): a slower charge is no option, and the answer says so.
MAX_CHARGE_S = 86_400.0


class Orders(Protocol):
    """Better orders of a round that charges."""

    def stretch(self, places: list[int]) -> list[int]:
        """A stretch's places in a better order, its first and last kept."""
        ...

    def through(self, chargers: list[int]) -> list[int]:
        """The whole round in its best order with a visit to each of ``chargers`` (place
        indices; one listed twice is visited twice)."""
        ...


def with_charges(day: Drive, itinerary: Itinerary, orders: Orders | None = None) -> PlanResult:
    """The ``itinerary`` driven as ``day`` says and simulated, with charges between stops
    where the battery would not last (none when it does, or without chargers). With
    ``orders``, the round is then solved again through the chargers it visits, and each
    stretch between charges put in its own best order: the best of these that holds is kept
    (:func:`_better_orders`).

    With the day's windows and latest return, a charge is only made where the time it adds
    leaves every later window and the return in time (the forward time slack); its ``busy``
    says when other vans take every point of a charger: the van charges between. The
    itinerary's charges are visits to start from, fitted again: a plan that changed a little
    keeps its charges where they still serve (:attr:`PlanResult.itinerary`)."""
    points = charge_points(day.problem, day.scene.places)
    if itinerary.charges:  # the visits of an earlier plan, fitted again (open when free now)
        order = itinerary.order
        first = {
            q: replace(c, open_s=_open_s(day, order[q], points[order[q]]))
            for q, c in itinerary.charges.items()
        }
        charged = _refitted(day, Itinerary(order, first))
    else:
        charged = _Charged(itinerary, simulate_route(day, itinerary))
    if not points or charged.result.battery.feasible:
        return charged.result
    charged = _charged_until_it_holds(day, points, charged)
    result = charged.result
    planned = charged.itinerary
    reloads = any(planned.reloads_at(q) for q in range(len(planned.order)))
    if orders is not None and planned.charges and result.battery.feasible and not reloads:
        result = _better_orders(day, points, charged, orders)
    if not result.battery.feasible:
        leg = result.first_infeasible_leg
        where = f" on the way to '{result.legs[leg].to_id}'" if leg is not None else ""
        warning = (
            f"even with charging the battery runs below its reserve{where}: no stop before it "
            "lets the van reach an open charger with its reserve, and charge there in the time its "
            "later windows leave (no charger within reach)"
        )
        result = replace(result, warnings=[*result.warnings, warning, *_too_slow(day, points)])
    return result


def _too_slow(day: Drive, points: dict[int, ChargePoint]) -> list[str]:
    """A warning for each charger at which the van would charge from its reserve to full in
    more than :data:`MAX_CHARGE_S` (its charging curve, or the charger, too slow)."""
    reserve = day.problem.van.battery.min_soc
    warnings = []
    for place, point in points.items():
        curve = charge_curve(day.problem.van.battery, point.power_kw * WATTS_PER_KW)
        hours = curve.time_s(reserve, 1.0) / 3600
        if hours * 3600 > MAX_CHARGE_S:
            name = "depot" if place == 0 else f"'{day.scene.places[place].id}'"
            warnings.append(
                f"charging at the {name} charger would take {hours:,.0f} h from the reserve to "
                f"full at {float(curve.power_at_w(reserve)[()]) / 1000:g} kW (the charger's "
                "power and the van's charging_curve): no charge longer than "
                f"{MAX_CHARGE_S / 3600:.0f} h is planned"
            )
    return warnings


def _charged(
    day: Drive, points: dict[int, ChargePoint], charged: _Charged, stretch: tuple[int, int]
) -> _Charged | None:
    """The day with one more charge in ``stretch``: the best of the options
    (:func:`_charge_options`, at most :data:`OPTIONS_TRIED` simulated) that the simulation
    says the van reaches with its reserve and that leaves the day's lowest point higher;
    None when none does."""
    reserve = day.problem.van.battery.min_soc
    itinerary, result = charged.itinerary, charged.result
    for option in _charge_options(day, points, charged, stretch)[:OPTIONS_TRIED]:
        cut = option.cut
        tried = (
            itinerary.with_charge(cut, option.place, option.visit)
            if option.inserted
            else itinerary.charged_at(cut, option.visit)  # at the depot, where the van reloads
        )
        again = _refitted(day, tried)  # filled, then every charge fitted
        simulated = again.result
        reached = simulated.legs[cut if option.inserted else cut - 1].soc_end >= reserve
        if reached and simulated.battery.margin_kwh > result.battery.margin_kwh:
            return again
    return None


@dataclass(frozen=True)
class _Charged:
    """A round's itinerary and its simulation."""

    itinerary: Itinerary
    result: PlanResult


def _charged_until_it_holds(
    day: Drive, points: dict[int, ChargePoint], charged: _Charged
) -> _Charged:
    """``charged`` with one more charge in its first stretch below the reserve, again and
    again, until the battery holds or no charger is within reach."""
    for _ in range(len(charged.itinerary.order)):
        stretch = _first_short_stretch(day.problem, charged)
        if stretch is None:
            break
        tried = _charged(day, points, charged, stretch)
        if tried is None:
            break  # no charger within reach
        charged = tried
    return charged


def _curve(day: Drive, point: ChargePoint, result: PlanResult) -> ChargeCurve:
    """The van's charging curve at ``point`` (on the battery's usable capacity as aged)."""
    battery = day.problem.van.battery
    share = result.battery.usable_capacity_kwh / battery.usable_capacity_kwh
    return charge_curve(battery, point.power_kw * WATTS_PER_KW, share)


def _open_s(day: Drive, place: int, point: ChargePoint) -> Windows:
    """When ``point`` (at ``place``) is open and has a point free [s after the
    departure]; empty: always."""
    date, start = day.problem.date, day.start
    hours = [
        (seconds_after(date, w.start, start), seconds_after(date, w.end, start))
        for w in (point.opening_hours if isinstance(point, Charger) else ())
    ]
    taken = [
        ((a - start).total_seconds(), (b - start).total_seconds())
        for a, b in day.busy.get(place, ())
    ]
    if not taken:
        return hours
    free = _without(hours or [(-math.inf, math.inf)], sorted(taken))
    return free or [(-math.inf, -math.inf)]  # taken all day: never free


def _without(windows: Windows, taken: Windows) -> list[tuple[float, float]]:
    """``windows`` less the sorted spans ``taken``."""
    free: list[tuple[float, float]] = []
    for opens, closes in windows:
        at = opens
        for a, b in taken:
            if b <= at or a >= closes:
                continue
            if a > at:
                free.append((at, a))
            at = max(at, b)
        if at < closes:
            free.append((at, closes))
    return free


def _better_orders(
    day: Drive, points: dict[int, ChargePoint], charged: _Charged, orders: Orders
) -> PlanResult:
    """The best on the objective of the charged round and of others, each with its charges
    fitted again and kept only when its battery holds: the whole round solved again through
    the chargers it visits (the solver then passes them where it costs least; charged more
    where it still runs short), and every stretch between charges in its own best order (of
    either)."""
    order, charges = charged.itinerary.order, charged.itinerary.charges
    chargers = [order[q] for q in sorted(charges)]
    through = orders.through(chargers)
    visits = {
        place: [charges[q] for q in sorted(charges) if order[q] == place] for place in chargers
    }
    again: dict[int, ChargeVisit] = {}
    for q in range(1, len(through) - 1):
        if visits.get(through[q]):
            again[q] = visits[through[q]].pop(0)
    retoured = _charged_until_it_holds(day, points, _refitted(day, Itinerary.of(through, again)))
    best = charged.result
    for candidate in (charged, retoured):
        planned = candidate.itinerary
        stretches = [
            orders.stretch(list(planned.order[a : b + 1]))
            for a, b in itertools.pairwise(planned.stretch_ends())
        ]
        reordered = (planned.order[0], *(place for stretch in stretches for place in stretch[1:]))
        tried = [candidate]
        if reordered != planned.order:
            tried.append(_refitted(day, Itinerary(reordered, planned.charges)))
        for option in tried:
            result = option.result
            if result.battery.feasible and _measure(result) < _measure(best):
                best = result
    return best


def _refitted(day: Drive, itinerary: Itinerary) -> _Charged:
    """The day of ``itinerary`` with its charges fitted to what it takes. A visit left with
    nothing to charge is dropped, and the others fitted again: its detour is no longer driven,
    so the stretch it closed takes less."""
    result = simulate_route(day, itinerary)
    for _ in range(len(itinerary.charges) + 1):
        fitted = _fitted(day.problem, itinerary, result)
        itinerary = itinerary.refitted(fitted)
        result = simulate_route(day, itinerary)
        if len(itinerary.charges) == len(fitted):
            break
    return _Charged(itinerary, result)


def _measure(result: PlanResult) -> float:
    """The round on its objective, as simulated: metres, seconds or kWh."""
    if result.objective == "duration":
        return result.duration_s
    if result.objective == "energy":
        return result.energy_kwh["total"]
    return result.distance_m


def _stretch_low(result: PlanResult, first: int, last: int) -> float:
    """The lowest state of charge over legs ``first`` to ``last − 1`` (a stretch) [–]."""
    legs = result.legs[first:last]
    return min(min(leg.soc_start, leg.soc_end) for leg in legs)


def _first_short_stretch(problem: PlanProblem, charged: _Charged) -> tuple[int, int] | None:
    """The first stretch (from one charge, or the start, to the next) below the reserve."""
    reserve = problem.van.battery.min_soc
    for first, last in itertools.pairwise(charged.itinerary.stretch_ends()):
        if _stretch_low(charged.result, first, last) < reserve - 1e-9:
            return first, last
    return None


@dataclass(frozen=True)
class _Option:
    """Charging at place ``place`` after position ``cut`` of the order (``inserted``), or at
    position ``cut`` itself (the depot, where the van comes back to reload): the time it adds
    [s] and the visit (a full charge, fitted after)."""

    cut: int
    place: int
    added_s: float
    visit: ChargeVisit
    inserted: bool = True


def _charge_options(
    day: Drive, points: dict[int, ChargePoint], charged: _Charged, stretch: tuple[int, int]
) -> list[_Option]:
    """Where the van may charge within ``stretch``, best first: after each stop it leaves
    with its reserve, each charger it reaches with its reserve and that is open long enough
    for the charge, by the time the day gains (the detour, the wait for the opening, the
    plug-in and the charge along the curve at the charger's power; when one charge does not
    cover the rest of the stretch, the rest at another visit like it)."""
    reserve = day.problem.van.battery.min_soc
    legs = day.scene.legs
    order, charges, result = charged.itinerary.order, charged.itinerary.charges, charged.result
    capacity_j = result.battery.usable_capacity_kwh * JOULES_PER_KWH
    driven_j = sum(leg.energy_kwh["traction"] for leg in result.legs) * JOULES_PER_KWH
    per_metre_j = max(driven_j, 0.0) / max(result.distance_m, 1.0) * RETURN_ENERGY_FACTOR
    standing_j = result.energy_kwh["total"] * JOULES_PER_KWH - driven_j
    per_second_j = max(standing_j, 0.0) / max(result.duration_s, 1.0)

    def way_soc(a: int, b: int) -> float:
        """The state of charge the drive from place ``a`` to ``b`` takes, estimated [–]."""
        way_j = per_metre_j * legs.distance_m[a, b] + per_second_j * legs.duration_s[a, b]
        return float(way_j / capacity_j)

    slack = _slack_s(day, order, result)
    options: list[_Option] = []
    for p in range(stretch[0], stretch[1]):
        here, onward = order[p], order[p + 1]
        if p in charges or (p == 0 and here == 0):  # charged here already, or the depot
            continue
        if here == 0 and 0 in points:  # back to reload: charge meanwhile
            at = _reload_charge(day, points[0], p, result, _energy_j(result, p, stretch[1]))
            if at is not None and at.added_s <= slack[p]:
                options.append(at)
        leaving = result.legs[p].soc_start
        left_s = (result.legs[p].depart - day.start).total_seconds()
        rest = _energy_j(result, p + 1, stretch[1]) / capacity_j
        for place, point in points.items():
            if place in (here, onward):
                continue
            come_s = left_s + legs.duration_s[here, place]
            open_s = _open_s(day, place, point)
            hours = next_window(come_s, open_s)
            if hours is None:
                continue
            wait_s = max(hours[0] - come_s, 0.0)
            plugged = leaving - way_soc(here, place) - per_second_j * wait_s / capacity_j
            if leaving < reserve or plugged < reserve + PARTIAL_CHARGE_MARGIN / 2:
                continue
            plug_s = point.plug_minutes * 60
            detour_s = float(
                legs.duration_s[here, place]
                + legs.duration_s[place, onward]
                - legs.duration_s[here, onward]
            )
            needed = reserve + rest + way_soc(place, onward) + PARTIAL_CHARGE_MARGIN
            curve = _curve(day, point, result)
            charge_s = curve.time_s(plugged, min(needed, 1.0))
            if come_s + wait_s + plug_s + charge_s > hours[1] or charge_s > MAX_CHARGE_S:
                continue  # it closes before the charge is done, or it charges too slowly
            added_s = detour_s + wait_s + plug_s + charge_s
            if added_s > slack[p + 1]:
                continue  # a later window or the return would be missed
            if needed > 1.0:  # the rest at another visit like this one
                rate_w = float(curve.power_at_w(reserve)[()]) * curve.efficiency
                added_s += (needed - 1.0) * capacity_j / rate_w + detour_s + plug_s
            full_s = min(curve.time_s(plugged, 1.0), MAX_CHARGE_S)
            visit = ChargeVisit(
                plug_s, full_s, point.power_kw, open_s, price_per_kwh=point.price_per_kwh
            )
            options.append(_Option(p, place, added_s, visit))
    return sorted(options, key=lambda o: (o.added_s, -o.cut))


def _reload_charge(
    day: Drive, point: ChargePoint, p: int, result: PlanResult, rest_j: float
) -> _Option | None:
    """Charging at the depot's ``point`` while the van reloads at position ``p``: the time
    beyond the reload it adds (with any wait for a free point); None when the van comes back
    below its reserve or no point is free for the charge."""
    arriving = result.legs[p - 1].soc_end
    reserve = day.problem.van.battery.min_soc
    come_s = (result.legs[p - 1].arrive - day.start).total_seconds()
    open_s = _open_s(day, 0, point)
    hours = next_window(come_s, open_s)
    if arriving < reserve or hours is None:
        return None
    capacity_j = result.battery.usable_capacity_kwh * JOULES_PER_KWH
    needed = min(reserve + rest_j / capacity_j + PARTIAL_CHARGE_MARGIN, 1.0)
    curve = _curve(day, point, result)
    plug_s = point.plug_minutes * 60
    wait_s = max(hours[0] - come_s, 0.0)
    charge_s = curve.time_s(arriving, needed)
    standing_s = wait_s + plug_s + charge_s
    if come_s + standing_s > hours[1] or charge_s > MAX_CHARGE_S:
        return None  # another van takes the point before the charge is done, or too slow
    added_s = max(standing_s - day.problem.reload_minutes * 60, 0.0)
    full_s = min(curve.time_s(arriving, 1.0), MAX_CHARGE_S)
    visit = ChargeVisit(plug_s, full_s, point.power_kw, open_s, True, point.price_per_kwh)
    return _Option(p, 0, added_s, visit, inserted=False)


def _slack_s(day: Drive, order: Sequence[int], result: PlanResult) -> list[float]:
    """How much later the van may reach each position of ``order`` and still serve every
    later stop inside its window and be back in time [s] (Savelsbergh's forward time slack,
    *ORSA J. Computing* 4 (1992) 146: a delay is absorbed by the waits, then shifts each
    service up to its window's close); infinite without windows and a latest return."""
    if day.windows_s is None and day.latest_return_s is None:
        return [math.inf] * len(order)
    start = day.start
    back_s = (result.legs[-1].arrive - start).total_seconds()
    slack = [math.inf] * len(order)
    if day.latest_return_s is not None:
        slack[-1] = day.latest_return_s - back_s
    stops = {stop.id: stop for stop in result.stops}
    for q in range(len(order) - 2, 0, -1):
        stop = stops.get(day.scene.places[order[q]].id)
        if stop is None:  # a charger: a delay goes on
            slack[q] = slack[q + 1]
            continue
        served_s = (stop.service_start - start).total_seconds()
        windows = day.windows_s[order[q]] if day.windows_s is not None else ()
        window = next_window(served_s, windows)
        closes = math.inf if window is None else window[1]
        slack[q] = stop.wait_s + min(closes - served_s, slack[q + 1])
    return slack


def _energy_j(result: PlanResult, first: int, end: int) -> float:
    """What the round takes from the arrival at position ``first`` of the order to position
    ``end`` (no charge between): its legs and its stops, as simulated [J] (energy, not the
    state of charge, which stops falling at empty)."""
    stops = {stop.id: stop for stop in result.stops}
    legs = result.legs[first:end]
    places = [leg.from_id for leg in legs]
    standing = sum(stops[i].energy_kwh["total"] for i in places if i in stops)
    driving = sum(leg.energy_kwh["total"] for leg in legs)
    return (standing + driving) * JOULES_PER_KWH


def _fitted(
    problem: PlanProblem, itinerary: Itinerary, result: PlanResult
) -> dict[int, ChargeVisit]:
    """Every charge fitted to the stretch after it, from what ``result`` simulated: the state
    of charge each stretch drops by does not depend on where it starts."""
    battery = problem.van.battery
    share = result.battery.usable_capacity_kwh / battery.usable_capacity_kwh
    ends = itinerary.stretch_ends()
    plugged = {charge.arrive: charge.soc_before for charge in result.charges}
    fitted: dict[int, ChargeVisit] = {}
    leaving = result.legs[0].soc_start
    for k in range(1, len(ends) - 1):
        came, here, goes = ends[k - 1], ends[k], ends[k + 1]
        came_in = result.legs[here - 1]
        # what the stretch and the wait for the opening took, as simulated
        waited = came_in.soc_end - plugged.get(came_in.arrive, came_in.soc_end)
        arriving = leaving - (result.legs[came].soc_start - came_in.soc_end) - waited
        drop = result.legs[here].soc_start - _stretch_low(result, here, goes)
        target = (
            1.0
            if battery.charge_to_full
            else min(battery.min_soc + drop + PARTIAL_CHARGE_MARGIN, 1.0)
        )
        visit = itinerary.charges[here]
        curve = charge_curve(battery, visit.power_kw * WATTS_PER_KW, share)
        fitted[here] = replace(visit, charge_s=min(curve.time_s(arriving, target), MAX_CHARGE_S))
        leaving = max(arriving, target)
    return fitted
