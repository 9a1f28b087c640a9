"""POST /v1/studies/*: the paper's what-if sweeps."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Depends

from app import connectors
from app.examples import SCENARIOS_EXAMPLE, SPEED_SWEEP_EXAMPLE
from app.routers import results
from app.routers.plans import plan_problem
from app.schemas import (
    ConsumptionWhPerKm,
    ScenarioCellOut,
    ScenariosRequest,
    ScenariosResponse,
    SpeedPointOut,
    SpeedSweepRequest,
    SpeedSweepResponse,
    clock_time,
)
from app.settings import Settings, get_settings
from core.clock import departure
from core.exceptions import LimitExceededError
from core.studies import default_seasons, scenario_grid, speed_sweep

router = APIRouter(prefix="/studies", tags=["studies"])


@router.post("/speed-sweep", operation_id="sweepSpeeds", summary="Best constant speed")
def sweep_speeds(
    request: Annotated[
        SpeedSweepRequest,
        Body(
            openapi_examples={
                "hot-day": {
                    "summary": "Paper Fig. 11 on a hot Vienna day",
                    "value": SPEED_SWEEP_EXAMPLE,
                }
            }
        ),
    ],
) -> SpeedSweepResponse:
    """Energy per km of each consumer on flat trips at each speed, and the speed with the
    lowest total: with the cooling unit on, about 40 km/h (paper Fig. 11)."""
    start, _ = departure(
        request.date, clock_time(request.start_time), request.timezone, request.location.lon
    )
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
    return SpeedSweepResponse(
        points=[
            SpeedPointOut(
                speed_kmh=p.speed_kmh, energy_wh_per_km=ConsumptionWhPerKm(**p.energy_wh_per_km)
            )
            for p in sweep.points
        ],
        optimum_speed_kmh=sweep.optimum_speed_kmh,
    )


@router.post("/scenarios", operation_id="runScenarios", summary="Seasons × drivers × traffic")
def run_scenarios(
    request: Annotated[
        ScenariosRequest,
        Body(
            openapi_examples={
                "vienna-grid": {
                    "summary": "The Vienna round, default axes",
                    "value": SCENARIOS_EXAMPLE,
                }
            }
        ),
    ],
    settings: Annotated[Settings, Depends(get_settings)],
) -> ScenariosResponse:
    """The round planned once for its own conditions (the baseline), then simulated on that
    tour for every combination of season, driver aggressiveness and traffic density."""
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
    grid = scenario_grid(
        plan_problem(request.plan, settings),
        seasons,
        request.driver_aggressiveness,
        request.traffic_density,
        router=connectors.router(settings),
        weather_service=connectors.weather_service(settings),
    )
    return ScenariosResponse(
        tour=grid.tour,
        baseline_energy_kwh=results.energy(grid.baseline_energy_kwh),
        cells=[
            ScenarioCellOut(**(vars(c) | {"energy_kwh": results.energy(c.energy_kwh)}))
            for c in grid.cells
        ],
    )
