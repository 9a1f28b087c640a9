"""POST /v1/fleet-plans: the day's stops across several vans, every route simulated."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Request, Response

from app.deps import ExecutorDep, SettingsDep
from app.examples import FLEET_EXAMPLES
from app.execution import sent
from app.openapi_doc import request_examples
from app.operations.fleet_plan import fleet_answer
from app.schemas.fleet import FleetPlanRequest, FleetPlanResponse

router = APIRouter(tags=["fleet"])


@router.post(
    "/fleet-plans",
    operation_id="createFleetPlan",
    summary="Plan the day's stops across a fleet of vans",
    response_model=FleetPlanResponse,
)
async def create_fleet_plan(
    request: Annotated[
        FleetPlanRequest,
        Body(openapi_examples=request_examples(FLEET_EXAMPLES)),
    ],
    http: Request,
    settings: SettingsDep,
    pool: ExecutorDep,
) -> Response:
    """Splits the stops across the vans (PyVRP's search, OR-Tools' where the battery binds; time
    windows, shifts, payload and each van's battery as constraints) and simulates every route's day
    in full: the charge never falls below a van's reserve, service starts inside a window, every van
    is back before its shift ends, deliveries fit the payload. A route the simulation rejects is
    tightened and solved again (its work `work_s`, `time_limit_s` the cap); stops no van can
    serve are listed in `unassigned` with their reason. Solved in a worker process, as plans
    are."""
    made = await pool.run(fleet_answer, request, settings, disconnected=http.is_disconnected)
    http.app.state.metrics.solve.observe(made.runtime_s)
    return sent(made)
