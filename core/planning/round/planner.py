"""A delivery round from depot, stops and date to a simulated round trip (paper §4, Fig. 7).

1. legs between every ordered pair (:mod:`core.routing.geo`: the client's matrix, a road
   router's table or the estimate); 2. the order of the stops on the chosen objective: the
   round trip (:mod:`core.routing.tsp`), or, when stops have time windows, the fleet search of
   :mod:`core.planning.search.fleet` with this one van; 3. the day driven and simulated in full
   (:mod:`core.planning.day.verify`), with the weather for the round's span (a forecast service,
   the request, or the climatology).
"""

from __future__ import annotations

import datetime as dt
import time
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from core.clock import check_representable, departure
from core.exceptions import (
    InvalidStopsError,
    LimitExceededError,
    NoRouteError,
)
from core.params import Place
from core.physics.weather import WeatherService
from core.planning.day.estimates import cost_matrix
from core.planning.day.recharge import with_charges
from core.planning.day.scene import (
    Scene,
    charge_points,
    legs_for,
    round_field,
    round_places,
    weather_service_for,
)
from core.planning.day.start_state import check_start, path_tour, under_way
from core.planning.day.timeline import client_legs_too_fast, windows_after
from core.planning.day.verify import Drive
from core.planning.itinerary import Itinerary
from core.planning.model import (
    MAX_ROUND_S,
    START_ID,
    PlanProblem,
    PlanResult,
    Solved,
    check_places,
    cut_short,
    replay_of,
)
from core.planning.round.reloads import check_payload, with_reloads
from core.planning.search.day import VanShift, fleet_day, leg_roads
from core.planning.search.fleet import search
from core.routing.effort import Effort, SearchEnd, combined
from core.routing.geo import Legs
from core.routing.roads import LegRoute, RememberingRouter, RoadRouter
from core.routing.tsp import Tour, solve_path, solve_tour

#: Search work for each stretch between charges of a round [reference s]: stretches are short
#: enough for CP-SAT's proof within it.
TRIP_WORK_S = 0.2


def plan(
    problem: PlanProblem,
    router: RoadRouter | None = None,
    weather_service: WeatherService | None = None,
) -> PlanResult:
    """Solve the round trip on the chosen objective and simulate it in full (paper Fig. 7).

    Parameters
    ----------
    problem
        The round.
    router
        A road router for the distance matrix and the legs' roads; used unless the problem
        carries the client's own matrix. Its failures propagate
        (:class:`core.exceptions.ServiceUnavailableError`): a plan is never silently made on
        estimated roads when real ones were asked for.
    weather_service
        An hourly forecast for the round's span; used unless the problem carries its own
        weather. When it fails the round is planned on the climatology and ``warnings`` says
        so.
    """
    started = time.perf_counter()
    effort = problem.effort(problem.time_limit_s, problem.replay_limit_s)
    start, timezone_name = check(problem)
    problem = under_way(problem)
    places = round_places(problem)
    legs = legs_for(problem, router, places)
    _check_reachable(problem, places, legs)
    too_fast = client_legs_too_fast(legs, problem.van.vehicle.max_acceleration_mps2)
    scene = Scene(
        places,
        legs,
        timezone_name,
        weather_service_for(problem, weather_service),
        (too_fast,) if too_fast else (),
    )
    windowed = any(stop.time_windows for stop in problem.stops)
    if windowed and not problem.keep_order:
        return _replayable(effort, _in_windows(problem, scene, start, router, started, effort))
    cost, unit_value, offset = cost_matrix(problem, legs, start)
    tours = _Tours(
        cost, len(places) - len(problem.chargers), problem.start_state is not None, effort
    )
    tour = tours.first(problem.keep_order)
    order = with_reloads(problem, tour.order, None if problem.keep_order else tours.stretch)
    round_s = float(legs.duration_s[order[:-1], order[1:]].sum()) + sum(
        stop.service_time_s for stop in problem.stops
    )
    if round_s > MAX_ROUND_S:
        raise LimitExceededError(
            f"the round would last {round_s / 3600:,.0f} h; the planner simulates at most "
            f"{MAX_ROUND_S / 3600:.0f} h",
            "stops",
        )

    remembering = None if router is None else RememberingRouter(router)

    def roads(driven: list[int]) -> list[LegRoute] | None:
        if remembering is None or legs.source != "osrm":
            return None
        return leg_roads(remembering, scene.places, driven)

    found = Solved(
        status=tour.status,
        objective_value=tour.cost * unit_value + offset * (len(order) - 1),
        runtime_s=tour.runtime_s,
    )
    windows = windows_after(problem.stops, problem.date, start) if windowed else None
    drive = Drive(problem, scene, start, roads, found, windows)
    result = with_charges(drive, Itinerary.of(order), None if problem.keep_order else tours)
    solved = _how_solved(tour, result, scene.places, tours.ends)
    warnings = [*result.warnings, *cut_short(solved.stopped_by)]
    return _replayable(effort, _in_time(problem, replace(result, solved=solved, warnings=warnings)))


