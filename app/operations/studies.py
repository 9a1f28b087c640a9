"""``POST /v1/studies/*`` and jobs of type ``scenarios``: the speed sweep and the scenario grid."""

from __future__ import annotations

import datetime as dt

from app import connectors
from app.operations.answers import energy
from app.operations.plan import check_plan, plan_problem
from app.operations.vans import van_of
from app.schemas.base import ConsumptionWhPerKm
from app.schemas.studies import (
    ScenarioCellOut,
    ScenariosRequest,
    ScenariosResponse,
    SpeedPointOut,
    SpeedSweepRequest,
    SpeedSweepResponse,
)
from app.settings import Settings
from core.clock import departure
from core.exceptions import CoreError, LimitExceededError, TooMuchToWaitForError
from core.planning.studies import (
    GridAxes,
    SweepTrips,
    check_seasons,
    default_seasons,
    scenario_grid,
    speed_sweep,
)


def sweep_start(request: SpeedSweepRequest, settings: Settings) -> dt.datetime:
    """The sweep's departure, and each trip within the server's limit of samples."""
    start, _ = departure(request.date, request.start_time, request.timezone, request.location.lon)
    for index, speed_kmh in enumerate(request.speeds_kmh):
        # Each trip is a trace of its own: at least its distance at its speed, every second.
        if request.distance_m / (speed_kmh / 3.6) > settings.max_trace_samples:
            raise LimitExceededError(
                f"{request.distance_m:g} m at {speed_kmh:g} km/h takes more than "
                f"{settings.max_trace_samples} s; this server simulates at most that many samples",
                f"speeds_kmh[{index}]",
            )
    return start


def check_sweep(request: SpeedSweepRequest, settings: Settings) -> None:
    """Everything but the sweep itself: what a job refuses at submission."""
    sweep_start(request, settings)
    van_of(request, settings)


def sweep_speeds(request: SpeedSweepRequest, settings: Settings) -> SpeedSweepResponse:
    """Energy per km at each constant speed (``POST /v1/studies/speed-sweep``)."""
    start = sweep_start(request, settings)
    simulated_s = sum(request.distance_m / (v / 3.6) for v in request.speeds_kmh)
    if simulated_s > settings.max_sync_simulated_s:
        raise TooMuchToWaitForError(
            f"{len(request.speeds_kmh)} trips of {request.distance_m:g} m simulate "
            f"{simulated_s / 86_400:,.0f} days; a synchronous sweep simulates at most "
            f"{settings.max_sync_simulated_s / 86_400:,.0f}: fewer speeds or a shorter trip, or "
            "submit it as a job (POST /v1/jobs, type speed-sweep)",
            "speeds_kmh",
        )
    try:
        trips = SweepTrips(
            request.distance_m, request.driver_aggressiveness, request.traffic_density
        )
        sweep = speed_sweep(
            request.speeds_kmh, trips, start, request.location, van_of(request, settings),
            request.weather,
        )  # fmt: skip
    except CoreError as error:
        if error.field == "start":  # the trips would run past the year 9999
            raise error.at("date") from None
        raise
    return SpeedSweepResponse(
        points=[
            SpeedPointOut(
                **dict(p) | {"energy_wh_per_km": ConsumptionWhPerKm(**p.energy_wh_per_km)}
            )
            for p in sweep.points
        ],
        optimum_speed_kmh=sweep.optimum_speed_kmh,
    )


def check_scenarios(request: ScenariosRequest, settings: Settings, job: bool = False) -> None:
    """A scenario grid within the server's limits: cells × stops, and the time the cells
    simulate — at least their services' — within what a synchronous study (a 413 pointing to
    jobs) or a job simulates."""
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
    least_s = n_cells * sum(stop.service_time_s for stop in request.plan.stops)
    limit_s = settings.max_job_simulated_s if job else settings.max_sync_simulated_s
    if least_s > limit_s:
        said = (
            f"{n_cells} cells of a round whose services alone take "
            f"{least_s / n_cells / 3600:,.1f} h simulate at least {least_s / 86_400:,.0f} days; "
        )
        if job:
            raise LimitExceededError(
                f"{said}a job simulates at most {limit_s / 86_400:,.0f}: fewer cells", "seasons"
            )
        raise TooMuchToWaitForError(
            f"{said}a synchronous study simulates at most {limit_s / 86_400:,.0f}: fewer "
            "cells, or submit it as a job (POST /v1/jobs, type scenarios)",
            "seasons",
        )


def run_scenarios(request: ScenariosRequest, settings: Settings) -> ScenariosResponse:
    """One round over seasons × drivers × traffic (``POST /v1/studies/scenarios``)."""
    check_scenarios(request, settings)
    seasons = request.seasons or default_seasons(request.plan.date.year)
    try:
        grid = scenario_grid(
            plan_problem(request.plan, settings),
            GridAxes(seasons, request.driver_aggressiveness, request.traffic_density),
            router=connectors.router(settings),
            weather_service=connectors.weather_service(settings),
            max_simulated_s=settings.max_sync_simulated_s,
        )
    except CoreError as error:  # the round's own fields sit under plan.
        if error.field is not None and error.field.startswith(("seasons", "plan")):
            raise
        raise error.under("plan") from None
    return ScenariosResponse(
        tour=grid.tour,
        baseline_energy_kwh=energy(grid.baseline_energy_kwh),
        cells=[
            ScenarioCellOut(**dict(c) | {"energy_kwh": energy(c.energy_kwh)}) for c in grid.cells
        ],
    )


def check_scenarios_job(request: ScenariosRequest, settings: Settings) -> None:
    """Everything but the grid itself: what a job refuses at submission."""
    check_scenarios(request, settings, job=True)
    try:
        check_plan(request.plan, settings)
    except CoreError as error:
        raise error.under("plan") from None
    check_seasons(
        plan_problem(request.plan, settings),
        request.seasons or default_seasons(request.plan.date.year),
    )
