"""The work the service does, as plain functions of a validated request and the settings.

They run in the worker processes (:mod:`app.execution`) for the synchronous endpoints, and in
the job runners (the server's own pool or Celery workers) for ``/v1/jobs``; every argument and
every result pickles. A job's result is exactly what the synchronous endpoint returns.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import BaseModel

from app import connectors
from app.routers import results
from app.schemas import (
    ConsumptionWhPerKm,
    FleetPlanRequest,
    JobRequest,
    JobType,
    PlanRequest,
    PowerSeries,
    RoundRequest,
    ScenarioCellOut,
    ScenariosRequest,
    ScenariosResponse,
    Series,
    SimulateRequest,
    SimulateResponse,
    SpeedPointOut,
    SpeedSweepRequest,
    SpeedSweepResponse,
)
from app.settings import Settings
from core.clock import departure
from core.cycles import generate_leg
from core.exceptions import CoreError, LimitExceededError
from core.fleet import FleetProblem, FleetResult, FleetVehicle, check_fleet, plan_fleet
from core.params import STREET_TYPES, clock_time
from core.plan import check, plan
from core.round import PlanProblem, PlanResult
from core.simulate import check_trace, simulate
from core.studies import default_seasons, scenario_grid, speed_sweep
from core.weather import forecast_for

#: Shortest distance for which energy per km is reported [m].
MIN_DISTANCE_FOR_PER_KM_M = 1.0


def _round_fields(request: RoundRequest, settings: Settings) -> dict[str, Any]:
    """What a plan and a fleet plan pass alike to the core, within the server's limits."""
    if len(request.stops) > settings.max_stops:
        raise LimitExceededError(
            f"{len(request.stops)} stops; this server plans at most {settings.max_stops}",
            "stops",
        )
    return {
        "date": request.date,
        "timezone": request.timezone,
        "depot": request.depot,
        "stops": request.stops,
        "weather": request.weather,
        "driver_aggressiveness": request.driver_aggressiveness,
        "traffic_density": request.traffic_density,
        "objective": request.objective,
        "matrix": request.matrix,
        "time_limit_s": min(request.time_limit_s, settings.max_time_limit_s),
    }


def plan_problem(request: PlanRequest, settings: Settings) -> PlanProblem:
    """The core problem of a plan request, within the server's limits."""
    return PlanProblem(
        **_round_fields(request, settings),
        start_time=clock_time(request.start_time),
        van=request.van(),
        keep_order=request.keep_order,
    )


def fleet_problem(request: FleetPlanRequest, settings: Settings) -> FleetProblem:
    """The core problem of a fleet plan request, within the server's limits; a van's own
    errors name it (``vehicles[1].battery.min_soc``)."""
    fields = _round_fields(request, settings)
    vehicles = []
    for index, vehicle in enumerate(request.vehicles):
        try:
            van = vehicle.van()
        except CoreError as error:
            details = [(f"vehicles[{index}].{field}", rule) for field, rule in error.details]
            raise type(error)(error.message, details[0][0], details) from None
        vehicles.append(
            FleetVehicle(
                id=vehicle.id,
                van=van,
                shift_start=vehicle.shift_start,
                shift_end=vehicle.shift_end,
            )
        )
    return FleetProblem(**fields, vehicles=vehicles, minimize_vehicles=request.minimize_vehicles)


def run_fleet_plan(request: FleetPlanRequest, settings: Settings) -> FleetResult:
    """Plan the fleet's day with the configured road router and weather service."""
    return plan_fleet(
        fleet_problem(request, settings),
        connectors.router(settings),
        connectors.weather_service(settings),
    )


def run_plan(request: PlanRequest, settings: Settings) -> PlanResult:
    """Plan a round with the configured road router and weather service."""
    return plan(
        plan_problem(request, settings),
        connectors.router(settings),
        connectors.weather_service(settings),
    )


def simulate_trace(request: SimulateRequest, settings: Settings) -> SimulateResponse:
    """Energy of one speed trace, sent or generated (``POST /v1/simulate``)."""
    van = request.van()
    if request.cycle is not None:
        cycle = request.cycle
        street = STREET_TYPES[cycle.street_type]
        # Check the size before generating: a trace at least as long as cruising at v̄.
        if cycle.distance_m / street.mean_speed_mps / request.dt_s > settings.max_trace_samples:
            raise LimitExceededError(
                f"a {cycle.distance_m:g} m {cycle.street_type} trace at dt_s {request.dt_s:g} "
                f"has more than {settings.max_trace_samples} samples",
                "cycle.distance_m",
            )
        speed = generate_leg(
            cycle.distance_m,
            street,
            cycle.driver_aggressiveness,
            van.vehicle.max_acceleration_mps2,
            cycle.traffic_density,
            request.dt_s,
        )
    else:
        speed = np.asarray(request.speed_mps, dtype=float)
    if speed.size > settings.max_trace_samples:
        raise LimitExceededError(
            f"the trace has {speed.size} samples; this server simulates at most "
            f"{settings.max_trace_samples}",
            "speed_mps" if request.cycle is None else "cycle.distance_m",
        )
    check_trace(speed, request.dt_s)  # at least 2 samples; before asking for the weather
    weather, warnings = forecast_for(
        request.weather,
        connectors.weather_service(settings),
        request.location.lat,
        request.location.lon,
        request.start,
        (speed.size - 1) * request.dt_s,
    )
    result = simulate(
        speed,
        request.dt_s,
        request.start,
        request.location,
        van,
        grade=request.grade,
        weather=weather,
        door_openings=request.door_openings,
        parked=request.parked,
    )
    km = result.distance_m / 1000
    # Per-km figures of a trace that (nearly) stands still mean nothing: null below a metre.
    moved = result.distance_m >= MIN_DISTANCE_FOR_PER_KM_M
    per_km = {k: (v * 1000 / km if moved else None) for k, v in result.energy_kwh.items()}
    series = None
    if request.include_series:
        series = Series(
            time_s=result.time_s.tolist(),
            speed_mps=result.speed_mps.tolist(),
            power_w=PowerSeries(**{k: [0.0, *p.tolist()] for k, p in result.power_w.items()}),
            soc=result.soc.tolist(),
        )
    dynamic = van.cargo_box.mode == "dynamic"
    return SimulateResponse(
        distance_m=result.distance_m,
        duration_s=result.duration_s,
        energy_kwh=results.energy(result.energy_kwh),
        consumption_wh_per_km=ConsumptionWhPerKm(**per_km),
        battery=results.battery(result.battery, None, result.battery_loss_kwh),
        weather=results.weather(result.weather, result.weather_source, result.weather_days),
        box=results.box(
            result.box.max_temperature_c if dynamic else None,
            result.box.minutes_above_limit if dynamic else None,
        ),
        series=series,
        grid_kwh=result.grid_kwh,
        warnings=warnings,
    )


