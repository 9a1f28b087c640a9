"""/v1/jobs: a job's submission, state and answer."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal, Union

from pydantic import AwareDatetime, BaseModel, Field

from app.jobs.models import STATUSES, JobStatus
from app.operations.kinds import JOB_KINDS
from app.schemas.base import ApiModel, Problem

if TYPE_CHECKING:  # built at run time from the registry of job kinds
    JobType = str
    JobResult = BaseModel
else:
    JobType = Literal[tuple(JOB_KINDS)]
    JobResult = Union[tuple(kind.response for kind in JOB_KINDS.values())]  # noqa: UP007


class JobSubmission(ApiModel):
    """A job: the type and the body the synchronous endpoint would take."""

    type: JobType = Field(
        ...,
        description="; ".join(f"{name}: {kind.summary}" for name, kind in JOB_KINDS.items()) + ".",
    )
    request: dict[str, Any] = Field(
        ...,
        description="The request, exactly as for the synchronous endpoint; validated before "
        "the job is accepted (422 naming request.… otherwise).",
        json_schema_extra={
            "oneOf": [
                {"$ref": f"#/components/schemas/{kind.request.__name__}"}
                for kind in JOB_KINDS.values()
            ]
        },
    )


class JobProgress(ApiModel):
    """How far a job run in parts is (an electrification study: its route-days × candidates,
    cut into parts shared out over the workers)."""

    done: int = Field(..., description="Work done: the parts finished, by their weight.")
    total: int = Field(..., description="Work in all (electrification: route-days × candidates).")
    parts_done: int = Field(..., description="Parts finished (each is kept when a worker is lost).")
    parts_total: int = Field(..., description="Parts in all.")


class JobSummary(ApiModel):
    """A job's state."""

    id: str = Field(..., description="The job's identifier (a UUID).")
    type: JobType = Field(..., description=f"{', '.join(JOB_KINDS)}.")
    status: JobStatus = Field(..., description=f"{', '.join(STATUSES)}.")
    created_at: AwareDatetime = Field(..., strict=False, description="When it was accepted (UTC).")
    started_at: AwareDatetime | None = Field(
        None, strict=False, description="When its last run began (UTC)."
    )
    finished_at: AwareDatetime | None = Field(
        None, strict=False, description="When it ended (UTC)."
    )
    attempts: int = Field(..., description="Runs so far (a lost worker means another run).")
    progress: JobProgress | None = Field(
        None,
        description="A job run in parts, once its runner has cut it up: how far it is. Null "
        "for the others.",
    )


class JobOut(JobSummary):
    """A job, with its answer once it has one."""

    result: JobResult | None = Field(
        None,
        description="When succeeded: exactly what the synchronous endpoint returns.",
    )
    error: Problem | None = Field(None, description="When failed: why, as a problem document.")
    request: dict[str, Any] | None = Field(
        None, description="The request as it was submitted (GET with include_request=true)."
    )


class JobList(ApiModel):
    """Jobs, newest first."""

    jobs: list[JobSummary] = Field(
        ..., description="The jobs, newest first, without their results."
    )