def _replayable(effort: Effort, result: PlanResult) -> PlanResult:
    """``result`` with the work its searches did under ``effort``, to replay them."""
    return replace(result, solved=result.solved.model_copy(update={"replay": replay_of(effort)}))


def _in_time(problem: PlanProblem, result: PlanResult) -> PlanResult:
    """``result`` when it serves every stop in a window; else the client's own order misses
    one (the planner's never do): an error naming the first stop it misses."""
    if not result.late_stops:
        return result
    late = result.late_stops[0]
    index = next(k for k, stop in enumerate(problem.stops) if stop.id == late)
    arrival = next(s.arrival for s in result.stops if s.id == late)
    raise InvalidStopsError(
        f"in the given order the van reaches '{late}' at {arrival:%H:%M}, after its last "
        "time window closes; change the order or let the planner choose it (keep_order "
        "false)",
        f"stops[{index}].time_windows",
    )


def _how_solved(
    tour: Tour, result: PlanResult, places: list[Place], ends: list[SearchEnd]
) -> Solved:
    """The plan's status: ``optimal`` only when its whole answer carries the proof — the
    order of the stops proven and kept, and no charge or reload placed by the heuristics
    after it (then ``feasible``, with ``order`` in ``proven`` while the stops keep the proven
    order); how its searches stopped."""
    proven_ids = [places[k].id for k in tour.order[1:-1]]
    kept = tour.status == "optimal" and [s.id for s in result.stops] == [
        i for i in proven_ids if i != START_ID
    ]
    whole = kept and not (result.charges or result.reloads)
    status = tour.status if tour.status != "optimal" else ("optimal" if whole else "feasible")
    return result.solved.model_copy(
        update={
            "status": status,
            "stopped_by": combined(ends),
            "proven": ("order",) if kept else (),
        }
    )


@dataclass(frozen=True)
class _Tours:
    """The round's orders on the solver's ``cost`` (every place: the depot, the stops, the
    van's position when under way, then the chargers): the places up to ``visited`` are the
    round's, the chargers after them are visited as the battery needs. Every search shares
    ``effort``'s deadline and seed; ``ends`` collects how each stopped."""

    cost: NDArray[np.int64]
    visited: int
    under_way: bool
    effort: Effort
    ends: list[SearchEnd] = field(default_factory=list)

    def ended(self, tour: Tour) -> Tour:
        self.ends.append(tour.ended)
        return tour

    def first(self, keep_order: bool) -> Tour:
        """The round without charging: a round trip, or from the van's position to the depot."""
        cost = self.cost[: self.visited, : self.visited]
        if self.under_way:
            return self.ended(path_tour(cost, self.effort, keep_order))
        return self.ended(solve_tour(cost, self.effort, keep_order))

    def stretch(self, places: list[int]) -> list[int]:
        return self.ended(solve_path(self.cost, places, self._trip())).order

    def _trip(self, trips: int = 1) -> Effort:
        """A stretch's work: :data:`TRIP_WORK_S` each, under the round's deadline."""
        return replace(self.effort, work_s=TRIP_WORK_S * trips)

    def through(self, chargers: list[int]) -> list[int]:
        """The round again with a visit to each of ``chargers`` (a place listed twice, twice),
        never one right after another or at the depot."""
        nodes = [*range(self.visited), *chargers]
        cost = self.cost[np.ix_(nodes, nodes)].copy()
        never = int(cost.max()) * len(nodes) + 1
        cost[self.visited :, self.visited :] = never
        cost[self.visited :, 0] = never
        cost[0, self.visited :] = never
        if self.under_way:
            start = self.visited - 1
            ends = [start, *range(1, start), *range(self.visited, len(nodes)), 0]
            path = self.ended(solve_path(cost, ends, self._trip(len(chargers)))).order
        else:
            path = self.ended(solve_tour(cost, self._trip(len(chargers)))).order
        return [nodes[k] for k in path]


