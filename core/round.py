"""One round of one van, driven and simulated (paper §4, Fig. 7): the day's timeline from the
order of its stops — depart, drive each leg (the router's road speed profile, or a generated
trace lasting the leg's duration), arrive, wait for the stop's time window, park, open the door
within the service time, unload (the payload and so the mass drop), go on, return — then one
vectorised simulation of the whole day (:func:`core.simulate.simulate`), split per leg and per
stop. The planners (:mod:`core.plan` for one van, :mod:`core.fleet` for several) choose the
order; this module also gives them their arc costs.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from core.arrays import FloatArray
from core.battery import JOULES_PER_KWH, BatteryVerdict
from core.clock import at, check_representable
from core.cycles import drive_profile, generate_leg, stretch_to_duration, trace_distance_m
from core.exceptions import InvalidStopsError, NoRouteError
from core.geo import (
    MAX_LEG_GRADE,
    STREET_TYPE_NAMES,
    DistanceSource,
    Legs,
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
from core.tsp import SolverStatus
from core.vehicle import step_traction_power_w
from core.weather import DayWeather, Forecast, WeatherSource

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
    service_start: dt.datetime
    wait_s: float
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
    late_stops: list[str]


@dataclass(frozen=True)
class Solved:
    """How the order of the stops was found: the solver's status, the objective's value in its
    unit (m, s or Wh) and the search time [s]."""

    status: SolverStatus
    objective_value: float
    runtime_s: float


#: The weather to simulate a span with: ``(start, span_s) -> (forecast or None, warnings)``.
WeatherFor = Callable[[dt.datetime, float], tuple[Forecast | None, list[str]]]


def simulate_round(
    problem: PlanProblem,
    places: list[Depot],
    legs: Legs,
    order: list[int],
    start: dt.datetime,
    timezone_name: str,
    routes: list[LegRoute] | None,
    weather_for: WeatherFor,
    solved: Solved,
    windows_s: Sequence[Sequence[tuple[float, float]]] | None = None,
    latest_return_s: float | None = None,
) -> PlanResult:
    """Drive the places in ``order`` (depot first and last) from ``start`` and simulate the day.

    Parameters
    ----------
    problem
        The van, the stops and the conditions.
    places, legs
        The depot then the stops, and every ordered pair's leg.
    order
        Place indices in driving order, 0 first and last.
    start
        Departure (zone-aware).
    routes
        The road of each leg of ``order`` from a router, or None to generate the traces.
    weather_for
        The weather for the day's span.
    solved
        How the order was found (reported as it is).
    windows_s
        Each place's time windows [s after ``start``]. The van waits at a stop for its window,
        and leaves the depot as much later as saves waiting without missing a window or
        ``latest_return_s``. Stops reached after their last window closes are served at once
        and listed in ``late_stops``.
    latest_return_s
        When the van must be back [s after ``start``], if ever.
    """
    timeline = _timeline(problem, places, legs, order, routes, windows_s)
    if windows_s is not None:
        delay_s = _later_departure_s(timeline, order, windows_s, latest_return_s)
        if delay_s > 0:
            start = at(start, delay_s)
            windows_s = [[(a - delay_s, b - delay_s) for a, b in place] for place in windows_s]
            timeline = _timeline(problem, places, legs, order, routes, windows_s)
    check_representable(start, timeline.speed.size * PLAN_DT_S, "date")
    weather, warnings = weather_for(start, timeline.speed.size * PLAN_DT_S)
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
        problem, places, legs, order, result, timeline, start, timezone_name, solved, warnings
    )


def _later_departure_s(
    timeline: _Timeline,
    order: list[int],
    windows_s: Sequence[Sequence[tuple[float, float]]],
    latest_return_s: float | None,
) -> float:
    """How much later the van can leave and wait less: a delay is absorbed by the waits before
    each stop, and beyond them shifts the stop's service, which must stay inside its window
    (the forward time slack of Savelsbergh, *ORSA J. Computing* 4 (1992) 146)."""
    waited = 0.0
    slack = (
        math.inf if latest_return_s is None else latest_return_s - timeline.leave[-1] * PLAN_DT_S
    )
    for k, j in enumerate(order[1:-1]):
        served_s = timeline.serve[k] * PLAN_DT_S
        waited += served_s - timeline.arrive[k] * PLAN_DT_S
        closes = next((b for a, b in windows_s[j] if a <= served_s <= b), math.inf)
        slack = min(slack, waited + closes - served_s)
    return float(max(min(waited, slack), 0.0) // PLAN_DT_S * PLAN_DT_S)


def windows_after(
    stops: Sequence[Stop], date: dt.date, reference: dt.datetime
) -> list[list[tuple[float, float]]]:
    """Each place's time windows (depot first, none) in seconds after ``reference``: the local
    clock times on ``date`` in ``reference``'s zone, as elapsed time (daylight saving counted)."""
    zone = reference.tzinfo
    origin = reference.timestamp()

    def seconds(clock: dt.time) -> float:
        return dt.datetime.combine(date, clock, tzinfo=zone).timestamp() - origin

    return [[]] + [
        [(seconds(w.start), seconds(w.end)) for w in stop.time_windows] for stop in stops
    ]


