"""A delivery round from depot, stops and date to a simulated round trip (paper §4, Fig. 7).

1. legs between every ordered pair (:mod:`core.geo`: the client's matrix, a road router's table
or the estimate); 2. the order of the stops on the chosen objective: the round trip
(:mod:`core.tsp`), or, when stops have time windows, the routing solver of :mod:`core.fleet`
with one van; 3. the day driven and simulated in full (:mod:`core.round`), with the weather for
the round's span (a forecast service, the request, or the climatology).
"""

from __future__ import annotations

import datetime as dt

from core.clock import check_representable, departure
from core.exceptions import InvalidStopsError, LimitExceededError, NoRouteError
from core.fleet import FleetSolver, VanShift
from core.geo import Legs, build_legs
from core.params import Depot
from core.roads import RememberingRouter, RoadRouter
from core.round import (
    MAX_ROUND_S,
    PlanProblem,
    PlanResult,
    Solved,
    WeatherFor,
    check_stop_ids,
    cost_matrix,
    leg_routes,
    simulate_round,
    windows_after,
)
from core.tsp import solve_tour
from core.weather import Forecast, WeatherService, forecast_for


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
    start, timezone_name = check(problem)
    places: list[Depot] = [problem.depot, *problem.stops]
    table = router.table(places) if router is not None and problem.matrix is None else None
    legs = build_legs(places, problem.matrix, table)
    _check_reachable(places, legs)

    def weather_for(begin: dt.datetime, span_s: float) -> tuple[Forecast | None, list[str]]:
        return forecast_for(
            problem.weather, weather_service, problem.depot.lat, problem.depot.lon, begin, span_s
        )

    windowed = any(stop.time_windows for stop in problem.stops)
    if windowed and not problem.keep_order:
        return _in_windows(problem, places, legs, start, timezone_name, router, weather_for)
    cost, unit_value, offset = cost_matrix(problem, legs, start)
    tour = solve_tour(cost, problem.time_limit_s, problem.keep_order)
    order = tour.order
    round_s = float(legs.duration_s[order[:-1], order[1:]].sum()) + sum(
        stop.service_time_s for stop in problem.stops
    )
    if round_s > MAX_ROUND_S:
        raise LimitExceededError(
            f"the round would last {round_s / 3600:,.0f} h; the planner simulates at most "
            f"{MAX_ROUND_S / 3600:.0f} h",
            "stops",
        )
    routes = (
        leg_routes(router, places, order) if router is not None and legs.source == "osrm" else None
    )
    result = simulate_round(
        problem,
        places,
        legs,
        order,
        start,
        timezone_name,
        routes,
        weather_for,
        Solved(tour.status, tour.cost * unit_value + offset * (len(order) - 1), tour.runtime_s),
        windows_after(problem.stops, problem.date, start) if windowed else None,
    )
    if result.late_stops:  # the client's own order misses a window
        index = next(k for k, stop in enumerate(problem.stops) if stop.id == result.late_stops[0])
        arrival = next(s.arrival for s in result.stops if s.id == result.late_stops[0])
        raise InvalidStopsError(
            f"in the given order the van reaches '{result.late_stops[0]}' at "
            f"{arrival:%H:%M}, after its last time window closes; change the order or let the "
            "planner choose it (keep_order false)",
            f"stops[{index}].time_windows",
        )
    return result


def _in_windows(
    problem: PlanProblem,
    places: list[Depot],
    legs: Legs,
    start: dt.datetime,
    timezone_name: str,
    router: RoadRouter | None,
    weather_for: WeatherFor,
) -> PlanResult:
    """The round when stops have time windows: the routing solver with this one van, every
    stop required; a stop no order serves in time is an error naming it."""
    routed = FleetSolver(
        [VanShift(id="van", problem=problem, start=start, end=None)],
        places,
        legs,
        timezone_name,
        None if router is None else RememberingRouter(router),
        weather_for,
        energy_budget=False,
    ).run(minimize_vehicles=False)
    if routed.unassigned:
        first = routed.unassigned[0]
        index = next(k for k, stop in enumerate(problem.stops) if stop.id == first.id)
        field = "time_windows" if first.reason == "time_window" else ""
        raise InvalidStopsError(
            f"no order of the round serves '{first.id}' in time: {first.detail}",
            f"stops[{index}].{field}" if field else f"stops[{index}]",
        )
    return routed.routes[0].plan


def _check_reachable(places: list[Depot], legs: Legs) -> None:
    """Every stop can be driven to from the depot and back (a router may find no road)."""
    for index in legs.unreachable():
        raise NoRouteError(
            f"no road links '{places[index].id}' with the depot '{places[0].id}'",
            f"stops[{index - 1}]",
        )


def check(problem: PlanProblem) -> tuple[dt.datetime, str]:
    """Everything about a round that can be checked without solving it: unique stop ids, the
    payload, the time zone and start time, the client's matrix. Raises
    :class:`core.exceptions.CoreError` naming the field; returns the departure and the zone's
    name."""
    _check_stops(problem)
    start, timezone_name = departure(
        problem.date, problem.start_time, problem.timezone, problem.depot.lon
    )
    check_representable(start, MAX_ROUND_S, "date")  # the longest round the planner simulates
    if problem.matrix is not None:
        build_legs([problem.depot, *problem.stops], problem.matrix)
    return start, timezone_name


def _check_stops(problem: PlanProblem) -> None:
    check_stop_ids(problem.depot, problem.stops)
    delivered = sum(stop.delivery_kg for stop in problem.stops)
    if delivered > problem.van.payload_kg + 1e-9:
        raise InvalidStopsError(
            f"the stops' delivery_kg add up to {delivered:g} kg, more than the payload "
            f"{problem.van.payload_kg:g} kg",
            "stops",
        )
