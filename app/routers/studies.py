"""POST /v1/studies/*: the paper's what-if sweeps."""

from __future__ import annotations

import asyncio
import time
from typing import Annotated

from fastapi import APIRouter, Body, File, Form, Request, Response, UploadFile
from starlette.concurrency import run_in_threadpool

from app.deps import ExecutorDep, SettingsDep
from app.examples import ELECTRIFICATION_EXAMPLE, SCENARIOS_EXAMPLE, SPEED_SWEEP_EXAMPLE
from app.execution import sent
from app.operations.electrification import merged_answer, plan_study, run_study_part
from app.operations.encoded import answered
from app.operations.studies import run_scenarios as scenarios
from app.operations.studies import sweep_speeds as sweep
from app.operations.telematics import with_history
from app.routers.forms import json_object, text_of, validated
from app.schemas.studies import (
    ElectrificationRequest,
    ElectrificationResponse,
    ScenariosRequest,
    ScenariosResponse,
    SpeedSweepRequest,
    SpeedSweepResponse,
)

router = APIRouter(prefix="/studies", tags=["studies"])


@router.post(
    "/speed-sweep",
    operation_id="sweepSpeeds",
    summary="Best constant speed",
    response_model=SpeedSweepResponse,
)
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
) -> Response:
    """Energy per km of each consumer on flat trips at each speed, and the speed with the
    lowest total: with the cooling unit on, about 40 km/h (paper Fig. 11)."""
    return await pool.answer(sweep, request, settings, disconnected=http.is_disconnected)


@router.post(
    "/scenarios",
    operation_id="runScenarios",
    summary="Seasons × drivers × traffic",
    response_model=ScenariosResponse,
)
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
) -> Response:
    """The round planned once for its own conditions (the baseline), then simulated on that
    tour for every combination of season, driver aggressiveness and traffic density."""
    return await pool.answer(scenarios, request, settings, disconnected=http.is_disconnected)


@router.post(
    "/electrification",
    operation_id="studyElectrification",
    summary="Which routes can go electric, with which battery",
    response_model=ElectrificationResponse,
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
) -> Response:
    """Each route as it was driven — its stops in order from its start time — simulated for
    each candidate van on every day it is driven in the year, with that date's weather: the
    days each battery covers (alone, and with the charges a day may take), the battery that
    covers 95 % and all of them, the worst days and why; per candidate, the routes that go
    electric and the depot's recharge. The routes are shared out over the server's workers.
    Larger studies run as jobs (type electrification)."""
    started = time.perf_counter()
    context, parts = await pool.run(
        plan_study, request, settings, settings.workers, False, disconnected=http.is_disconnected
    )
    done = await asyncio.gather(
        *(
            pool.run(
                run_study_part, request, settings, context, spec, disconnected=http.is_disconnected
            )
            for spec, _ in parts
        )
    )
    runtime_s = time.perf_counter() - started
    return sent(
        await asyncio.to_thread(
            answered, merged_answer, request, settings, context, list(done), runtime_s
        )
    )


@router.post(
    "/electrification/from-csv",
    operation_id="electrificationStudyFromCsv",
    summary="A study's routes from a telematics export or GPS traces (CSV)",
    response_model_exclude_unset=True,  # the study as sent, ready to send on
)
async def electrification_study_from_csv(
    study: Annotated[
        str,
        Form(
            description="The body of POST /v1/studies/electrification as JSON text, its routes "
            "without stops, start_time and days: `id`, `depot`, `product`."
        ),
    ],
    history: Annotated[
        UploadFile,
        File(
            description="The telematics export: a header row, then one row per stop visited — "
            "`route_id`, `date` (YYYY-MM-DD), `stop_id`, `lat`, `lon`, `arrival`, `departure` "
            "(local HH:MM or HH:MM:SS) and optionally `delivery_kg`, `door_minutes`; each day "
            "of a route its rows together, first the departure from the route's depot (its "
            "`stop_id` the depot's id), then the stops in the order driven, then the return if "
            "the export has it. Or GPS traces, one row per fix: `route_id`, `date`, `time` "
            "(local HH:MM[:SS]), `lat`, `lon`, each day's fixes together in time order: the "
            "day starts at the last fix at the depot (within 150 m), a stop is 2 min or more "
            "within 50 m, its service the dwell. Comma or semicolon between cells. UTF-8."
        ),
    ],
) -> ElectrificationRequest:
    """The study with each route's days as driven, read from the export (a bad cell is a 422
    naming `history[<line>].<column>`, the file's line): send it to POST
    /v1/studies/electrification, or as a job of type electrification when it is large."""
    body = json_object(study, "study")
    text = await text_of(history, "history")
    merged = await run_in_threadpool(with_history, body, text)
    return validated(ElectrificationRequest, merged)