def check_stop_ids(depot: Depot, stops: Sequence[Stop]) -> None:
    """Every stop's id is its own (and not the depot's); else an error naming the second."""
    seen: dict[str, int] = {depot.id: -1}
    for index, stop in enumerate(stops):
        if stop.id in seen:
            other = "the depot" if seen[stop.id] < 0 else f"stops[{seen[stop.id]}]"
            raise InvalidStopsError(
                f"stop id '{stop.id}' is used twice (also by {other}); ids must be unique",
                f"stops[{index}].id",
            )
        seen[stop.id] = index


def leg_routes(router: RoadRouter, places: list[Depot], order: list[int]) -> list[LegRoute]:
    """The router's road of every leg of the tour; a leg with no road names its destination."""
    routes = []
    for i, j in itertools.pairwise(order):
        try:
            routes.append(router.route(places[i], places[j]))
        except NoRouteError as error:
            raise NoRouteError(error.message, place_field(j)) from None
    return routes


def place_field(index: int) -> str:
    """The request field of place ``index`` (0 the depot)."""
    return "depot" if index == 0 else f"stops[{index - 1}]"


def standing(problem: PlanProblem, start: dt.datetime, parked: bool = False) -> SimulationResult:
    """The van standing at the depot at ``start``, pre-conditioned: its loads at departure,
    with the engine running (``parked`` False) or parked at a stop (the cab's duty at stops)."""
    return simulate(
        np.zeros(2),
        PLAN_DT_S,
        start,
        Location(lat=problem.depot.lat, lon=problem.depot.lon),
        problem.van.model_copy(update={"precondition_at_depot": True}),
        weather=problem.weather,
        parked=[Interval(start_s=0.0, duration_s=2 * PLAN_DT_S)] if parked else [],
    )


def constant_power_w(problem: PlanProblem, start: dt.datetime) -> float:
    """Auxiliaries + cab + box power at departure, standing [W]: the energy objective's time
    cost."""
    still = standing(problem, start)
    return float(sum(still.power_w[name][0] for name in CONSUMERS if name != "traction"))


def energy_matrix_j(problem: PlanProblem, legs: Legs, start: dt.datetime) -> FloatArray:
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
    return traction + constant_power_w(problem, start) * legs.duration_s


