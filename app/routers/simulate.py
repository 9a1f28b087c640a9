"""POST /v1/simulate: energy of one speed trace."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Request, Response

from app.deps import ExecutorDep, SettingsDep
from app.examples import SIMULATE_EXAMPLE, SIMULATE_TRACE_EXAMPLE
from app.operations import simulate as operation
from app.schemas.simulate import SimulateRequest, SimulateResponse

router = APIRouter(tags=["simulation"])


@router.post(
    "/simulate",
    operation_id="simulateTrace",
    summary="Energy of one speed trace",
    response_model=SimulateResponse,
)
async def simulate_trace(
    request: Annotated[
        SimulateRequest,
        Body(
            openapi_examples={
                "urban-cycle": {
                    "summary": "Generated 8 km urban leg, summer",
                    "value": SIMULATE_EXAMPLE,
                },
                "own-trace": {
                    "summary": "Your own 1 Hz trace, winter, with series",
                    "value": SIMULATE_TRACE_EXAMPLE,
                },
            }
        ),
    ],
    http: Request,
    settings: SettingsDep,
    pool: ExecutorDep,
) -> Response:
    """Per-consumer power and energy, state of charge and battery verdict along a trace you send
    (`speed_mps`, `dt_s`, `grade`) or one generated from a street type (`cycle`)."""
    return await pool.answer(
        operation.simulate_trace, request, settings, disconnected=http.is_disconnected
    )
