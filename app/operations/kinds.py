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
class Fanout(Generic[RequestT]):
    """How a job is run in parts shared out over the workers (:mod:`app.jobs.fanout`).

    Attributes
    ----------
    plan
        The request checked and cut up (in a worker): what every part needs (JSON) and each
        part's spec (JSON) with its weight (the work it stands for, e.g. route-days).
    run_part
        One part's work (in a worker): its result as JSON.
    merge
        The answer of every part's result, in their order, and the time it took [s]: the same
        however the work was cut up.
    """

    plan: Callable[[RequestT, Settings], tuple[dict[str, Any], list[tuple[Any, int]]]]
    run_part: Callable[[RequestT, Settings, dict[str, Any], Any], dict[str, Any]]
    merge: Callable[[RequestT, Settings, dict[str, Any], list[dict[str, Any]], float], BaseModel]


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
        The work, in a worker process: the core's result (None: run in parts, ``fanout``).
    answer
        The result as the endpoint answers it.
    time_limit_s
        The solver budget the request asks for [s].
    fanout
        How the job runs in parts over the workers, if it does.
    """

    request: type[RequestT]
    response: type[BaseModel]
    summary: str
    check: Callable[[RequestT, Settings], None]
    run: Callable[[RequestT, Settings], ResultT] | None
    answer: Callable[[RequestT, ResultT], BaseModel]
    time_limit_s: Callable[[RequestT], float]
    fanout: Fanout[RequestT] | None = None


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
        None,
        lambda _request, response: response,
        electrification.time_limit_s,  # no solver: the routes' simulations alone
        Fanout(
            electrification.plan_study,
            electrification.run_study_part,
            electrification.merged_answer,
        ),
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
    job, validated = _job(kind, request)
    assert job.run is not None, f"{kind} jobs run in parts"
    return job.answer(validated, job.run(validated, job_settings(settings))).model_dump(mode="json")


def plan_parts(
    kind: str, request: dict[str, Any], settings: Settings
) -> tuple[dict[str, Any], list[tuple[Any, int]]]:
    """A job run in parts, checked and cut up (:attr:`Fanout.plan`)."""
    fanout, validated = _fanout(kind, request)
    return fanout.plan(validated, job_settings(settings))


def run_part(
    kind: str, request: dict[str, Any], settings: Settings, context: dict[str, Any], spec: Any
) -> dict[str, Any]:
    """One part's result as JSON (:attr:`Fanout.run_part`)."""
    fanout, validated = _fanout(kind, request)
    return fanout.run_part(validated, job_settings(settings), context, spec)


def merge_parts(
    kind: str,
    request: dict[str, Any],
    settings: Settings,
    context: dict[str, Any],
    results: list[dict[str, Any]],
    runtime_s: float,
) -> dict[str, Any]:
    """The job's result as JSON from its parts' (:attr:`Fanout.merge`)."""
    fanout, validated = _fanout(kind, request)
    answer = fanout.merge(validated, job_settings(settings), context, results, runtime_s)
    return answer.model_dump(mode="json")


def job_settings(settings: Settings) -> Settings:
    """The settings a job runs with: it may solve up to ``max_job_time_limit_s`` and simulate
    as long as it must."""
    return settings.model_copy(
        update={
            "max_time_limit_s": settings.max_job_time_limit_s,
            "max_sync_simulated_s": float("inf"),
            "max_sync_calibration_samples": sys.maxsize,
        }
    )


def _job(kind: str, request: dict[str, Any]) -> tuple[JobKind[Any, Any], BaseModel]:
    job = JOB_KINDS[kind]
    return job, job.request.model_validate(request)


def _fanout(kind: str, request: dict[str, Any]) -> tuple[Fanout[Any], BaseModel]:
    job, validated = _job(kind, request)
    assert job.fanout is not None, f"{kind} jobs do not run in parts"
    return job.fanout, validated
