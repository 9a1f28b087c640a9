"""Charging in a fleet's day: the E-VRPTW search (:mod:`core.routing.evrp`) plans the routes,
the chargers between their stops and what to charge at each, on the planning layer's
estimates; every route is then verified by the full simulation of its day with its charges
fitted, the charge points booked across the fleet, and repaired where the simulation refuses.

1. **The search's instance** (:func:`charging_instance`): the day's places, the chargers on
   the way and the depot's charger (a place of its own in the search: a van comes back to
   charge), each arc's cost on the objective, its driving time (the times the simulation
   taught the search) and, per kind of van, its energy (traction by the arc's grade for the
   van's mass, the standing loads by its duration, each stop's service and door openings at
   its origin: :mod:`core.planning.day.estimates`); each van kind's battery between its reserve
   and full, what it holds at departure, its payload, its shift (its latest return less the
   driver's breaks the shift holds) and where it sets off; each
   charger's charge time per joule (the van's charging curve at the charger's power, reserve
   to 80 %), its plug-in time, its points when fewer than the vans (the search shares them
   out) and when it is closed (outside its opening hours); each stop's window (the first
   opening to the last close).
2. **The search** starts from the two best of its own routes of the stops, found with and
   without part of the charging time in the arcs (when every van leaves the depot), and the
   routes the fleet's search found without charging (the stops left out inserted where they
   cost least), each with half the work, keeps the better, and serves every stop it can,
   then fewest vans (when asked), then the objective. When its routes hold (3.), the work
   kept for searching again with a smaller battery searches on from them.
3. **Verification**: each route is simulated with its charges fitted to what the simulation
   says each stretch takes (:func:`core.planning.day.recharge.with_charges`), the charge points
   free only between the other vans' charges as simulated (:class:`Bookings`: the search
   shared them out on its estimates). A route the simulation
   refuses loses the stop it names, else the costliest, until it holds
   (:func:`core.planning.search.repair.repair`).

The fleet keeps whichever serves more stops — then fewer vans when asked, then the lower
objective — of the routes without charging and these.
"""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from core.params import BatteryParams, ChargePoint, Charger
from core.physics.battery import JOULES_PER_KWH
from core.physics.charging import WATTS_PER_KW, charge_curve
from core.planning.day.estimates import cost_matrix, energy_matrix_j
from core.planning.day.scene import charge_points
from core.planning.day.start_state import start_payload_kg
from core.planning.day.timeline import EU_BREAK_S, MAX_DRIVING_S, seconds_after
from core.planning.day.verify import Busy, Failure, route_failure
from core.planning.itinerary import ChargeVisit, Itinerary
from core.planning.model import DEPOT_CHARGER_ID, PlanProblem, PlanResult
from core.planning.search.day import FleetDay, long_where_no_road
from core.planning.search.repair import Repaired, repair
from core.routing.effort import Effort, SearchEnd, combined
from core.routing.evrp import (
    EvrpInstance,
    EvrpSolution,
    VehicleKind,
    solve_evrptw,
)
from core.routing.geo import Legs
from core.routing.points import Span, full_spans, outside
from core.routing.units import payload_units_down

#: State of charge the charge time per joule is taken up to (the curve's constant part).
CHARGE_TIME_SOC = 0.8
#: The share of each van's battery (and of its charge at departure) the search plans with when
#: no route found without charging says how far the estimates fall short of the simulation
#: (:func:`battery_margin`): the estimates do not see every draw of the simulation (the weather
#: through the day, the standing loads while waiting). Small: a route the simulation finds
#: short makes its kind's battery smaller by the shortfall (:func:`charging_routes`), and every
#: percent held back is range lost where the estimates are right (0.9 cost c101 4 % distance,
#: r101 a van).
BATTERY_MARGIN = 0.98
#: The least share of the battery the search plans with, however short the estimates fell.
MIN_BATTERY_MARGIN = 0.85
#: Searches at most (the first, then again after routes the simulation refused for their
#: battery), the first's share of the work, and how many times what a route fell below its
#: reserve its kind of van's battery is made smaller after.
CHARGING_ROUNDS = 3
FIRST_SHARE = 0.85
TIGHTEN_MARGIN = 1.2
#: And at least this share of the battery: a route that ends a rounding below its reserve
#: would otherwise send the search back to the same routes. Likewise a route back after its
#: shift makes its kind's latest return earlier, by at least this [s].
MIN_TIGHTEN_SHARE = 0.01
MIN_TIGHTEN_S = 300.0


