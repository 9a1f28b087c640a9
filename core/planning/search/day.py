"""The day as a fleet search sees it, fixed for the whole search: the vans and their shifts in
seconds after the day's first departure, each place's windows, service and demand in the
solver's units, the arcs that exist, and each van's estimates (:class:`FleetDay`); and how one
van's route is simulated (:meth:`FleetDay.simulate`)."""

from __future__ import annotations

import datetime as dt
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from core.arrays import FloatArray
from core.clock import at
from core.exceptions import NoRouteError
from core.params import Place
from core.planning.day.estimates import VanEstimates, van_estimates
from core.planning.day.recharge import with_charges
from core.planning.day.scene import Scene
from core.planning.day.start_state import start_payload_kg
from core.planning.day.timeline import windows_after
from core.planning.day.verify import Busy, Drive, simulate_route
from core.planning.itinerary import Itinerary
from core.planning.model import MAX_ROUND_S, PlanProblem, PlanResult, Solved, place_field
from core.routing.geo import Legs
from core.routing.roads import LegRoute, RoadRouter
from core.routing.units import payload_units_down, payload_units_up
from core.routing.vrp import trips_of


@dataclass(frozen=True)
class VanShift:
    """One van as the search sees it: its round (van, stops, conditions), its earliest
    departure, its latest return (None: the planner's longest round) and whether its battery is
    a constraint (a fleet's vans) or only reported (a single round); the places of the stops
    pinned to it (no other van serves them)."""

    id: str
    problem: PlanProblem
    start: dt.datetime
    end: dt.datetime | None
    pinned: frozenset[int] = frozenset()
    battery_enforced: bool = True


def leg_roads(router: RoadRouter, places: list[Place], order: list[int]) -> list[LegRoute]:
    """The router's road of every leg of ``order``; a leg with no road names its destination."""
    roads = []
    for i, j in itertools.pairwise(order):
        try:
            roads.append(router.route(places[i], places[j]))
        except NoRouteError as error:
            raise NoRouteError(error.message, place_field(j)) from None
    return roads


@dataclass(frozen=True)
class FleetDay:
    """The fixed facts of one fleet search; times in seconds after ``reference``.

    Attributes
    ----------
    scene
        The places, their legs, the zone and the weather.
    router
        For the roads of the legs driven (OSRM), or None.
    shifts
        The vans.
    reference
        The day's first departure.
    shift_s
        Each van's earliest departure and latest return [s].
    horizon_s
        The latest return of any van [s].
    windows_s
        Each place's time windows [s] (the depot's none).
    service_s, demand_g
        Each place's service time [s] and delivery [g] (the depot's 0).
    finite, duration_s
        Which arcs have a road, and the matrix's driving time (0 where none) [s].
    unreachable
        Places with no road from or to the depot.
    estimates
        Each van's estimates (vans of one kind share them).
    starts
        The place each van sets off from: the depot (0), or its position when it is under way
        (a place after the stops).
    """

    scene: Scene
    router: RoadRouter | None
    shifts: list[VanShift]
    reference: dt.datetime
    shift_s: list[tuple[float, float]]
    horizon_s: int
    windows_s: list[list[tuple[float, float]]]
    service_s: FloatArray
    demand_g: NDArray[np.int64]
    finite: NDArray[np.bool_]
    duration_s: FloatArray
    unreachable: frozenset[int]
    estimates: list[VanEstimates]
    starts: list[int]

    @property
    def n(self) -> int:
        """The solver's places: the depot, the stops and the positions of the vans under way
        (the chargers come after them)."""
        return len(self.finite)

    @property
    def stop_nodes(self) -> range:
        """The stops' places."""
        return range(1, len(self.shifts[0].problem.stops) + 1)

    @cached_property
    def pinned_to(self) -> dict[int, int]:
        """The van each pinned stop's place is pinned to."""
        return {node: v for v, shift in enumerate(self.shifts) for node in shift.pinned}

    def may_serve(self, v: int, node: int) -> bool:
        """Whether van ``v`` may serve the place ``node``: not pinned to another van."""
        return self.pinned_to.get(node, v) == v

    def vans_for(self, node: int) -> list[int]:
        """The vans that may serve the place ``node``: the one it is pinned to, else all."""
        pinned = self.pinned_to.get(node)
        return list(self.vans) if pinned is None else [pinned]

    def forbidden(self, v: int) -> frozenset[int]:
        """The places van ``v`` may not serve: the stops pinned to other vans."""
        return frozenset(node for node, u in self.pinned_to.items() if u != v)

    def order(self, v: int, route: Sequence[int]) -> list[int]:
        """The places van ``v`` drives for ``route``: from where it sets off, back to the depot."""
        return [self.starts[v], *route, 0]

    @property
    def vans(self) -> range:
        return range(len(self.shifts))

    def carries(self, v: int, route: Sequence[int]) -> bool:
        """Whether van ``v`` carries ``route`` (stops, a 0 between them a return to reload):
        no more trips than its ``max_trips``, none heavier than its payload."""
        problem = self.shifts[v].problem
        trips = trips_of(route)
        payload = payload_units_down(problem.van.payload_kg)
        if route[:1] == [0]:  # under way, back to reload first
            trips = [[], *trips]
        first = payload_units_down(start_payload_kg(problem))  # under way: what is aboard
        return len(trips) <= problem.max_trips and all(
            int(self.demand_g[trip].sum()) <= (first if k == 0 else payload)
            for k, trip in enumerate(trips)
        )

    def clock(self, seconds: float) -> str:
        """A moment of the day as local HH:MM ("never" for infinity)."""
        if not math.isfinite(seconds):
            return "never"
        return f"{at(self.reference, seconds):%H:%M}"

    def simulate(self, v: int, route: list[int]) -> PlanResult:
        """The full simulation of van ``v`` driving ``route`` (stops; the depot around it)."""
        return simulate_route(self._drive(v, route), Itinerary.of(self.order(v, route)))

    def charged(self, v: int, itinerary: Itinerary, busy: Busy) -> PlanResult:
        """Van ``v`` driving ``itinerary`` with its charges fitted again and more where its
        battery would not last (:func:`core.planning.day.recharge.with_charges`): its windows
        and its shift kept, the charge points free when ``busy`` says other vans do not take
        them all."""
        stops = [place for place in itinerary.order[1:-1] if place in self.stop_nodes]
        return with_charges(self._drive(v, stops, busy), itinerary)

    def _drive(self, v: int, route: list[int], busy: Busy | None = None) -> Drive:
        """Van ``v``'s round of ``route`` as its simulations see it: windows from its own
        departure, the router's roads when the legs came from it, back by its shift's end."""
        shift = self.shifts[v]
        solved = Solved(
            status="feasible", objective_value=self.estimates[v].route_cost(route), runtime_s=0.0
        )
        windows, latest_s = self._limits(v)
        return Drive(
            shift.problem, self.scene, shift.start, self._roads, solved, windows, latest_s,
            busy or {},
        )  # fmt: skip

    def _roads(self, order: list[int]) -> list[LegRoute] | None:
        if self.router is None or self.scene.legs.source != "osrm":
            return None
        return leg_roads(self.router, self.scene.places, order)

    def _limits(self, v: int) -> tuple[list[list[tuple[float, float]]], float | None]:
        """Van ``v``'s windows of every place [s after its departure] and its latest return."""
        shift = self.shifts[v]
        origin = self.reference.timestamp() - shift.start.timestamp()
        windows = [[(a + origin, b + origin) for a, b in place] for place in self.windows_s]
        windows += [[] for _ in range(len(self.scene.places) - len(windows))]  # the chargers
        latest_s = None if shift.end is None else shift.end.timestamp() - shift.start.timestamp()
        return windows, latest_s