def cost_matrix(
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
    tenth_wh = energy_matrix_j(problem, legs, start) / 360.0
    off_diagonal = ~np.eye(tenth_wh.shape[0], dtype=bool)
    lowest = float(tenth_wh[off_diagonal].min()) if off_diagonal.any() else 0.0
    shifted = np.where(off_diagonal, tenth_wh - lowest, 0.0)
    return np.rint(shifted).astype(np.int64), 0.1, lowest * 0.1


@dataclass(frozen=True)
class _Timeline:
    """The day sample by sample, and the marks that split it: leg k drives from depart[k] to
    arrive[k]; the stop after it (if any) waits for its window until serve[k] and lasts until
    leave[k]; ``late`` lists the places reached after their last window closed."""

    speed: FloatArray
    grade: FloatArray
    payload: FloatArray
    heading: FloatArray
    doors: list[DoorOpening]
    parked: list[Interval]
    depart: NDArray[np.int_]
    arrive: NDArray[np.int_]
    serve: NDArray[np.int_]
    leave: NDArray[np.int_]
    late: list[int]
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
        if legs.source == "client":  # the client's router knows how long the leg takes
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


def drive_time_s(problem: PlanProblem, legs: Legs, i: int, j: int, route: LegRoute | None) -> float:
    """How long the van takes from place i to place j in the simulation [s] (the generated or
    road-profile trace, which may differ from the matrix's duration)."""
    trace, _, _ = _drive(problem, legs, i, j, route, 0.0)
    return (trace.size - 1) * PLAN_DT_S


def _wait_s(arrival_s: float, windows_s: Sequence[tuple[float, float]]) -> float | None:
    """Wait from ``arrival_s`` until a window opens [s]: 0 inside one or without any; None
    when every window has closed."""
    if not windows_s:
        return 0.0
    for opens, closes in windows_s:
        if arrival_s <= closes:
            return max(opens - arrival_s, 0.0)
    return None


def _timeline(
    problem: PlanProblem,
    places: list[Depot],
    legs: Legs,
    order: list[int],
    routes: list[LegRoute] | None,
    windows_s: Sequence[Sequence[tuple[float, float]]] | None = None,
) -> _Timeline:
    """Speed, grade, payload and heading of every sample of the day, the door openings, the
    stops and the marks. With ``windows_s`` (each place's time windows, seconds after the
    departure) the van waits, parked with the door shut, for a stop's window to open; a stop
    reached after its last window closes is served at once and listed in ``late``."""
    speed_parts: list[FloatArray] = [np.zeros(1)]
    grade_parts: list[FloatArray] = [np.zeros(1)]
    heading_parts: list[FloatArray] = [np.full(1, np.nan)]
    payload_parts: list[FloatArray] = [np.array([problem.van.payload_kg])]
    doors: list[DoorOpening] = []
    parked: list[Interval] = []
    depart, arrive, serve, leave = [], [], [], []
    late: list[int] = []
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
            wait_s = _wait_s(clock * PLAN_DT_S, windows_s[j] if windows_s is not None else ())
            if wait_s is None:
                late.append(j)
            wait = math.ceil((wait_s or 0.0) / PLAN_DT_S)
            dwell = math.ceil(stop.service_time_s / PLAN_DT_S)
            parked.append(
                Interval(start_s=clock * PLAN_DT_S, duration_s=(wait + dwell) * PLAN_DT_S)
            )
            clock += wait
            serve.append(clock)
            if stop.door_open_s > 0:
                doors.append(DoorOpening(start_s=clock * PLAN_DT_S, duration_s=stop.door_open_s))
            speed_parts.append(np.zeros(wait + dwell))
            grade_parts.append(np.zeros(wait + dwell))
            heading_parts.append(np.full(wait + dwell, np.nan))
            # Unloading happens during the service: the lighter van drives away.
            payload_parts.append(np.full(wait, payload))
            payload = max(payload - stop.delivery_kg, 0.0)
            payload_parts.append(np.full(dwell, payload))
            clock += dwell
        else:
            serve.append(clock)
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
        serve=np.array(serve),
        leave=np.array(leave),
        late=late,
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
    solved: Solved,
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
        served = int(timeline.serve[k])
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
                    service_start=moment(served),
                    wait_s=(served - b) * PLAN_DT_S,
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
        solver_status=solved.status,
        objective=problem.objective,
        objective_value=solved.objective_value,
        solver_runtime_s=solved.runtime_s,
        profile=DayProfile([moment(int(i)) for i in picks], profile_kwh),
        late_stops=[places[j].id for j in timeline.late],
    )