@dataclass(frozen=True)
class Short:
    """By kind of van, the most a simulated route fell below its reserve [J] and came back
    after its shift [s]: what the search's estimates missed."""

    energy_j: dict[int, float] = field(default_factory=dict)
    late_s: dict[int, float] = field(default_factory=dict)

    def __bool__(self) -> bool:
        return bool(self.energy_j or self.late_s)


@dataclass
class Bookings:
    """The charges of the fleet's vans on each charge point (by place index): who is plugged
    in from when to when."""

    points: dict[int, ChargePoint]
    spans: dict[int, list[tuple[dt.datetime, dt.datetime, str]]] = field(default_factory=dict)

    def book(self, van_id: str, place_of: dict[str, int], result: PlanResult) -> None:
        """Van ``van_id``'s charges, in place of any it had before."""
        for place, spans in self.spans.items():
            self.spans[place] = [s for s in spans if s[2] != van_id]
        for charge in result.charges:  # plugged in: from after any wait to the departure
            place = 0 if charge.charger_id == DEPOT_CHARGER_ID else place_of[charge.charger_id]
            plugged = dt.timedelta(minutes=charge.minutes + self.points[place].plug_minutes)
            self.spans.setdefault(place, []).append(
                (charge.depart - plugged, charge.depart, van_id)
            )

    def busy(self, van_id: str) -> Busy:
        """When the other vans take every point of each charger."""
        out: dict[int, list[tuple[dt.datetime, dt.datetime]]] = {}
        for place, spans in self.spans.items():
            others = [(a, b) for a, b, v in spans if v != van_id]
            out[place] = full_spans(others, self.points[place].points)
        return out


@dataclass(frozen=True)
class ChargingInstance:
    """The search's instance of a fleet's day, and how to read its answer: the product's
    place of each of the search's places (the depot's charger and the returns to reload are
    the depot), the vans of each kind, each charger's plug-in time [s] and power [kW], and the
    search's places that are returns to reload."""

    instance: EvrpInstance
    place_of: list[int]
    vans_of: list[list[int]]
    points: dict[int, ChargePoint]
    reloads: frozenset[int] = frozenset()


def charging_instance(
    day: FleetDay, times_s: np.ndarray, minimize_vehicles: bool, margin: float = BATTERY_MARGIN
) -> ChargingInstance:
    """The E-VRPTW instance of ``day`` (module docstring, item 1); ``times_s`` the driving
    times the simulation taught the search (the day's solver places); ``margin`` the share of
    each battery it plans with."""
    problem = day.shifts[0].problem
    places = day.scene.places
    points = charge_points(problem, places)
    every = day.scene.legs
    legs = long_where_no_road(every, np.isfinite(every.duration_s) & np.isfinite(every.distance_m))
    place_of = list(range(len(places))) + ([0] if 0 in points else [])
    stations = [q for q, p in enumerate(place_of) if p in points and (q > 0)]
    reload_place = {}  # a return to reload: a place of the depot's, one per reload time
    for reload_s in sorted({_reload_s(day, v) for v in day.vans if _reloads(day, v)}):
        reload_place[reload_s] = len(place_of)
        place_of.append(0)
    at = np.array(place_of)
    arcs = np.ix_(at, at)
    n = day.n
    duration = legs.duration_s.copy()
    taught = day.finite & (day.duration_s > 0)
    ratio = float(times_s[taught].sum() / max(day.duration_s[taught].sum(), 1e-9))
    duration *= ratio if taught.any() else 1.0
    duration[:n, :n] = np.where(day.finite, times_s, duration[:n, :n])
    arc_cost, unit_value, _ = cost_matrix(problem, legs, day.shifts[0].start)
    ready, due, service = _windows(day, len(place_of), stations, place_of, points)
    for reload_s, q in reload_place.items():
        service[q] = reload_s
    chargers = {q: points[place_of[q]] for q in stations}
    kinds, vans_of = _kinds(day, legs, (arcs, len(place_of)), (reload_place, margin), chargers)
    instance = EvrpInstance(
        distance=arc_cost[arcs].astype(float) * unit_value,
        duration=duration[arcs],
        ready=ready,
        due=due,
        service=service,
        demand=np.concatenate([day.demand_g, np.zeros(len(place_of) - n)]).astype(float),
        customers=[k for k in day.stop_nodes if k not in day.unreachable],
        stations=stations,
        charge_time=_charge_times(problem.van.battery, chargers, len(place_of)),  # its start's
        kinds=kinds,
        fewest_vehicles=minimize_vehicles,
        points={q: c.points for q, c in chargers.items() if c.points < len(day.vans)},
        closed={q: _closed_s(day, c) for q, c in chargers.items() if _closed_s(day, c)},
    )
    return ChargingInstance(instance, place_of, vans_of, points, frozenset(reload_place.values()))


