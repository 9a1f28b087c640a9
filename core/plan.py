"""A delivery round from depot, stops and date to a simulated round trip (paper §4, Fig. 7).

1. legs between every ordered pair (:mod:`core.geo`: the client's matrix, a road router's table
or the estimate); 2. the tour (:mod:`core.tsp`) on the chosen objective; 3. the day's timeline —
depart, drive each leg (the router's road speed profile, or a generated trace), arrive, park,
open the door within the service time, unload (the payload and so the mass drop), go on,
return; 4. the weather for the round's span (a forecast service, the request, or the
climatology); 5. one vectorised simulation of the whole day (:func:`core.simulate.simulate`),
split per leg and per stop.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from core.arrays import FloatArray
from core.battery import JOULES_PER_KWH, BatteryVerdict
from core.clock import at, check_representable, departure
from core.cycles import drive_profile, generate_leg, stretch_to_duration, trace_distance_m
from core.exceptions import (
    InvalidStopsError,
    LimitExceededError,
    NoRouteError,
)
from core.geo import (
    MAX_LEG_GRADE,
    STREET_TYPE_NAMES,
    DistanceSource,
    Legs,
    build_legs,
    street_type_by_speed,
)
from core.params import (
    NORMAL_DRIVER,
    STREET_TYPES,
    Depot,
    DoorOpening,
    Interval,
    Location,
    Objective,
    Params,
    RoadMatrix,
    Stop,
    StreetTypeName,
    VanParams,
    Weather,
)
from core.roads import LegRoute, RoadRouter, bearing_deg
from core.simulate import CONSUMERS, SimulationResult, simulate
from core.tsp import SolverStatus, solve_tour
from core.vehicle import step_traction_power_w
from core.weather import DayWeather, WeatherService, WeatherSource, forecast_for

#: Sampling interval of the day's simulation [s].
PLAN_DT_S = 1.0
#: Longest round the planner simulates [s] (a week): longer inputs are mistakes.
MAX_ROUND_S = 7 * 86_400.0
#: Length of the flat reference leg that calibrates the energy objective per street type [m].
_REFERENCE_LEG_M = 10_000.0


class PlanProblem(Params):
    """Everything a round needs."""

    date: dt.date = Field(..., description="Day of the round.")
    start_time: dt.time = Field(dt.time(8, 0), description="Departure from the depot, local.")
    timezone: str | None = Field(
        None, description="IANA time zone; null uses local mean solar time at the depot."
    )
    depot: Depot
    stops: list[Stop] = Field(..., min_length=1)
    van: VanParams = Field(default_factory=VanParams)
    weather: Weather | None = None
    driver_aggressiveness: float = Field(NORMAL_DRIVER, ge=0, le=1)
    traffic_density: float | None = Field(None, gt=0, lt=1)
    objective: Objective = "distance"
    matrix: RoadMatrix | None = None
    keep_order: bool = False
    time_limit_s: float = Field(1.0, gt=0, le=600)


@dataclass(frozen=True)
class LegResult:
    """One driven leg of the round.

    ``geometry`` is the road as ``(lon, lat)`` points: the router's polyline, or the straight
    line between the two places when the distances are an estimate or the client's.
    """

    from_id: str
    to_id: str
    depart: dt.datetime
    arrive: dt.datetime
    distance_m: float
    duration_s: float
    street_type: StreetTypeName
    grade: float
    energy_kwh: dict[str, float]
    soc_start: float
    soc_end: float
    geometry: list[tuple[float, float]]


@dataclass(frozen=True)
class StopResult:
    """One stop of the round, in visiting order."""

    id: str
    arrival: dt.datetime
    departure: dt.datetime
    door_heat_kwh: float
    payload_after_kg: float
    energy_kwh: dict[str, float]
    soc_arrival: float
    soc_departure: float
    snap_distance_m: float | None
    lat: float
    lon: float


#: Spacing of the day profile's points [s].
PROFILE_STEP_S = 60.0


@dataclass(frozen=True)
class DayProfile:
    """Cumulative energy per consumer over the clock time of the round (paper Fig. 8).

    Attributes
    ----------
    time
        Moments every minute from departure to return, local time.
    energy_kwh
        Energy used since departure at each moment, per consumer and ``total`` [kWh].
    """

    time: list[dt.datetime]
    energy_kwh: dict[str, list[float]]


@dataclass(frozen=True)
class PlanResult:
    """The solved and simulated round."""

    tour: list[str]
    legs: list[LegResult]
    stops: list[StopResult]
    distance_m: float
    duration_s: float
    energy_kwh: dict[str, float]
    energy_share: dict[str, float]
    battery: BatteryVerdict
    battery_loss_kwh: float
    grid_kwh: float
    first_infeasible_leg: int | None
    max_box_temperature_c: float | None
    minutes_above_product_limit: float | None
    weather: Weather
    weather_days: list[DayWeather]
    weather_source: WeatherSource
    warnings: list[str]
    timezone: str
    distance_source: DistanceSource
    depot_snap_distance_m: float | None
    solver_status: SolverStatus
    objective: Objective
    objective_value: float
    solver_runtime_s: float
    profile: DayProfile


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
    cost, unit_value, offset = _cost_matrix(problem, legs, start)
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
    objective_value = tour.cost * unit_value + offset * (len(order) - 1)
    routes = (
        _routes(router, places, order) if router is not None and legs.source == "osrm" else None
    )
    timeline = _timeline(problem, places, legs, order, routes)
    check_representable(start, timeline.speed.size * PLAN_DT_S, "date")
    weather, warnings = forecast_for(
        problem.weather,
        weather_service,
        problem.depot.lat,
        problem.depot.lon,
        start,
        timeline.speed.size * PLAN_DT_S,
    )
    result = simulate(
        timeline.speed,
        PLAN_DT_S,
        start,
        Location(lat=problem.depot.lat, lon=problem.depot.lon),
        problem.van,
        grade=timeline.grade,
        payload_kg=timeline.payload,
        weather=weather,
        door_openings=timeline.doors,
        parked=timeline.parked,
        heading_deg=timeline.heading,
    )
    return _assemble(
        problem,
        places,
        legs,
        order,
        result,
        timeline,
        start,
        timezone_name,
        tour.status,
        objective_value,
        tour.runtime_s,
        warnings,
    )


def _routes(router: RoadRouter, places: list[Depot], order: list[int]) -> list[LegRoute]:
    """The router's road of every leg of the tour; a leg with no road names its destination."""
    routes = []
    for i, j in itertools.pairwise(order):
        try:
            routes.append(router.route(places[i], places[j]))
        except NoRouteError as error:
            raise NoRouteError(error.message, _place_field(j)) from None
    return routes


