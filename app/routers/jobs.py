"""POST/GET/DELETE /v1/jobs: rounds too big to wait on, and batch planning."""

from __future__ import annotations

import asyncio
import dataclasses
from typing import Annotated, Any

from fastapi import APIRouter, Body, Header, Path, Query, Request, Response
from fastapi.exceptions import RequestValidationError
from pydantic import BaseModel, ValidationError
from starlette.exceptions import HTTPException

from app.deps import SettingsDep, StoreDep
from app.examples import PLAN_EXAMPLE
from app.jobs.models import FINISHED, JobStatus
from app.jobs.schemas import JobList, JobOut, JobSubmission, JobSummary
from app.jobs.store import IdempotencyConflictError, JobStore, JobView, Progress
from app.operations.kinds import JOB_KINDS
from app.settings import Settings
from core.exceptions import CoreError

router = APIRouter(prefix="/jobs", tags=["jobs"])
#: Visible ASCII, no whitespace at either end.
IDEMPOTENCY_KEY_PATTERN = r"^[!-~]([ -~]*[!-~])?$"


def _validated(submission: JobSubmission, settings: Settings) -> BaseModel:
    """The job's request as the synchronous endpoint would validate and check it, every field
    named under ``request.``."""
    kind = JOB_KINDS[submission.type]
    try:
        request: BaseModel = kind.request.model_validate(submission.request)
    except ValidationError as error:
        raise RequestValidationError(
            [e | {"loc": ("body", "request", *e["loc"])} for e in error.errors()],
            body={"request": submission.request},
        ) from None
    try:
        kind.check(request, settings)
    except CoreError as error:
        raise error.under("request") from None
    return request


def _summary(job: JobView, progress: Progress | None = None) -> dict[str, Any]:
    return {
        "id": job.id,
        "type": job.type,
        "status": job.status,
        "created_at": job.created_at,
        "started_at": job.started_at,
        "finished_at": job.finished_at,
        "attempts": job.attempts,
        "progress": None if progress is None else dataclasses.asdict(progress),
    }


def _out(job: JobView, progress: Progress | None = None) -> JobOut:
    # The stored result is JSON (times as text): read it back as JSON is read, not strictly.
    return JobOut.model_validate(
        _summary(job, progress) | {"result": job.result, "error": job.error}, strict=False
    )


def _get(store: JobStore, job_id: str) -> tuple[JobView, Progress | None]:
    job = store.get(job_id)
    if job is None:
        raise HTTPException(404, f"no job {job_id}")
    return job, store.progress([job_id]).get(job_id)


@router.post(
    "",
    operation_id="createJob",
    summary="Submit a plan or a scenario study to run in the background",
    status_code=202,
    responses={
        200: {"model": JobOut, "description": "The job an Idempotency-Key already named."},
        202: {"description": "Accepted; poll Location."},
        409: {"description": "The Idempotency-Key names a job with another request."},
    },
)
async def create_job(
    submission: Annotated[
        JobSubmission,
        Body(
            openapi_examples={
                "plan": {
                    "summary": "The Vienna round as a job",
                    "value": {"type": "plan", "request": PLAN_EXAMPLE},
                }
            }
        ),
    ],
    http: Request,
    response: Response,
    settings: SettingsDep,
    store: StoreDep,
    idempotency_key: Annotated[
        str | None,
        Header(
            min_length=1,
            max_length=255,
            pattern=IDEMPOTENCY_KEY_PATTERN,
            description="Repeat a submission safely: the same key returns the same job. 1–255 "
            "visible ASCII characters (inner spaces allowed); an empty key would be one that "
            "every such client shares.",
        ),
    ] = None,
) -> JobOut:
    """Validates the request as the synchronous endpoint would (422 naming the field), stores
    the job and answers at once with its id; `GET /v1/jobs/{id}` tells its state and, when it
    has succeeded, its result — exactly what the synchronous endpoint returns."""
    request = _validated(submission, settings)
    kind = JOB_KINDS[submission.type]
    time_limit_s = kind.time_limit_s(request)
    if kind.fanout is None:  # a solver's budget is capped; a study's is its work (route-days)
        time_limit_s = min(time_limit_s, settings.max_job_time_limit_s)
    try:
        job, new = await asyncio.to_thread(
            store.create,
            submission.type,
            request.model_dump(mode="json", exclude_unset=True),
            time_limit_s,
            idempotency_key,
        )
    except IdempotencyConflictError as conflict:
        raise HTTPException(
            409,
            f"Idempotency-Key {idempotency_key!r} already names job {conflict.job.id}, which "
            "was submitted with a different request",
        ) from None
    runner = getattr(http.app.state, "runner", None)
    if new and runner is not None:
        await runner.submitted(job)
    response.status_code = 202 if new else 200
    response.headers["Location"] = f"/v1/jobs/{job.id}"
    return _out(job)


@router.get("", operation_id="listJobs", summary="Jobs, newest first")
async def list_jobs(
    store: StoreDep,
    status: Annotated[JobStatus | None, Query(description="Only jobs in this state.")] = None,
    limit: Annotated[int, Query(ge=1, le=500, description="At most this many.")] = 50,
) -> JobList:
    """The newest jobs first, without their results."""
    jobs = await asyncio.to_thread(store.recent, status, limit)
    progress = await asyncio.to_thread(store.progress, [job.id for job in jobs])
    return JobList(
        jobs=[JobSummary.model_validate(_summary(job, progress.get(job.id))) for job in jobs]
    )


JobId = Annotated[str, Path(max_length=64, description="The job's id.")]


@router.get(
    "/{job_id}",
    operation_id="getJob",
    summary="A job's state and result",
    responses={404: {"description": "No such job (or it expired)."}},
)
async def get_job(
    job_id: JobId,
    store: StoreDep,
    include_request: Annotated[
        bool, Query(description="Also return the request as it was submitted.")
    ] = False,
) -> JobOut:
    """Its status and timestamps; its result when it succeeded, its error when it failed; with
    `include_request`, what was submitted (the plan viewer reopens a job's plan with it)."""
    job, progress = await asyncio.to_thread(_get, store, job_id)
    out = _out(job, progress)
    return out.model_copy(update={"request": job.request}) if include_request else out


@router.delete(
    "/{job_id}",
    operation_id="cancelJob",
    summary="Cancel a job",
    responses={
        404: {"description": "No such job (or it expired)."},
        409: {"description": "The job has already ended."},
    },
)
async def cancel_job(job_id: JobId, store: StoreDep) -> JobOut:
    """A queued job never runs; a running one is stopped (its worker process is terminated).
    A job that has already ended cannot be cancelled (409)."""
    before, _ = await asyncio.to_thread(_get, store, job_id)
    if before.status in FINISHED:
        raise HTTPException(409, f"job {job_id} has already ended ({before.status})")
    job = await asyncio.to_thread(store.cancel, job_id)
    if job is None:  # deleted meanwhile (its retention ran out)
        raise HTTPException(404, f"no job {job_id}")
    # The runner watching it stops its worker processes within a heartbeat.
    return _out(job, await asyncio.to_thread(lambda: store.progress([job_id]).get(job_id)))
