"""Fleet planning: the day's stops split across several vans from one depot, with delivery time
windows, shifts, payload and the battery as constraints — and every returned route verified by
the full simulation of its day.

1. The solver (:mod:`core.routing.vrp`) plans with estimates (:mod:`core.planning.day.estimates`):
   each arc's driving time, and its energy as traction by the arc's distance and grade for the
   van's mass plus the standing loads (auxiliaries, cab, box) times its duration, with each
   stop's service and door openings; the usable battery energy between departure charge and
   reserve is the van's budget.
2. Each route is driven and simulated in full (:mod:`core.planning.day.verify`: traction,
   auxiliaries, cab, refrigeration with the door openings, at the time of day each leg is
   really driven). A route that breaks a rule — its charge below the reserve, a window missed,
   back after its shift — tightens the estimate that misled the solver (that van's energy
   budget by the simulated shortfall; the driving times of the arcs driven, exactly, and of the
   others by the ratio seen) and the fleet is solved again from the routes that held, within
   the time budget.
3. Whatever still fails when the budget is spent loses stops, one at a time, until its
   simulation holds (:mod:`core.planning.search.repair`). A stop no van can serve is listed
   with its reason (:mod:`core.planning.search.explain`) — never a route reported feasible that
   the simulation says is not.
4. With chargers (the depot's, or on the way) and stops left out for their battery, the
   E-VRPTW search plans the fleet again from these routes with charges between stops, each
   route verified by its simulation with its charges
   (:mod:`core.planning.search.charging.fleet_charging`); the fleet keeps whichever serves more
   stops (then fewer vans when asked, then the lower objective).

Steps 1–4 are the search (:mod:`core.planning.search.fleet`); this module checks the request
and builds the answer around it. Every step is bounded by work, not by the clock
(:mod:`core.routing.effort`): the solves by their share of the request's work, the
verification by :data:`~core.planning.search.fleet.MAX_RESOLVES` re-solves, the charging by
the places it tries. The request's time limit only caps them, and the answer says when it
did (``stopped_by``).
"""

from __future__ import annotations

import time

from core.clock import check_representable, departure
from core.exceptions import CoreError, InvalidParameterError, NoRouteError
from core.params import Place
from core.physics.simulate import CONSUMERS
from core.physics.weather import WeatherService, forecast_for
from core.planning.day.scene import Scene, legs_for, round_field
from core.planning.day.start_state import check_start, check_start_id, under_way
from core.planning.day.timeline import client_legs_too_fast
from core.planning.model import (
    START_ID,
    FleetProblem,
    FleetResult,
    PlanProblem,
    RoundFields,
    TripFields,
    Unassigned,
    check_places,
    cut_short,
    fields_of,
    replay_of,
)
from core.planning.search.day import VanShift, fleet_day
from core.planning.search.fleet import search
from core.routing.roads import RememberingRouter, RoadRouter


def plan_fleet(
    problem: FleetProblem,
    router: RoadRouter | None = None,
    weather_service: WeatherService | None = None,
) -> FleetResult:
    """Split the stops across the fleet, order each van's stops and verify every route by the
    full simulation of its day.

    Parameters
    ----------
    problem
        The fleet and the day's stops.
    router
        A road router for the matrix and the roads, as in :func:`core.planning.round.planner.plan`.
    weather_service
        An hourly forecast for the day, as in :func:`core.planning.round.planner.plan`.
    """
    started = time.perf_counter()
    effort = problem.effort(problem.time_limit_s, problem.replay_limit_s)
    shifts, timezone_name = check_fleet(problem)
    scene, starts, weather_warnings = _fleet_scene(
        problem, shifts, timezone_name, router, weather_service
    )
    legs = scene.legs
    remembering = None if router is None else RememberingRouter(router)
    charging = problem.depot.charger is not None or bool(problem.chargers)
    routed = search(
        fleet_day(shifts, scene, remembering, starts),
        problem.minimize_vehicles,
        effort,
        charging,
    )
    routes = routed.stamped(time.perf_counter() - started)
    plans = [route.plan for route in routes]
    return FleetResult(
        routes=routes,
        unassigned=routed.unassigned,
        distance_m=sum(p.distance_m for p in plans),
        duration_s=sum(p.duration_s for p in plans),
        energy_kwh={name: sum(p.energy_kwh[name] for p in plans) for name in (*CONSUMERS, "total")},
        grid_kwh=sum(p.grid_kwh for p in plans),
        vehicles_used=len(plans),
        objective=problem.objective,
        objective_value=routed.objective_value,
        runtime_s=time.perf_counter() - started,
        stopped_by=routed.ended,
        replay=replay_of(effort),
        verification_rounds=routed.verification_rounds,
        timezone=timezone_name,
        distance_source=legs.source,
        warnings=[
            *weather_warnings,
            *routed.warnings,
            *_payload_short(problem, routed.unassigned),
            *cut_short(routed.ended),
        ],
    )