def _place_field(index: int) -> str:
    """The request field of place ``index`` (0 the depot)."""
    return "depot" if index == 0 else f"stops[{index - 1}]"


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
    seen: dict[str, int] = {problem.depot.id: -1}
    for index, stop in enumerate(problem.stops):
        if stop.id in seen:
            other = "the depot" if seen[stop.id] < 0 else f"stops[{seen[stop.id]}]"
            raise InvalidStopsError(
                f"stop id '{stop.id}' is used twice (also by {other}); ids must be unique",
                f"stops[{index}].id",
            )
        seen[stop.id] = index
    delivered = sum(stop.delivery_kg for stop in problem.stops)
    if delivered > problem.van.payload_kg + 1e-9:
        raise InvalidStopsError(
            f"the stops' delivery_kg add up to {delivered:g} kg, more than the payload "
            f"{problem.van.payload_kg:g} kg",
            "stops",
        )


def _constant_power_w(problem: PlanProblem, start: dt.datetime) -> float:
    """Auxiliaries + cab + box power at departure, standing [W]: the energy objective's time
    cost."""
    standing = simulate(
        np.zeros(2),
        PLAN_DT_S,
        start,
        Location(lat=problem.depot.lat, lon=problem.depot.lon),
        problem.van.model_copy(update={"precondition_at_depot": True}),
        weather=problem.weather,
    )
    return float(sum(standing.power_w[name][0] for name in CONSUMERS if name != "traction"))


