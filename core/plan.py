"""A delivery round from depot, stops and date to a simulated round trip (paper §4, Fig. 7).

1. legs between every ordered pair (:mod:`core.geo`); 2. the tour (:mod:`core.tsp`) on the
chosen objective; 3. the day's timeline — depart, drive each leg (a generated speed trace),
arrive, open the door within the service time, unload (the payload and so the mass drop), go
on, return; 4. one vectorised simulation of the whole day (:func:`core.simulate.simulate`),
split per leg and per stop.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
from dataclasses import dataclass
from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from core.arrays import FloatArray
from core.battery import JOULES_PER_KWH, BatteryVerdict
from core.cycles import generate_leg, stretch_to_duration, trace_distance_m
from core.exceptions import InvalidParameterError, InvalidStopsError, LimitExceededError
from core.geo import MAX_LEG_GRADE, STREET_TYPE_NAMES, Legs, build_legs
from core.params import (
    NORMAL_DRIVER,
    STREET_TYPES,
    Depot,
    DoorOpening,
    Location,
    Objective,
    Params,
    RoadMatrix,
    Stop,
    StreetTypeName,
    VanParams,
    Weather,
)
from core.simulate import CONSUMERS, SimulationResult, simulate
from core.tsp import SolverStatus, solve_tour
from core.vehicle import step_traction_power_w
from core.weather import WeatherSource

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
    """One driven leg of the round."""

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
    first_infeasible_leg: int | None
    max_box_temperature_c: float | None
    minutes_above_product_limit: float | None
    weather: Weather
    weather_source: WeatherSource
    timezone: str
    solver_status: SolverStatus
    objective: Objective
    objective_value: float
    solver_runtime_s: float
    profile: DayProfile


def plan(problem: PlanProblem) -> PlanResult:
    """Solve the round trip on the chosen objective and simulate it in full (paper Fig. 7)."""
    _check_stops(problem)
    start, timezone_name = departure(
        problem.date, problem.start_time, problem.timezone, problem.depot.lon
    )
    places: list[Depot] = [problem.depot, *problem.stops]
    legs = build_legs(places, problem.matrix)
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

    speed, grade, payload, doors, marks = _timeline(problem, legs, order)
    result = simulate(
        speed,
        PLAN_DT_S,
        start,
        Location(lat=problem.depot.lat, lon=problem.depot.lon),
        problem.van,
        grade=grade,
        payload_kg=payload,
        weather=problem.weather,
        door_openings=doors,
    )
    return _assemble(
        problem,
        places,
        legs,
        order,
        result,
        marks,
        start,
        timezone_name,
        tour.status,
        objective_value,
        tour.runtime_s,
    )


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


def departure(
    date: dt.date, start_time: dt.time, timezone: str | None, lon: float
) -> tuple[dt.datetime, str]:
    """Departure time with its zone, and the zone's name; with no IANA zone, local mean solar
    time at longitude ``lon`` [°] (UTC offset lon/15 h)."""
    if timezone is None:
        offset = dt.timedelta(minutes=round(lon * 4))
        zone: dt.tzinfo = dt.timezone(offset)
        minutes = abs(int(offset.total_seconds() // 60))
        sign = "+" if offset >= dt.timedelta(0) else "-"
        name = f"local mean solar time (UTC{sign}{minutes // 60:02d}:{minutes % 60:02d})"
    else:
        try:
            zone = ZoneInfo(timezone)
        except (ZoneInfoNotFoundError, ValueError):
            raise InvalidParameterError(
                f"unknown time zone '{timezone}'; use an IANA name like Europe/Vienna",
                "timezone",
            ) from None
        name = timezone
    return dt.datetime.combine(date, start_time, tzinfo=zone), name


def _constant_power_w(problem: PlanProblem, start: dt.datetime) -> float:
    """Auxiliaries + cab + box power at departure, standing [W]: the energy objective's time
    cost."""
    standing = simulate(
        np.zeros(2),
        PLAN_DT_S,
        start,
        Location(lat=problem.depot.lat, lon=problem.depot.lon),
        problem.van,
        weather=problem.weather,
    )
    return float(sum(standing.power_w[name][0] for name in CONSUMERS if name != "traction"))


def _energy_matrix_j(problem: PlanProblem, legs: Legs, start: dt.datetime) -> FloatArray:
    """Estimated electric energy of every leg [J]: the energy objective's arc costs.

    Traction per metre is simulated once per street type on a 10 km reference trace (same
    driver, traffic and departure mass) at every grade of a table from −25 % to +25 % in one
    broadcast call, and read for each leg by interpolation in its grade: climbs cost over the
    drive-train efficiency, descents first replace motoring and only then regenerate, and the
    matrix is asymmetric. Auxiliaries, cab and box add their power at departure times the leg's
    duration. The chosen tour is then simulated in full.
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
class _Marks:
    """Sample indices of the timeline: leg k drives from depart[k] to arrive[k]; the stop after
    it (if any) lasts until leave[k]."""

    depart: NDArray[np.int_]
    arrive: NDArray[np.int_]
    leave: NDArray[np.int_]