def _windows(
    day: FleetDay,
    size: int,
    stations: Sequence[int],
    place_of: Sequence[int],
    points: dict[int, ChargePoint],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each place's window (a stop's first opening to its last close; the depot's the day)
    and service [s]: a stop's, a charger's plug-in and out."""
    ready, due, service = np.zeros(size), np.full(size, float(day.horizon_s)), np.zeros(size)
    for k, windows in enumerate(day.windows_s):
        if windows:
            ready[k], due[k] = windows[0][0], windows[-1][1]
    service[: day.n] = day.service_s
    for q in stations:
        service[q] = points[place_of[q]].plug_minutes * 60.0
    return ready, due, service


def _closed_s(day: FleetDay, point: ChargePoint) -> list[Span]:
    """When ``point`` is closed [s after the day's reference]: outside its opening hours."""
    date = day.shifts[0].problem.date
    hours = point.opening_hours if isinstance(point, Charger) else []
    return outside(
        [
            (seconds_after(date, w.start, day.reference), seconds_after(date, w.end, day.reference))
            for w in hours
        ]
    )


def _breaks_s(problem: PlanProblem, shift_s: tuple[float, float]) -> float:
    """The driver's breaks a shift of ``shift_s`` holds [s], kept off the search's latest
    return (the search does not place them; the simulation does, and a route that comes
    back late for them loses stops): under EU 561 a 45-minute break for every 4 h 30 of
    driving the shift leaves room for, fixed breaks as given."""
    if isinstance(problem.breaks, list):
        return sum(rest.minutes for rest in problem.breaks) * 60.0
    if problem.breaks != "eu-561":
        return 0.0
    return math.floor((shift_s[1] - shift_s[0]) / (MAX_DRIVING_S + EU_BREAK_S)) * EU_BREAK_S


def _reloads(day: FleetDay, v: int) -> bool:
    return day.shifts[v].problem.max_trips > 1


def _reload_s(day: FleetDay, v: int) -> float:
    return day.shifts[v].problem.reload_minutes * 60.0


def _kinds(
    day: FleetDay,
    legs: Legs,
    places: tuple[tuple[np.ndarray, ...], int],
    reloads: tuple[dict[float, int], float],
    chargers: dict[int, ChargePoint],
) -> tuple[list[VehicleKind], list[list[int]]]:
    """The fleet's kinds — vans alike in estimates, shift, start, what they carry at first,
    their trips and the stops they may not serve — and their vans; a return to reload
    (``reloads``: its place by the reload's time) draws the van's standing loads for the
    reload's time; each kind charges at ``chargers`` (by the search's place) along its own
    charging curve, on the ``reloads``' margin's share of its battery. ``places``: the
    search's places as arcs of the day's, and how many."""
    (arcs, size), (reload_place, margin) = places, reloads
    groups: dict[tuple[object, ...], list[int]] = {}
    for v in day.vans:
        problem = day.shifts[v].problem
        trips = (problem.max_trips, problem.reload_minutes, start_payload_kg(problem))
        key = (id(day.estimates[v]), day.shift_s[v], day.starts[v], trips, day.forbidden(v))
        groups.setdefault(key, []).append(v)
    kinds = []
    for vans in groups.values():
        v = vans[0]
        shift = day.shifts[v]
        problem = shift.problem
        estimates = day.estimates[v]
        energy = energy_matrix_j(problem, legs, shift.start)
        energy[: day.n, : day.n] = estimates.energy_j
        energy = energy[arcs]
        reload = reload_place[_reload_s(day, v)] if _reloads(day, v) else -1
        if reload >= 0:
            energy[reload] += estimates.standing_w * _reload_s(day, v)
        battery = problem.van.battery
        window = battery.initial_soc - battery.min_soc
        kinds.append(
            VehicleKind(
                count=len(vans),
                energy=energy,
                battery=estimates.budget_j * (1.0 - battery.min_soc) / window * margin,
                initial=estimates.budget_j * margin if shift.battery_enforced else math.inf,
                capacity=float(payload_units_down(problem.van.payload_kg)),
                start=day.starts[v],
                ready=day.shift_s[v][0],
                due=day.shift_s[v][1] - _breaks_s(problem, day.shift_s[v]),
                aboard=float(payload_units_down(start_payload_kg(problem))),
                reload=reload,
                max_trips=problem.max_trips,
                charge_time=_charge_times(battery, chargers, size),
                forbidden=day.forbidden(v),  # the search's places of the stops are the day's
            )
        )
    return kinds, list(groups.values())


def _charge_times(
    battery: BatteryParams, chargers: dict[int, ChargePoint], size: int
) -> np.ndarray:
    """Time to charge a joule [s/J] at each of the search's ``size`` places, at the
    ``chargers`` (by place) along the ``battery``'s curve."""
    seconds_per_j = np.zeros(size)
    for q, point in chargers.items():
        seconds_per_j[q] = _seconds_per_joule(battery, point)
    return seconds_per_j


def _seconds_per_joule(battery: BatteryParams, point: ChargePoint) -> float:
    """Time to charge a joule at ``point`` [s/J]: the ``battery``'s charging curve at the
    point's power, from its reserve to :data:`CHARGE_TIME_SOC`."""
    curve = charge_curve(battery, point.power_kw * WATTS_PER_KW)
    top = max(CHARGE_TIME_SOC, battery.min_soc + 0.05)
    joules = (top - battery.min_soc) * battery.usable_capacity_kwh * JOULES_PER_KWH
    return curve.time_s(battery.min_soc, top) / joules


@dataclass(frozen=True)
class Charging:
    """The fleet's routes (stops per van) with charging, their simulations, the stops the
    verification took out with why, and how the search ended."""

    routes: list[list[int]]
    results: dict[int, PlanResult]
    removed: dict[int, Failure]
    ended: SearchEnd


def measure(
    day: FleetDay, routes: list[list[int]], results: dict[int, PlanResult], fewest_vans: bool
) -> tuple[int, int, float]:
    """Stops left out, vans driving (when fewer vans come first) and the objective's value
    of the simulated days: the lower the better."""
    served = sum(1 for route in routes for node in route if node)
    objective = day.shifts[0].problem.objective
    value = sum(
        r.distance_m if objective == "distance" else r.duration_s if objective == "duration"
        else r.energy_kwh["total"]
        for v, r in results.items()
        if routes[v]
    )  # fmt: skip
    vans = sum(1 for route in routes if route) if fewest_vans else 0
    return -served, vans, value


def battery_margin(
    day: FleetDay, routes: list[list[int]], results: Mapping[int, PlanResult]
) -> float:
    """The share of the batteries the charging search plans with: over the simulated routes
    found without charging (one trip, no charge), the energy the estimates gave them over what
    the simulation drew from the battery, together — at most 1, at least
    :data:`MIN_BATTERY_MARGIN`; :data:`BATTERY_MARGIN` when no route says. Together, not the
    worst route's: a route the simulation finds short makes its kind's battery smaller by its
    shortfall (:func:`charging_routes`), and each percent held back for the worst is range
    lost on every route (on the Vienna day of the benchmark the worst route's 0.914 against
    0.942 together cost a third charge and 8 km)."""
    estimated_kwh = drawn_kwh = 0.0
    for v, result in results.items():
        if not routes[v] or result.charges or 0 in routes[v]:
            continue
        battery = result.battery
        drawn = (result.legs[0].soc_start - battery.final_soc) * battery.usable_capacity_kwh
        if drawn > 0:
            estimated_kwh += day.estimates[v].route_energy_j(routes[v]) / JOULES_PER_KWH
            drawn_kwh += drawn
    if not drawn_kwh:
        return BATTERY_MARGIN
    return min(max(estimated_kwh / drawn_kwh, MIN_BATTERY_MARGIN), 1.0)


def charging_routes(
    day: FleetDay,
    times_s: np.ndarray,
    found: tuple[list[list[int]], Mapping[int, PlanResult]],
    minimize_vehicles: bool,
    effort: Effort,
) -> Charging:
    """The fleet's routes with charging (module docstring), from the best starts of the
    search's own (every van at the depot) and ``routes`` (stops per van, a 0 a return to
    reload) found without. A route whose simulation runs below its reserve
    makes its kind of van's battery (and its charge at departure) smaller in the search by what
    the simulation fell below the reserve, one back after its shift the kind's latest return
    earlier by its lateness (:func:`_tightened`), and the search starts
    again from ``routes`` (which hold without charging; the routes it found may not hold with
    the smaller battery even when charged), at most
    :data:`CHARGING_ROUNDS` times; the best verified routes are kept. When the first
    search's routes hold, the work the other rounds would have had searches on from them
    (without PyVRP's starts: the routes are the best the search knows)."""
    routes, results = found
    charging = charging_instance(
        day, times_s, minimize_vehicles, battery_margin(day, routes, results)
    )
    kind_of = {v: k for k, vans in enumerate(charging.vans_of) for v in vans}
    kinds = charging.instance.kinds
    initial = [
        (kind_of[v], _with_reloads(route, kinds[kind_of[v]].reload))
        for v, route in enumerate(routes)
        if route
    ]
    best: Charging | None = None
    ends: list[SearchEnd] = []
    for round_ in range(CHARGING_ROUNDS):
        share = FIRST_SHARE if not round_ else (1.0 - FIRST_SHARE) / (CHARGING_ROUNDS - 1)
        solution = solve_evrptw(charging.instance, effort.share(share), initial)
        ends.append(solution.ended)
        verified, short = _verified(day, charging, solution)
        if best is None or _ranked(day, verified, minimize_vehicles) < _ranked(
            day, best, minimize_vehicles
        ):
            best = verified
        if solution.ended == "time_limit":
            break
        if not short:
            if not round_:  # the rounds' work unspent: searched on from these routes
                rest = effort.share(1.0 - FIRST_SHARE)
                solution = solve_evrptw(charging.instance, rest, solution.searched, own=False)
                ends.append(solution.ended)
                further, _ = _verified(day, charging, solution)
                if _ranked(day, further, minimize_vehicles) < _ranked(day, best, minimize_vehicles):
                    best = further
            break
        charging = replace(charging, instance=_tightened(charging.instance, short))
    assert best is not None
    return replace(best, ended=combined(ends))


def _with_reloads(route: list[int], reload: int) -> list[int]:
    """The stops of ``route`` for the search: a return to reload (a 0) as the kind's place
    for it, or none when the kind does not reload."""
    return [place or reload for place in route if place or reload >= 0]


def _ranked(day: FleetDay, charging: Charging, fewest_vans: bool) -> tuple[int, int, float]:
    return measure(day, charging.routes, charging.results, fewest_vans)


def _tightened(instance: EvrpInstance, short: Short) -> EvrpInstance:
    """Each kind's battery and charge at departure less what its simulated routes fell below
    the reserve, and its latest return earlier by how late they came back, each
    :data:`TIGHTEN_MARGIN` times, at least :data:`MIN_TIGHTEN_SHARE` of the battery and
    :data:`MIN_TIGHTEN_S`."""

    def less(k: int, kind: VehicleKind) -> VehicleKind:
        if k in short.energy_j:
            cut = max(short.energy_j[k] * TIGHTEN_MARGIN, kind.battery * MIN_TIGHTEN_SHARE)
            kind = replace(kind, battery=kind.battery - cut, initial=kind.initial - cut)
        if k in short.late_s:
            kind = replace(
                kind, due=kind.due - max(short.late_s[k] * TIGHTEN_MARGIN, MIN_TIGHTEN_S)
            )
        return kind

    return replace(instance, kinds=[less(k, kind) for k, kind in enumerate(instance.kinds)])


def _verified(
    day: FleetDay, charging: ChargingInstance, solution: EvrpSolution
) -> tuple[Charging, Short]:
    """Each route of ``solution`` given to a van of its kind, simulated with its charges
    fitted and the charge points booked, repaired until it holds; and by kind, what the
    routes' first simulations fell short by."""
    places = day.scene.places
    bookings = Bookings(charging.points)
    index = {place.id: k for k, place in enumerate(places)}
    routes: list[list[int]] = [[] for _ in day.vans]
    results: dict[int, PlanResult] = {}
    removed: dict[int, Failure] = {}
    short = Short()
    free = [list(vans) for vans in charging.vans_of]
    for route in solution.routes:
        v = free[route.kind].pop(0)
        order = [charging.place_of[visit.place] for visit in route.visits]
        charges = {
            q: _visit(charging, route.kind, order[q], visit.place, visit.charge)
            for q, visit in enumerate(route.visits)
            if 0 < q < len(order) - 1 and visit.place in charging.instance.stations
        }
        reloads = [q for q, visit in enumerate(route.visits) if visit.place in charging.reloads]
        itinerary = Itinerary.of(order, charges).reloading_while_charging(reloads)
        repaired, first = _held(day, v, itinerary, bookings)
        if first is not None and first.battery.margin_kwh < 0:
            below_j = -first.battery.margin_kwh * JOULES_PER_KWH
            short.energy_j[route.kind] = max(short.energy_j.get(route.kind, 0.0), below_j)
        end = day.shifts[v].end
        if first is not None and end is not None and first.legs[-1].arrive > end:
            late_s = (first.legs[-1].arrive - end).total_seconds()
            short.late_s[route.kind] = max(short.late_s.get(route.kind, 0.0), late_s)
        routes[v] = repaired.route
        removed |= repaired.removed
        if repaired.result is not None:
            results[v] = repaired.result
            bookings.book(day.shifts[v].id, index, repaired.result)
    return Charging(routes, results, removed, solution.ended), short


def _visit(
    charging: ChargingInstance, kind: int, place: int, q: int, charge_j: float
) -> ChargeVisit:
    """The charge of ``charge_j`` [J] at the search's place ``q`` (the day's ``place``) by a
    van of ``kind``, at its charging curve."""
    instance = charging.instance
    charge_s = charge_j * float(instance.charge_time_of(kind)[q])
    point = charging.points[place]
    return ChargeVisit(
        instance.service[q], charge_s, point.power_kw, price_per_kwh=point.price_per_kwh
    )


def _held(
    day: FleetDay, v: int, itinerary: Itinerary, bookings: Bookings
) -> tuple[Repaired, PlanResult | None]:
    """Van ``v`` driving ``itinerary`` with its charges fitted — else its stops with the
    charges the planner places itself (:func:`core.planning.day.recharge.with_charges`) —,
    stops taken out until its simulation holds (the chargers stay where they are); and its
    first simulation when neither held."""
    shift = day.shifts[v]
    busy = bookings.busy(shift.id)
    stops = itinerary.served()  # a charge at the depot while the van reloads reloads too

    def simulate(kept: list[int]) -> PlanResult:
        return day.charged(v, itinerary.keeping(set(kept)), busy)

    def check(_kept: list[int], result: PlanResult) -> Failure | None:
        return route_failure(shift.id, shift.problem, day.scene.places, result, shift.end, True)

    result = simulate(stops)
    failure = check(stops, result)
    if failure is None:
        return Repaired(stops, result, {}), None
    # the planner's own charges (a charge point the others take, a stretch the estimates
    # made too long), before any stop goes
    own = day.charged(v, Itinerary.of(day.order(v, stops)), busy)
    if check(stops, own) is None:
        return Repaired(stops, own, {}), None
    return repair(stops, failure, simulate, check, day.estimates[v]), result
