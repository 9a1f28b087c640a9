"""The operations that also run as jobs (``POST /v1/jobs``), one entry each: the request model,
what is checked at submission, the work (in a worker process) and its answer — exactly what the
synchronous endpoint returns."""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from pydantic import BaseModel

from app.operations import calibration, electrification, fleet_plan, plan, studies
from app.schemas.calibration import CalibrationRequest, CalibrationResponse
from app.schemas.fleet import FleetPlanRequest, FleetPlanResponse
from app.schemas.plans import PlanRequest, PlanResponse
from app.schemas.studies import (
    ElectrificationRequest,
    ElectrificationResponse,
    ScenariosRequest,
    ScenariosResponse,
    SpeedSweepRequest,
    SpeedSweepResponse,
)
from app.settings import Settings
from core.routing.tsp import prepare as prepare_search

RequestT = TypeVar("RequestT", bound=BaseModel)
ResultT = TypeVar("ResultT")


@dataclass(frozen=True)
class JobKind(Generic[RequestT, ResultT]):
    """One kind of job.

    Attributes
    ----------
    request, response
        The synchronous endpoint's request and response models.
    summary
        Which endpoint's body the request is, for the schema.
    check
        What can be refused at submission, without solving (raises a core error).
    run
        The work, in a worker process: the core's result.
    answer
        The result as the endpoint answers it.
    time_limit_s
        The solver budget the request asks for [s].
    """

    request: type[RequestT]
    response: type[BaseModel]
    summary: str
    check: Callable[[RequestT, Settings], None]
    run: Callable[[RequestT, Settings], ResultT]
    answer: Callable[[RequestT, ResultT], BaseModel]
    time_limit_s: Callable[[RequestT], float]


JOB_KINDS: dict[str, JobKind[Any, Any]] = {
    "plan": JobKind(
        PlanRequest,
        PlanResponse,
        "the body of POST /v1/plans",
        plan.check_plan,
        plan.run_plan,
        plan.answer,
        lambda request: request.time_limit_s,
    ),
    "fleet-plan": JobKind(
        FleetPlanRequest,
        FleetPlanResponse,
        "of /v1/fleet-plans",
        fleet_plan.check_fleet_plan,
        fleet_plan.run_fleet_plan,
        fleet_plan.answer,
        lambda request: request.time_limit_s,
    ),
    "scenarios": JobKind(
        ScenariosRequest,
        ScenariosResponse,
        "of /v1/studies/scenarios",
        studies.check_scenarios_job,
        studies.run_scenarios,
        lambda _request, response: response,
        lambda request: request.plan.time_limit_s,
    ),
    "speed-sweep": JobKind(
        SpeedSweepRequest,
        SpeedSweepResponse,
        "of /v1/studies/speed-sweep",
        studies.check_sweep,
        studies.sweep_speeds,
        lambda _request, response: response,
        lambda _request: 0.0,  # no solver: the sweep's simulations alone
    ),
    "electrification": JobKind(
        ElectrificationRequest,
        ElectrificationResponse,
        "of /v1/studies/electrification",
        electrification.check_electrification,
        electrification.run_electrification_job,
        lambda _request, response: response,
        lambda _request: 0.0,  # no solver: the routes' simulations alone
    ),
    "calibration": JobKind(
        CalibrationRequest,
        CalibrationResponse,
        "of /v1/calibrations",
        calibration.check_job,
        calibration.run_calibration,
        lambda _request, response: response,
        lambda _request: 0.0,  # no solver: the fit's simulations alone
    ),
}


def loaded() -> None:
    """A worker process that runs it has imported every operation and loaded the compiled
    round-trip search (a warm-up)."""
    prepare_search()


def run_job(kind: str, request: dict[str, Any], settings: Settings) -> dict[str, Any]:
    """A job's result as JSON: exactly the synchronous endpoint's answer (jobs may solve up to
    ``max_job_time_limit_s``)."""
    settings = settings.model_copy(
        update={
            "max_time_limit_s": settings.max_job_time_limit_s,
            "max_sync_simulated_s": float("inf"),  # a job may simulate as long as it must
            "max_sync_calibration_samples": sys.maxsize,
        }
    )
    job = JOB_KINDS[kind]
    validated = job.request.model_validate(request)
    return job.answer(validated, job.run(validated, settings)).model_dump(mode="json")
