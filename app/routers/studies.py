"""POST /v1/studies/*: the paper's what-if sweeps."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Request

from app.deps import ExecutorDep, SettingsDep
from app.examples import SCENARIOS_EXAMPLE, SPEED_SWEEP_EXAMPLE
from app.operations.studies import run_scenarios as scenarios
from app.operations.studies import sweep_speeds as sweep
from app.schemas.studies import (
    ScenariosRequest,
    ScenariosResponse,
    SpeedSweepRequest,
    SpeedSweepResponse,
)

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
    settings: SettingsDep,
    pool: ExecutorDep,
) -> SpeedSweepResponse:
    """Energy per km of each consumer on flat trips at each speed, and the speed with the
    lowest total: with the cooling unit on, about 40 km/h (paper Fig. 11)."""
    return await pool.run(sweep, request, settings, disconnected=http.is_disconnected)


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
    settings: SettingsDep,
    pool: ExecutorDep,
) -> ScenariosResponse:
    """The round planned once for its own conditions (the baseline), then simulated on that
    tour for every combination of season, driver aggressiveness and traffic density."""
    return await pool.run(scenarios, request, settings, disconnected=http.is_disconnected)
