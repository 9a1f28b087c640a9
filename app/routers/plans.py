"""POST /v1/plans: the round trip, simulated."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Depends

from app.examples import PLAN_EXAMPLE
from app.routers import results
from app.schemas import (
    EnergyShare,
    LegOut,
    PlanRequest,
    PlanResponse,
    SolverOut,
    StopOut,
    Totals,
    clock_time,
)
from app.settings import Settings, get_settings
from core.exceptions import LimitExceededError
from core.plan import PlanProblem, plan

router = APIRouter(tags=["plans"])


def plan_problem(request: PlanRequest, settings: Settings) -> PlanProblem:
    """The core problem of a plan request, within the server's limits."""
    if len(request.stops) > settings.max_stops:
        raise LimitExceededError(
            f"{len(request.stops)} stops; this server plans at most {settings.max_stops}",
            "stops",
        )
    return PlanProblem(
        date=request.date,
        start_time=clock_time(request.start_time),
        timezone=request.timezone,
        depot=request.depot,
        stops=request.stops,
        van=request.van(),
        weather=request.weather,
        driver_aggressiveness=request.driver_aggressiveness,
        traffic_density=request.traffic_density,
        objective=request.objective,
        matrix=request.matrix,
        keep_order=request.keep_order,
        time_limit_s=min(request.time_limit_s, settings.max_time_limit_s),
    )


@router.post("/plans", operation_id="createPlan", summary="Plan and simulate a delivery round")
def create_plan(
    request: Annotated[
        PlanRequest,
        Body(
            openapi_examples={
                "vienna-8-stops": {
                    "summary": "A summer morning round in Vienna",
                    "value": PLAN_EXAMPLE,
                }
            }
        ),
    ],
    settings: Annotated[Settings, Depends(get_settings)],
) -> PlanResponse:
    """Orders the stops (OR-Tools), simulates every leg and stop with the paper's model and says
    whether the battery holds out. Runs in a worker thread, off the event loop."""
    result = plan(plan_problem(request, settings))
    return PlanResponse(
        tour=result.tour,
        legs=[
            LegOut(**(vars(leg) | {"energy_kwh": results.energy(leg.energy_kwh)}))
            for leg in result.legs
        ],
        stops=[
            StopOut(**(vars(stop) | {"energy_kwh": results.energy(stop.energy_kwh)}))
            for stop in result.stops
        ],
        totals=Totals(
            distance_m=result.distance_m,
            duration_s=result.duration_s,
            energy_kwh=results.energy(result.energy_kwh),
            energy_share=EnergyShare(**result.energy_share),
        ),
        battery=results.battery(result.battery, result.first_infeasible_leg),
        weather=results.weather(result.weather, result.weather_source),
        timezone=result.timezone,
        box=results.box(result.max_box_temperature_c, result.minutes_above_product_limit),
        solver=SolverOut(
            status=result.solver_status,
            objective=result.objective,
            objective_value=result.objective_value,
            runtime_s=result.solver_runtime_s,
        ),
    )