def _energy_matrix_j(problem: PlanProblem, legs: Legs, start: dt.datetime) -> FloatArray:
    """Estimated electric energy of every leg [J]: the energy objective's arc costs.

    Traction per metre is simulated once per street type on a 10 km reference trace (same
    driver, traffic and departure mass) at every grade of a table from −25 % to +25 % in one
    broadcast call, and read for each leg by interpolation in its grade: climbs cost over the
    drive-train efficiency, descents first replace motoring and only then regenerate, and the
    matrix is asymmetric. Auxiliaries, cab and box add their power at departure (the request's
    weather or the climatology) times the leg's duration. The chosen tour is then simulated in
    full.
    """
    vehicle = problem.van.vehicle
    mass = vehicle.mass_kg + problem.van.payload_kg
    grades = np.linspace(-MAX_LEG_GRADE, MAX_LEG_GRADE, 51)
    traction = np.zeros_like(legs.distance_m)
    for index, name in enumerate(STREET_TYPE_NAMES):
        trace = generate_leg(
            _REFERENCE_LEG_M,
            STREET_TYPES[name],
            problem.driver_aggressiveness,
            vehicle.max_acceleration_mps2,
            problem.traffic_density,
            PLAN_DT_S,
        )
        power = step_traction_power_w(vehicle, trace, PLAN_DT_S, mass, grades[:, None])
        per_metre = power.sum(axis=1) * PLAN_DT_S / _REFERENCE_LEG_M
        on_type = legs.street_type == index
        traction[on_type] = np.interp(legs.grade[on_type], grades, per_metre)
    traction *= legs.distance_m
    return traction + _constant_power_w(problem, start) * legs.duration_s


def _cost_matrix(
    problem: PlanProblem, legs: Legs, start: dt.datetime
) -> tuple[NDArray[np.int64], float, float]:
    """Integer arc costs for the solver, the value of one cost unit and a per-arc offset, both in
    the objective's unit (m, s or Wh).

    Distance in metres and duration in seconds, rounded to the nearest integer; energy in
    tenths of a watt-hour, shifted so the cheapest arc costs 0 (every tour has the same number
    of arcs, so the shift does not change the best tour; the offset adds it back).
    """
    if problem.objective == "distance":
        return np.rint(legs.distance_m).astype(np.int64), 1.0, 0.0
    if problem.objective == "duration":
        return np.rint(legs.duration_s).astype(np.int64), 1.0, 0.0
    tenth_wh = _energy_matrix_j(problem, legs, start) / 360.0
    off_diagonal = ~np.eye(tenth_wh.shape[0], dtype=bool)
    lowest = float(tenth_wh[off_diagonal].min()) if off_diagonal.any() else 0.0
    shifted = np.where(off_diagonal, tenth_wh - lowest, 0.0)
    return np.rint(shifted).astype(np.int64), 0.1, lowest * 0.1


@dataclass(frozen=True)
class _Timeline:
    """The day sample by sample, and the marks that split it: leg k drives from depart[k] to
    arrive[k]; the stop after it (if any) lasts until leave[k]."""

    speed: FloatArray
    grade: FloatArray
    payload: FloatArray
    heading: FloatArray
    doors: list[DoorOpening]
    parked: list[Interval]
    depart: NDArray[np.int_]
    arrive: NDArray[np.int_]
    leave: NDArray[np.int_]
    street_types: list[StreetTypeName]
    geometry: list[list[tuple[float, float]]]