def fleet_day(
    shifts: list[VanShift],
    scene: Scene,
    router: RoadRouter | None,
    starts: Sequence[int] | None = None,
) -> FleetDay:
    """The day of ``shifts`` on ``scene``: the shared facts and each kind of van's estimates.
    ``starts``: where each van sets off (its position's place, after the stops, when under
    way; by default the depot)."""
    base = shifts[0].problem
    starts = list(starts or [0] * len(shifts))
    solver_places = max([len(base.stops) + 1, *(k + 1 for k in starts)])
    reference = min(shift.start for shift in shifts)
    origin = reference.timestamp()
    shift_s = [
        (
            shift.start.timestamp() - origin,
            (shift.end or at(shift.start, MAX_ROUND_S)).timestamp() - origin,
        )
        for shift in shifts
    ]
    legs = scene.legs.first(solver_places)  # not the chargers
    finite = np.isfinite(legs.duration_s) & np.isfinite(legs.distance_m)
    service_s = np.zeros(solver_places)
    service_s[1 : len(base.stops) + 1] = [math.ceil(s.service_time_s) for s in base.stops]
    demand_g = np.zeros(solver_places, dtype=np.int64)
    demand_g[1 : len(base.stops) + 1] = payload_units_up([s.delivery_kg for s in base.stops])
    solver_legs = long_where_no_road(legs, finite)
    kinds: dict[str, VanEstimates] = {}
    estimates = []
    for shift, start in zip(shifts, starts, strict=True):
        key = f"{shift.problem.van.model_dump_json()}@{shift.start.isoformat()}"
        if key not in kinds:
            kinds[key] = van_estimates(
                shift.problem, solver_legs, shift.start, base.stops, service_s
            )
        estimates.append(kinds[key] if not start else replace(kinds[key], start=start))
    return FleetDay(
        scene=scene,
        router=router,
        shifts=shifts,
        reference=reference,
        shift_s=shift_s,
        horizon_s=math.floor(max(end for _, end in shift_s)),
        windows_s=windows_after(base.stops, base.date, reference)
        + [[] for _ in range(solver_places - len(base.stops) - 1)],
        service_s=service_s,
        demand_g=demand_g,
        finite=finite,
        duration_s=np.where(finite, legs.duration_s, 0.0),
        unreachable=frozenset(legs.unreachable()),
        estimates=estimates,
        starts=starts,
    )


def long_where_no_road(legs: Legs, finite: NDArray[np.bool_]) -> Legs:
    """The legs with the arcs that have no road made long (the solver never picks them)."""
    if finite.all():
        return legs
    far_m = float(np.nanmax(legs.distance_m)) * 10 + 1e6
    far_s = float(np.nanmax(legs.duration_s)) * 10 + 1e5
    return Legs(
        distance_m=np.where(finite, legs.distance_m, far_m),
        duration_s=np.where(finite, legs.duration_s, far_s),
        grade=legs.grade,
        street_type=legs.street_type,
        source=legs.source,
        snap_distance_m=legs.snap_distance_m,
    )
