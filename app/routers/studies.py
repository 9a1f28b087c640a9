"""POST /v1/studies/*: the paper's what-if sweeps."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Depends, Request

from app import work
from app.examples import SCENARIOS_EXAMPLE, SPEED_SWEEP_EXAMPLE
from app.execution import Executor
from app.routers.plans import executor
from app.schemas import (
    ScenariosRequest,
    ScenariosResponse,
    SpeedSweepRequest,
    SpeedSweepResponse,
)
from app.settings import Settings, get_settings

router = APIRouter(prefix="/studies", tags=["studies"])


@router.post("/speed-sweep", operation_id="sweepSpeeds", summary="Best constant speed")
async def sweep_speeds(
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
    http: Request,
    settings: Annotated[Settings, Depends(get_settings)],
    pool: Annotated[Executor, Depends(executor)],
) -> SpeedSweepResponse:
    """Energy per km of each consumer on flat trips at each speed, and the speed with the
    lowest total: with the cooling unit on, about 40 km/h (paper Fig. 11)."""
    return await pool.run(work.sweep_speeds, request, settings, disconnected=http.is_disconnected)


@router.post("/scenarios", operation_id="runScenarios", summary="Seasons × drivers × traffic")
async def run_scenarios(
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
    http: Request,
    settings: Annotated[Settings, Depends(get_settings)],
    pool: Annotated[Executor, Depends(executor)],
) -> ScenariosResponse:
    """The round planned once for its own conditions (the baseline), then simulated on that
    tour for every combination of season, driver aggressiveness and traffic density."""
    return await pool.run(work.run_scenarios, request, settings, disconnected=http.is_disconnected)