def _drive(
    problem: PlanProblem,
    legs: Legs,
    i: int,
    j: int,
    route: LegRoute | None,
    straight_heading_deg: float,
) -> tuple[FloatArray, FloatArray, StreetTypeName]:
    """Speed trace, heading of each sample and street type of the leg from i to j."""
    vehicle = problem.van.vehicle
    if route is None:
        street_type = legs.street_type_name(i, j)
        trace = generate_leg(
            float(legs.distance_m[i, j]),
            STREET_TYPES[street_type],
            problem.driver_aggressiveness,
            vehicle.max_acceleration_mps2,
            problem.traffic_density,
            PLAN_DT_S,
        )
        if legs.source == "client":
            trace = stretch_to_duration(trace, PLAN_DT_S, float(legs.duration_s[i, j]))
        return trace, np.full(trace.size, straight_heading_deg), street_type
    free_flow_s = float(np.sum(route.segment_distance_m / route.segment_speed_mps))
    street_type = STREET_TYPE_NAMES[int(street_type_by_speed(route.distance_m, free_flow_s))]
    trace, travelled = drive_profile(
        route.segment_distance_m,
        route.segment_speed_mps,
        STREET_TYPES[street_type],
        problem.driver_aggressiveness,
        vehicle.max_acceleration_mps2,
        problem.traffic_density,
        PLAN_DT_S,
    )
    ends = np.cumsum(route.segment_distance_m)
    segment = np.minimum(np.searchsorted(ends, travelled), ends.size - 1)
    return trace, route.segment_heading_deg[segment], street_type


def _timeline(
    problem: PlanProblem,
    places: list[Depot],
    legs: Legs,
    order: list[int],
    routes: list[LegRoute] | None,
) -> _Timeline:
    """Speed, grade, payload and heading of every sample of the day, the door openings, the
    stops and the marks."""
    speed_parts: list[FloatArray] = [np.zeros(1)]
    grade_parts: list[FloatArray] = [np.zeros(1)]
    heading_parts: list[FloatArray] = [np.full(1, np.nan)]
    payload_parts: list[FloatArray] = [np.array([problem.van.payload_kg])]
    doors: list[DoorOpening] = []
    parked: list[Interval] = []
    depart, arrive, leave = [], [], []
    street_types: list[StreetTypeName] = []
    geometry: list[list[tuple[float, float]]] = []
    clock = 0
    payload = problem.van.payload_kg
    for k, (i, j) in enumerate(itertools.pairwise(order)):
        a, b = places[i], places[j]
        route = routes[k] if routes is not None else None
        trace, heading, street_type = _drive(
            problem, legs, i, j, route, bearing_deg(a.lat, a.lon, b.lat, b.lon)
        )
        street_types.append(street_type)
        geometry.append(
            [(float(x), float(y)) for x, y in route.coordinates]
            if route is not None
            else [(a.lon, a.lat), (b.lon, b.lat)]
        )
        drive = trace[1:]
        depart.append(clock)
        clock += drive.size
        arrive.append(clock)
        speed_parts.append(drive)
        heading_parts.append(heading[1:])
        grade_parts.append(np.full(drive.size, legs.grade[i, j]))
        payload_parts.append(np.full(drive.size, payload))
        if j != 0:
            stop = problem.stops[j - 1]
            dwell = math.ceil(stop.service_time_s / PLAN_DT_S)
            parked.append(Interval(start_s=clock * PLAN_DT_S, duration_s=dwell * PLAN_DT_S))
            if stop.door_open_s > 0:
                doors.append(DoorOpening(start_s=clock * PLAN_DT_S, duration_s=stop.door_open_s))
            payload = max(payload - stop.delivery_kg, 0.0)
            speed_parts.append(np.zeros(dwell))
            grade_parts.append(np.zeros(dwell))
            heading_parts.append(np.full(dwell, np.nan))
            # Unloading happens during the stop: the lighter van drives away.
            payload_parts.append(np.full(dwell, payload))
            clock += dwell
        leave.append(clock)
    return _Timeline(
        speed=np.concatenate(speed_parts),
        grade=np.concatenate(grade_parts),
        payload=np.concatenate(payload_parts),
        heading=np.concatenate(heading_parts),
        doors=doors,
        parked=parked,
        depart=np.array(depart),
        arrive=np.array(arrive),
        leave=np.array(leave),
        street_types=street_types,
        geometry=geometry,
    )


def _span_kwh(cumulative_j: dict[str, FloatArray], a: int, b: int) -> dict[str, float]:
    """Energy per consumer and total between samples a and b [kWh]."""
    energy = {name: float(c[b] - c[a]) / JOULES_PER_KWH for name, c in cumulative_j.items()}
    energy["total"] = sum(energy.values())
    return energy