def _timeline(
    problem: PlanProblem, legs: Legs, order: list[int]
) -> tuple[FloatArray, FloatArray, FloatArray, list[DoorOpening], _Marks]:
    """Speed, grade and payload of every sample of the day, the door openings and the marks."""
    vehicle = problem.van.vehicle
    speed_parts: list[FloatArray] = [np.zeros(1)]
    grade_parts: list[FloatArray] = [np.zeros(1)]
    payload_parts: list[FloatArray] = [np.array([problem.van.payload_kg])]
    doors: list[DoorOpening] = []
    depart, arrive, leave = [], [], []
    clock = 0
    payload = problem.van.payload_kg
    for i, j in itertools.pairwise(order):
        trace = generate_leg(
            float(legs.distance_m[i, j]),
            STREET_TYPES[legs.street_type_name(i, j)],
            problem.driver_aggressiveness,
            vehicle.max_acceleration_mps2,
            problem.traffic_density,
            PLAN_DT_S,
        )
        if legs.from_client:
            trace = stretch_to_duration(trace, PLAN_DT_S, float(legs.duration_s[i, j]))
        drive = trace[1:]
        depart.append(clock)
        clock += drive.size
        arrive.append(clock)
        speed_parts.append(drive)
        grade_parts.append(np.full(drive.size, legs.grade[i, j]))
        payload_parts.append(np.full(drive.size, payload))
        if j != 0:
            stop = problem.stops[j - 1]
            dwell = math.ceil(stop.service_time_s / PLAN_DT_S)
            if stop.door_open_s > 0:
                doors.append(DoorOpening(start_s=clock * PLAN_DT_S, duration_s=stop.door_open_s))
            payload = max(payload - stop.delivery_kg, 0.0)
            speed_parts.append(np.zeros(dwell))
            grade_parts.append(np.zeros(dwell))
            # Unloading happens during the stop: the lighter van drives away.
            payload_parts.append(np.full(dwell, payload))
            clock += dwell
        leave.append(clock)
    marks = _Marks(np.array(depart), np.array(arrive), np.array(leave))
    return (
        np.concatenate(speed_parts),
        np.concatenate(grade_parts),
        np.concatenate(payload_parts),
        doors,
        marks,
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
    marks: _Marks,
    start: dt.datetime,
    timezone_name: str,
    status: SolverStatus,
    objective_value: float,
    runtime_s: float,
) -> PlanResult:
    cumulative = {
        name: np.concatenate(([0.0], np.cumsum(power) * PLAN_DT_S))
        for name, power in result.power_w.items()
    }
    door_cumulative = np.concatenate(([0.0], np.cumsum(result.box.door_heat_w) * PLAN_DT_S))
    soc = result.soc

    def at(sample: int) -> dt.datetime:
        return start + dt.timedelta(seconds=float(sample) * PLAN_DT_S)

    leg_results, stop_results = [], []
    payload = problem.van.payload_kg
    for k, (i, j) in enumerate(itertools.pairwise(order)):
        a, b, c = int(marks.depart[k]), int(marks.arrive[k]), int(marks.leave[k])
        leg_results.append(
            LegResult(
                from_id=places[i].id,
                to_id=places[j].id,
                depart=at(a),
                arrive=at(b),
                distance_m=trace_distance_m(result.speed_mps[a : b + 1], PLAN_DT_S),
                duration_s=(b - a) * PLAN_DT_S,
                street_type=legs.street_type_name(i, j),
                grade=float(legs.grade[i, j]),
                energy_kwh=_span_kwh(cumulative, a, b),
                soc_start=float(soc[a]),
                soc_end=float(soc[b]),
            )
        )
        if j != 0:
            payload = max(payload - problem.stops[j - 1].delivery_kg, 0.0)
            stop_results.append(
                StopResult(
                    id=places[j].id,
                    arrival=at(b),
                    departure=at(c),
                    door_heat_kwh=float(door_cumulative[c] - door_cumulative[b]) / JOULES_PER_KWH,
                    payload_after_kg=payload,
                    energy_kwh=_span_kwh(cumulative, b, c),
                    soc_arrival=float(soc[b]),
                    soc_departure=float(soc[c]),
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
        first_infeasible_leg=(
            None if first_bad is None else int(np.searchsorted(marks.leave, first_bad, side="left"))
        ),
        max_box_temperature_c=result.box.max_temperature_c if dynamic else None,
        minutes_above_product_limit=result.box.minutes_above_limit if dynamic else None,
        weather=result.weather,
        weather_source=result.weather_source,
        timezone=timezone_name,
        solver_status=status,
        objective=problem.objective,
        objective_value=objective_value,
        solver_runtime_s=runtime_s,
        profile=DayProfile([at(int(i)) for i in picks], profile_kwh),
    )