def sweep_speeds(request: SpeedSweepRequest, settings: Settings) -> SpeedSweepResponse:
    """Energy per km at each constant speed (``POST /v1/studies/speed-sweep``)."""
    start, _ = departure(
        request.date, clock_time(request.start_time), request.timezone, request.location.lon
    )
    for index, speed_kmh in enumerate(request.speeds_kmh):
        # Each trip is a trace of its own: at least its distance at its speed, every second.
        if speed_kmh > 0 and request.distance_m / (speed_kmh / 3.6) > settings.max_trace_samples:
            raise LimitExceededError(
                f"{request.distance_m:g} m at {speed_kmh:g} km/h takes more than "
                f"{settings.max_trace_samples} s; this server simulates at most that many samples",
                f"speeds_kmh[{index}]",
            )
    try:
        sweep = speed_sweep(
            request.speeds_kmh,
            request.distance_m,
            start,
            request.location,
            request.van(),
            request.weather,
            request.driver_aggressiveness,
            request.traffic_density,
        )
    except CoreError as error:
        if error.field == "start":  # the trips would run past the year 9999
            raise type(error)(error.message, "date") from None
        raise
    return SpeedSweepResponse(
        points=[
            SpeedPointOut(
                speed_kmh=p.speed_kmh, energy_wh_per_km=ConsumptionWhPerKm(**p.energy_wh_per_km)
            )
            for p in sweep.points
        ],
        optimum_speed_kmh=sweep.optimum_speed_kmh,
    )


def check_scenarios(request: ScenariosRequest, settings: Settings) -> None:
    """A scenario grid within the server's limit of cells × stops."""
    seasons = request.seasons or default_seasons(request.plan.date.year)
    n_cells = (
        len(seasons)
        * len(request.driver_aggressiveness or [0] * 3)
        * len(request.traffic_density or [0] * 2)
    )
    if n_cells * len(request.plan.stops) > settings.max_study_cell_stops:
        raise LimitExceededError(
            f"{n_cells} cells of {len(request.plan.stops)} stops; this server evaluates at most "
            f"{settings.max_study_cell_stops} cell-stops per study",
            "plan.stops",
        )


def run_scenarios(request: ScenariosRequest, settings: Settings) -> ScenariosResponse:
    """One round over seasons × drivers × traffic (``POST /v1/studies/scenarios``)."""
    check_scenarios(request, settings)
    seasons = request.seasons or default_seasons(request.plan.date.year)
    try:
        grid = scenario_grid(
            plan_problem(request.plan, settings),
            seasons,
            request.driver_aggressiveness,
            request.traffic_density,
            router=connectors.router(settings),
            weather_service=connectors.weather_service(settings),
        )
    except CoreError as error:  # the round's own fields sit under plan.
        if error.field is None or error.field.startswith(("seasons", "plan")):
            raise
        raise type(error)(error.message, f"plan.{error.field}") from None
    return ScenariosResponse(
        tour=grid.tour,
        baseline_energy_kwh=results.energy(grid.baseline_energy_kwh),
        cells=[
            ScenarioCellOut(**(vars(c) | {"energy_kwh": results.energy(c.energy_kwh)}))
            for c in grid.cells
        ],
    )


def check_job(job_type: JobType, request: JobRequest, settings: Settings) -> None:
    """Refuse at submission what would fail at once: everything but the solve itself."""
    if isinstance(request, PlanRequest):
        check(plan_problem(request, settings))
    elif isinstance(request, FleetPlanRequest):
        check_fleet(fleet_problem(request, settings))
    else:
        check_scenarios(request, settings)
        try:
            check(plan_problem(request.plan, settings))
        except CoreError as error:
            field = f"plan.{error.field}" if error.field else "plan"
            raise type(error)(error.message, field) from None


def run_job(job_type: JobType, request: dict[str, Any], settings: Settings) -> dict[str, Any]:
    """A job's result as JSON: exactly the synchronous endpoint's answer (jobs may solve up to
    ``max_job_time_limit_s``)."""
    settings = settings.model_copy(update={"max_time_limit_s": settings.max_job_time_limit_s})
    if job_type == "plan":
        plan_request = PlanRequest.model_validate(request)
        answer: BaseModel = results.plan_response(
            run_plan(plan_request, settings), plan_request.include_geometry
        )
    elif job_type == "fleet-plan":
        fleet_request = FleetPlanRequest.model_validate(request)
        answer = results.fleet_response(
            run_fleet_plan(fleet_request, settings), fleet_request.include_geometry
        )
    else:
        answer = run_scenarios(ScenariosRequest.model_validate(request), settings)
    return answer.model_dump(mode="json")
