"""POST /v1/studies/*: the paper's what-if sweeps."""

from __future__ import annotations

import asyncio
import time
from typing import Annotated

from fastapi import APIRouter, Body, Request

from app.deps import ExecutorDep, SettingsDep
from app.examples import ELECTRIFICATION_EXAMPLE, SCENARIOS_EXAMPLE, SPEED_SWEEP_EXAMPLE
from app.operations.electrification import merged_answer, run_study_part, study_parts
from app.operations.studies import run_scenarios as scenarios
from app.operations.studies import sweep_speeds as sweep
from app.schemas.studies import (
    ElectrificationRequest,
    ElectrificationResponse,
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


@router.post(
    "/electrification",
    operation_id="studyElectrification",
    summary="Which routes can go electric, with which battery",
)
async def study_electrification(
    request: Annotated[
        ElectrificationRequest,
        Body(
            openapi_examples={
                "vienna-two-routes": {
                    "summary": "Two Vienna routes on weekdays, three batteries",
                    "value": ELECTRIFICATION_EXAMPLE,
                }
            }
        ),
    ],
    http: Request,
    settings: SettingsDep,
    pool: ExecutorDep,
) -> ElectrificationResponse:
    """Each route as it was driven — its stops in order from its start time — simulated for
    each candidate van on every day it is driven in the year, with that date's weather: the
    days each battery covers (alone, and with the charges a day may take), the battery that
    covers 95 % and all of them, the worst days and why; per candidate, the routes that go
    electric and the depot's recharge. The routes are shared out over the server's workers.
    Larger studies run as jobs (type electrification)."""
    started = time.perf_counter()
    parts, weather = await pool.run(
        study_parts, request, settings, disconnected=http.is_disconnected
    )
    done = await asyncio.gather(
        *(
            pool.run(
                run_study_part, request, settings, part, weather, disconnected=http.is_disconnected
            )
            for part in parts
        )
    )
    runtime_s = time.perf_counter() - started
    return await asyncio.to_thread(merged_answer, request, settings, list(done), weather, runtime_s)