def _fleet_scene(
    problem: FleetProblem,
    shifts: list[VanShift],
    timezone_name: str,
    router: RoadRouter | None,
    weather_service: WeatherService | None,
) -> tuple[Scene, list[int], list[str]]:
    """The day's places (the depot, the stops, the positions of the vans under way, the
    chargers), their legs and one forecast for the whole day shared by every van; the place
    each van sets off from; what the weather's source says of itself."""
    under_way = [k for k, v in enumerate(problem.vehicles) if v.start_state is not None]
    positions = [
        Place(id=START_ID, lat=state.lat, lon=state.lon)
        for k in under_way
        if (state := problem.vehicles[k].start_state) is not None
    ]
    places = [*problem.places, *positions, *problem.chargers]
    start_fields = [f"vehicles[{k}].start_state" for k in under_way]
    legs = legs_for(problem, router, places, start_fields)
    for index in legs.unreachable():
        if index > len(problem.stops) and index < len(places) - len(problem.chargers):
            raise NoRouteError(
                "no road links the van's position with the depot",
                round_field(problem, places, index, start_fields),
            )
    starts = [0] * len(shifts)
    for n, k in enumerate(under_way):
        starts[k] = len(problem.stops) + 1 + n
    first = min(shift.start for shift in shifts)
    last = max(shift.end for shift in shifts if shift.end is not None)
    day_weather = forecast_for(
        problem.weather,
        weather_service,
        problem.depot.lat,
        problem.depot.lon,
        first,
        last.timestamp() - first.timestamp() + 2 * 3600.0,
    )
    fastest = max(v.van.vehicle.max_acceleration_mps2 for v in problem.vehicles)
    too_fast = client_legs_too_fast(legs, fastest)
    scene = Scene(
        places,
        legs,
        timezone_name,
        lambda _begin, _span_s: day_weather,
        (too_fast,) if too_fast else (),
    )
    return scene, starts, list(day_weather[1])


def _payload_short(problem: FleetProblem, unassigned: list[Unassigned]) -> list[str]:
    """A warning when stops are left out because the fleet is full: what the vans carry and
    what the stops take [kg]."""
    full = [u.id for u in unassigned if u.reason == "capacity"]
    if not full:
        return []
    carried = sum(v.van.payload_kg * v.max_trips for v in problem.vehicles)
    taken = sum(stop.delivery_kg for stop in problem.stops)
    return [
        f"{len(full)} stop{'s' * (len(full) > 1)} left out for payload: the vans carry "
        f"{carried:,.0f} kg in all (payload_kg × max_trips) and the stops take {taken:,.0f} kg; "
        "check each van's payload_kg"
    ]


def check_fleet(problem: FleetProblem) -> tuple[list[VanShift], str]:
    """Everything about a fleet plan that can be checked without solving it: unique ids of
    stops and vans, the pinned stops' ids, each shift's start and end on the day in the zone,
    each start state (its time within the shift), the client's matrix. Raises
    :class:`core.exceptions.CoreError` naming the field; returns each van's shift (from its
    start state's time when under way) and the zone's name. A replay of another request too."""
    check_places(problem)
    problem.check_replay(problem.time_limit_s)
    moving = next((k for k, v in enumerate(problem.vehicles) if v.start_state is not None), None)
    if moving is not None:
        check_start_id(problem, f"vehicles[{moving}].start_state")
    vans: dict[str, int] = {}
    for index, vehicle in enumerate(problem.vehicles):
        if vehicle.id in vans:
            raise InvalidParameterError(
                f"vehicle id '{vehicle.id}' is used twice (also by vehicles[{vans[vehicle.id]}])"
                "; ids must be unique",
                f"vehicles[{index}].id",
            )
        vans[vehicle.id] = index
    pins = _pins(problem)
    timezone_name = ""
    shifts = []
    for index, vehicle in enumerate(problem.vehicles):
        ends = []
        for name in ("shift_start", "shift_end"):
            try:
                moment, timezone_name = departure(
                    problem.date, getattr(vehicle, name), problem.timezone, problem.depot.lon
                )
            except CoreError as error:
                if error.field != "start_time":  # the zone: the request's, not the van's
                    raise
                raise error.at(f"vehicles[{index}].{name}") from None
            ends.append(moment)
        check_representable(ends[1], 86_400.0, "date")
        round_problem = PlanProblem(
            **fields_of(problem, RoundFields),
            start_time=vehicle.shift_start,
            time_limit_s=problem.time_limit_s,
            breaks=vehicle.breaks,
            **fields_of(vehicle, TripFields),
            start_state=vehicle.start_state,
            van=vehicle.van,
        )
        field = f"vehicles[{index}].start_state"
        now = check_start(round_problem, ends[0].tzinfo, field, fleet=True)
        if now is not None and not ends[0] <= now < ends[1]:
            raise InvalidParameterError(
                f"{now:%H:%M} is outside the van's shift {vehicle.shift_start:%H:%M}–"
                f"{vehicle.shift_end:%H:%M}",
                f"{field}.time",
            )
        shifts.append(
            VanShift(vehicle.id, under_way(round_problem), now or ends[0], ends[1], pins[index])
        )
    return shifts, timezone_name


def _pins(problem: FleetProblem) -> list[frozenset[int]]:
    """The places of the stops pinned to each van; an unknown id, or a stop pinned twice,
    is an error naming the second."""
    node_of = {stop.id: node for node, stop in enumerate(problem.stops, start=1)}
    pinned: dict[str, str] = {}
    pins = []
    for index, vehicle in enumerate(problem.vehicles):
        for k, stop_id in enumerate(vehicle.pinned_stops):
            field = f"vehicles[{index}].pinned_stops[{k}]"
            if stop_id not in node_of:
                raise InvalidParameterError(f"no stop has the id '{stop_id}'", field)
            if stop_id in pinned:
                raise InvalidParameterError(
                    f"stop '{stop_id}' is pinned twice (also to {pinned[stop_id]}); a stop is "
                    "pinned to one van at most",
                    field,
                )
            pinned[stop_id] = f"vehicle '{vehicle.id}'"
        pins.append(frozenset(node_of[stop_id] for stop_id in vehicle.pinned_stops))
    return pins