def _in_windows(
    problem: PlanProblem,
    scene: Scene,
    start: dt.datetime,
    router: RoadRouter | None,
    started: float,
    effort: Effort,
) -> PlanResult:
    """The round when stops have time windows: the fleet search with this one van, its
    battery reported, not a constraint, and every stop required; a stop no order serves in
    time is an error naming it. When the battery does not last and there are chargers, the
    van charges where the time it adds keeps every later window
    (:func:`core.planning.day.recharge.with_charges`)."""
    remembering = None if router is None else RememberingRouter(router)
    van = VanShift("van", problem, start, None, battery_enforced=False)
    under_way = [len(problem.stops) + 1] if problem.start_state is not None else None
    day = fleet_day([van], scene, remembering, under_way)
    routed = search(day, False, effort)
    if routed.unassigned:
        first = routed.unassigned[0]
        index = next(k for k, stop in enumerate(problem.stops) if stop.id == first.id)
        field = f"stops[{index}].time_windows" if first.reason == "time_window" else ""
        raise InvalidStopsError(
            f"no order of the round serves '{first.id}' in time: {first.detail}",
            field or f"stops[{index}]",
        )
    result = routed.routes[0].plan
    if not result.battery.feasible and charge_points(problem, scene.places):
        # its charges placed afresh
        charged = day.charged(0, Itinerary.of(result.itinerary.order), {})
        if charged.battery.margin_kwh > result.battery.margin_kwh:
            result = replace(charged, solved=result.solved)
    solved = result.solved.model_copy(
        update={"runtime_s": time.perf_counter() - started, "stopped_by": routed.ended}
    )
    return replace(result, solved=solved, warnings=[*result.warnings, *cut_short(routed.ended)])


def _check_reachable(problem: PlanProblem, places: list[Place], legs: Legs) -> None:
    """Every stop (the van's position, each charger) can be driven to from the depot and
    back (a router may find no road)."""
    for index in legs.unreachable():
        raise NoRouteError(
            f"no road links '{places[index].id}' with the depot '{problem.depot.id}'",
            round_field(problem, places, index),
        )


def check(problem: PlanProblem) -> tuple[dt.datetime, str]:
    """Everything about a round that can be checked without solving it — what a job refuses
    at submission as the synchronous endpoint does: unique stop ids, the payload, the time
    zone and start time, the client's matrix, the start state, a replay of another request. Raises
    :class:`core.exceptions.CoreError` naming the field; returns the departure (from the van's
    position when it is under way) and the zone's name."""
    check_places(problem)
    check_payload(problem)
    problem.check_replay(problem.time_limit_s)
    start, timezone_name = round_start(problem)
    return check_start(problem, start.tzinfo) or start, timezone_name


def round_start(problem: PlanProblem) -> tuple[dt.datetime, str]:
    """The round's departure and the zone's name, for a day and a start time the clock has
    and a round of the longest duration the planner simulates can follow; raises
    :class:`core.exceptions.InvalidParameterError` naming ``date`` or ``start_time``."""
    start, timezone_name = departure(
        problem.date, problem.start_time, problem.timezone, problem.depot.lon
    )
    check_representable(start, MAX_ROUND_S, "date")
    return start, timezone_name