def _assemble(
    problem: PlanProblem,
    places: list[Depot],
    legs: Legs,
    order: list[int],
    result: SimulationResult,
    timeline: _Timeline,
    start: dt.datetime,
    timezone_name: str,
    status: SolverStatus,
    objective_value: float,
    runtime_s: float,
    warnings: list[str],
) -> PlanResult:
    cumulative = {
        name: np.concatenate(([0.0], np.cumsum(power) * PLAN_DT_S))
        for name, power in result.power_w.items()
    }
    door_cumulative = np.concatenate(([0.0], np.cumsum(result.box.door_heat_w) * PLAN_DT_S))
    soc = result.soc
    snap = legs.snap_distance_m

    def moment(sample: int) -> dt.datetime:
        return at(start, float(sample) * PLAN_DT_S)

    leg_results, stop_results = [], []
    payload = problem.van.payload_kg
    for k, (i, j) in enumerate(itertools.pairwise(order)):
        a, b, c = int(timeline.depart[k]), int(timeline.arrive[k]), int(timeline.leave[k])
        leg_results.append(
            LegResult(
                from_id=places[i].id,
                to_id=places[j].id,
                depart=moment(a),
                arrive=moment(b),
                distance_m=trace_distance_m(result.speed_mps[a : b + 1], PLAN_DT_S),
                duration_s=(b - a) * PLAN_DT_S,
                street_type=timeline.street_types[k],
                grade=float(legs.grade[i, j]),
                energy_kwh=_span_kwh(cumulative, a, b),
                soc_start=float(soc[a]),
                soc_end=float(soc[b]),
                geometry=timeline.geometry[k],
            )
        )
        if j != 0:
            payload = max(payload - problem.stops[j - 1].delivery_kg, 0.0)
            stop_results.append(
                StopResult(
                    id=places[j].id,
                    arrival=moment(b),
                    departure=moment(c),
                    door_heat_kwh=float(door_cumulative[c] - door_cumulative[b]) / JOULES_PER_KWH,
                    payload_after_kg=payload,
                    energy_kwh=_span_kwh(cumulative, b, c),
                    soc_arrival=float(soc[b]),
                    soc_departure=float(soc[c]),
                    snap_distance_m=None if snap is None else float(snap[j]),
                    lat=places[j].lat,
                    lon=places[j].lon,
                )
            )
    total = result.energy_kwh["total"]
    first_bad = result.battery.first_infeasible_index
    every = max(round(PROFILE_STEP_S / PLAN_DT_S), 1)
    picks = np.unique(np.append(np.arange(0, result.time_s.size, every), result.time_s.size - 1))
    profile_kwh = {name: (c[picks] / JOULES_PER_KWH).tolist() for name, c in cumulative.items()}
    profile_kwh["total"] = np.sum([profile_kwh[name] for name in CONSUMERS], axis=0).tolist()
    dynamic = problem.van.cargo_box.mode == "dynamic"
    return PlanResult(
        tour=[places[i].id for i in order],
        legs=leg_results,
        stops=stop_results,
        distance_m=result.distance_m,
        duration_s=result.duration_s,
        energy_kwh=dict(result.energy_kwh),
        energy_share={
            name: (result.energy_kwh[name] / total if total > 0 else 0.0) for name in CONSUMERS
        },
        battery=result.battery,
        battery_loss_kwh=result.battery_loss_kwh,
        grid_kwh=result.grid_kwh,
        first_infeasible_leg=(
            None
            if first_bad is None
            else int(np.searchsorted(timeline.leave, first_bad, side="left"))
        ),
        max_box_temperature_c=result.box.max_temperature_c if dynamic else None,
        minutes_above_product_limit=result.box.minutes_above_limit if dynamic else None,
        weather=result.weather,
        weather_days=result.weather_days,
        weather_source=result.weather_source,
        warnings=warnings,
        timezone=timezone_name,
        distance_source=legs.source,
        depot_snap_distance_m=None if snap is None else float(snap[0]),
        solver_status=status,
        objective=problem.objective,
        objective_value=objective_value,
        solver_runtime_s=runtime_s,
        profile=DayProfile([moment(int(i)) for i in picks], profile_kwh),
    )
