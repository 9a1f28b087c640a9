"""POST /v1/plans: the round trip, simulated."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Header, Request, Response

from app.deps import ExecutorDep, SettingsDep
from app.examples import PLAN_EXAMPLES
from app.execution import sent
from app.openapi_doc import request_examples
from app.operations.plan import GEOJSON, plan_answer
from app.schemas.plans import PlanRequest, PlanResponse

router = APIRouter(tags=["plans"])


def wants_geojson(accept: str | None) -> bool:
    """Whether the Accept header prefers GeoJSON over plain JSON (RFC 9110 quality values)."""
    if not accept:
        return False
    quality: dict[str, float] = {}
    for part in accept.split(","):
        media, *params = (p.strip() for p in part.split(";"))
        q = 1.0
        for param in params:
            if param.startswith("q="):
                try:
                    q = float(param[2:])
                except ValueError:
                    q = 0.0
        quality[media.lower()] = max(q, quality.get(media.lower(), 0.0))
    geo = quality.get(GEOJSON, 0.0)
    plain = max(quality.get("application/json", 0.0), quality.get("*/*", 0.0) * 0.999)
    return geo > 0 and geo >= plain


@router.post(
    "/plans",
    operation_id="createPlan",
    summary="Plan and simulate a delivery round",
    response_model=PlanResponse,
    responses={
        200: {
            "description": "The planned round; as a GeoJSON FeatureCollection when the request "
            "accepts application/geo+json.",
            "content": {
                GEOJSON: {"schema": {"$ref": "#/components/schemas/PlanFeatureCollection"}}
            },
        }
    },
)
async def create_plan(
    request: Annotated[
        PlanRequest,
        Body(openapi_examples=request_examples(PLAN_EXAMPLES)),
    ],
    http: Request,
    settings: SettingsDep,
    pool: ExecutorDep,
    accept: Annotated[
        str | None,
        Header(description="application/json (default) or application/geo+json for a map."),
    ] = None,
) -> Response:
    """Orders the stops (a local search, CP-SAT's proof), simulates every leg and stop with the
    paper's model and says whether the battery holds out. With `COLDROUTE_OSRM_URL` set, distances,
    durations and each leg's speed profile come from the OSRM road router. Solved in a worker
    process; when every worker is busy the request waits in a bounded queue (503 with Retry-After
    beyond it)."""
    made = await pool.run(
        plan_answer, request, settings, wants_geojson(accept), disconnected=http.is_disconnected
    )
    http.app.state.metrics.solve.observe(made.runtime_s)
    return sent(made)
