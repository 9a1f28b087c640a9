"""``POST /v1/studies/electrification`` and jobs of type ``electrification``: the fleet's
routes over a year, for each candidate van (:mod:`core.planning.electrification`)."""

from __future__ import annotations

from app import connectors
from app.operations.vans import van_of
from app.schemas.studies import ElectrificationRequest, ElectrificationResponse
from app.settings import Settings
from core.exceptions import CoreError, ServerLimitError, TooMuchToWaitForError
from core.planning.electrification.model import Candidate, ElectrificationProblem, StudyFields
from core.planning.electrification.study import (
    StudyPart,
    Weather,
    check_study,
    merged,
    parts_of,
    route_days,
    study,
    study_part,
    year_weather,
)
from core.planning.model import fields_of


def electrification_problem(
    request: ElectrificationRequest, settings: Settings, job: bool = False
) -> ElectrificationProblem:
    """The core study of a request, within the server's limits on route-days (a job's, or a
    synchronous answer's: a 413 pointing to jobs); a candidate's own errors name it."""
    candidates = []
    for index, candidate in enumerate(request.candidates):
        try:
            van = van_of(candidate, settings)
        except CoreError as error:
            raise error.under(f"candidates[{index}]") from None
        if request.refrigeration is not None and "refrigeration" not in candidate.model_fields_set:
            van = van.model_copy(update={"refrigeration": request.refrigeration})
        candidates.append(Candidate(id=candidate.id, van=van))
    problem = ElectrificationProblem(
        **fields_of(request, StudyFields),
        candidates=candidates,
        weather_source=request.weather.source,
    )
    simulated = route_days(problem) * len(candidates)
    said = f"{simulated:,} route-days × candidates"
    if simulated > settings.max_route_days:
        raise ServerLimitError(
            f"{said}; this server simulates at most {settings.max_route_days:,} per study "
            "(COLDROUTE_MAX_ROUTE_DAYS): fewer routes, days or candidates",
            "routes",
        )
    if not job and simulated > settings.max_sync_route_days:
        raise TooMuchToWaitForError(
            f"{said}; a synchronous study simulates at most {settings.max_sync_route_days:,}: "
            "submit it as a job (POST /v1/jobs, type electrification)",
            "routes",
        )
    return problem


def check_electrification(request: ElectrificationRequest, settings: Settings) -> None:
    """Everything but the simulations: what a job refuses at submission."""
    check_study(electrification_problem(request, settings, job=True))


def run_electrification(
    request: ElectrificationRequest, settings: Settings, job: bool = False
) -> ElectrificationResponse:
    """The study, with the configured road router and weather service."""
    result = study(
        electrification_problem(request, settings, job),
        connectors.router(settings),
        connectors.weather_service(settings),
    )
    return ElectrificationResponse(**dict(result))


def run_electrification_job(
    request: ElectrificationRequest, settings: Settings
) -> ElectrificationResponse:
    """The study as a job: a job's limit on route-days."""
    return run_electrification(request, settings, job=True)


def study_parts(request: ElectrificationRequest, settings: Settings) -> tuple[list[range], Weather]:
    """The synchronous study checked, split into a part per worker (routes of about as many
    route-days each), and the weather all parts run on (fetched once)."""
    problem = electrification_problem(request, settings)
    check_study(problem)
    weather = year_weather(problem, connectors.weather_service(settings))
    return parts_of(problem, settings.workers), weather


def run_study_part(
    request: ElectrificationRequest, settings: Settings, indices: range, weather: Weather
) -> StudyPart:
    """The routes at ``indices`` simulated, in a worker."""
    problem = electrification_problem(request, settings)
    return study_part(problem, indices, weather, connectors.router(settings))


def merged_answer(
    request: ElectrificationRequest,
    settings: Settings,
    parts: list[StudyPart],
    weather: Weather,
    runtime_s: float,
) -> ElectrificationResponse:
    """The answer of the parts, the same whatever the split."""
    result = merged(electrification_problem(request, settings), parts, weather, runtime_s)
    return ElectrificationResponse(**dict(result))
