"""``POST /v1/studies/electrification`` and jobs of type ``electrification``: the fleet's
routes over a year, for each candidate van (:mod:`core.planning.electrification`)."""

from __future__ import annotations

import dataclasses
import datetime as dt
import math
import time
from typing import Any

import numpy as np

from app import connectors
from app.operations.vans import van_of
from app.schemas.studies import ElectrificationRequest, ElectrificationResponse
from app.settings import Settings
from core.exceptions import (
    CoreError,
    InvalidParameterError,
    ServerLimitError,
    TooMuchToWaitForError,
)
from core.physics.weather import HourlyWeather
from core.planning.electrification.model import (
    Candidate,
    ElectrificationProblem,
    RouteOutcome,
    StudyFields,
)
from core.planning.electrification.study import (
    StudyPart,
    Weather,
    check_study,
    merged,
    parts_of,
    route_dates,
    simulated_days,
    study_part,
    year_weather,
)
from core.planning.electrification.summary import DepotRecharge
from core.planning.model import fields_of


def electrification_problem(
    request: ElectrificationRequest, settings: Settings, job: bool = False
) -> ElectrificationProblem:
    """The core study of a request, within the server's limits on route-days (a job's, or a
    synchronous answer's: a 413 pointing to jobs); a candidate's own errors name it."""
    candidates = []
    for index, candidate in enumerate(request.candidates):
        # a strategy (the candidate's own, or the study's) is set on the van as it is, for
        # the goods come from each route: the van is checked whole with them (carrying)
        own = "refrigeration" in candidate.model_fields_set
        strategy = candidate.refrigeration if own else request.refrigeration
        try:
            van = van_of(candidate.model_copy(update={"refrigeration": None}), settings)
        except CoreError as error:
            raise error.under(f"candidates[{index}]") from None
        if strategy is not None:
            van = van.model_copy(update={"refrigeration": strategy})
            bare = next((i for i, r in enumerate(request.routes) if r.product is None), None)
            if (
                strategy.strategy == "optimal"
                and van.cargo_box.product is None
                and bare is not None
            ):
                raise InvalidParameterError(
                    "strategy 'optimal' keeps goods in their band, and there are none to keep: "
                    f"routes[{bare}] has no product and candidates[{index}]'s cargo_box none; "
                    "give the route its product, or the candidate's box its goods",
                    f"candidates[{index}].refrigeration" if own else "refrigeration",
                )
        candidates.append(Candidate(id=candidate.id, van=van))
    problem = ElectrificationProblem(
        **fields_of(request, StudyFields),
        candidates=candidates,
        weather_source=request.weather.source,
    )
    simulated = simulated_days(problem) * len(candidates)
    said = f"{simulated:,} route-days × candidates (a round counted once for each day it lasts)"
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


#: Route-days × candidates a worker simulates per second at the least (the optimal
#: refrigeration strategy runs about 70 on this project's 2-core test machine): a job's time.
SLOWEST_ROUTE_DAYS_PER_S = 20.0
#: A study's plan: what its parts share (the year's weather) and each part (its routes, as
#: ``[first, stop)``) with its weight (route-days × candidates).
Plan = tuple[dict[str, Any], list[tuple[list[int], int]]]


def plan_study(
    request: ElectrificationRequest, settings: Settings, parts: int | None = None, job: bool = True
) -> Plan:
    """The study checked and cut into ``parts`` (by default, of about
    ``job_part_route_days`` each) of consecutive routes with about as many route-days each,
    and the year's weather all parts run on (fetched once)."""
    problem = electrification_problem(request, settings, job)
    check_study(problem)
    weather = year_weather(problem, connectors.weather_service(settings))
    per_route = [
        len(route_dates(r, problem.year, f"routes[{i}].days")) for i, r in enumerate(problem.routes)
    ]
    candidates = len(problem.candidates)
    if parts is None:
        parts = math.ceil(sum(per_route) * candidates / settings.job_part_route_days)
    ranges = parts_of(problem, max(parts, 1))
    return weather_json(weather), [
        ([r.start, r.stop], sum(per_route[r.start : r.stop]) * candidates) for r in ranges
    ]


def run_study_part(
    request: ElectrificationRequest, settings: Settings, context: dict[str, Any], spec: list[int]
) -> dict[str, Any]:
    """The routes ``[first, stop)`` of ``spec`` simulated on the plan's weather, as JSON."""
    problem = electrification_problem(request, settings, job=True)
    part = study_part(problem, range(*spec), weather_of(context), connectors.router(settings))
    return part_json(part)


def merged_answer(
    request: ElectrificationRequest,
    settings: Settings,
    context: dict[str, Any],
    parts: list[dict[str, Any]],
    runtime_s: float,
) -> ElectrificationResponse:
    """The answer of the parts (JSON), the same whatever the split."""
    problem = electrification_problem(request, settings, job=True)
    done = [part_of(part) for part in parts]
    result = merged(problem, done, weather_of(context), runtime_s)
    return ElectrificationResponse(**dict(result))


def run_study(request: ElectrificationRequest, settings: Settings) -> ElectrificationResponse:
    """The whole (synchronous-sized) study in this process, in one part."""
    started = time.perf_counter()
    context, parts = plan_study(request, settings, parts=1, job=False)
    done = [run_study_part(request, settings, context, spec) for spec, _ in parts]
    return merged_answer(request, settings, context, done, time.perf_counter() - started)


def time_limit_s(request: ElectrificationRequest) -> float:
    """The longest a study as a job may run beyond its fixed allowance [s]: its
    simulations at the slowest pace a worker keeps (the optimal refrigeration strategy)."""
    return simulated_days(request) * len(request.candidates) / SLOWEST_ROUTE_DAYS_PER_S


def weather_json(weather: Weather) -> dict[str, Any]:
    """The study's weather as JSON (exact: floats round-trip)."""
    return {
        "source": weather.source,
        "warnings": weather.warnings,
        "hours": [
            {"lat": lat, "lon": lon, **_arrays_json(hours)}
            for (lat, lon), hours in weather.hours.items()
        ],
    }


def weather_of(data: dict[str, Any]) -> Weather:
    """:func:`weather_json` read back."""
    hours = {}
    for place in data["hours"]:
        arrays: dict[str, Any] = {
            name: np.asarray(value, dtype=float) if isinstance(value, list) else value
            for name, value in place.items()
            if name not in ("lat", "lon")
        }
        hours[(place["lat"], place["lon"])] = HourlyWeather(**arrays)
    return Weather(hours, data["source"], list(data["warnings"]))


def _arrays_json(hours: HourlyWeather) -> dict[str, Any]:
    return {
        field.name: value.tolist() if isinstance(value, np.ndarray) else value
        for field in dataclasses.fields(hours)
        for value in [getattr(hours, field.name)]
    }


def part_json(part: StudyPart) -> dict[str, Any]:
    """A part of a study as JSON (exact: floats round-trip)."""

    def by_date(values: dict[str, dict[dt.date, float]]) -> dict[str, dict[str, float]]:
        return {c: {d.isoformat(): v for d, v in dates.items()} for c, dates in values.items()}

    return {
        "first": part.first,
        "routes": [route.model_dump(mode="json") for route in part.routes],
        "depot": [{"kwh": by_date(d.kwh), "kw": by_date(d.kw)} for d in part.depot],
        "route_days": part.route_days,
        "runtime_s": part.runtime_s,
    }


def part_of(data: dict[str, Any]) -> StudyPart:
    """:func:`part_json` read back."""

    def by_date(values: dict[str, dict[str, float]]) -> dict[str, dict[dt.date, float]]:
        return {
            c: {dt.date.fromisoformat(d): v for d, v in dates.items()}
            for c, dates in values.items()
        }

    return StudyPart(
        first=data["first"],
        routes=[RouteOutcome.model_validate(route) for route in data["routes"]],
        depot=[DepotRecharge(by_date(d["kwh"]), by_date(d["kw"])) for d in data["depot"]],
        route_days=data["route_days"],
        runtime_s=data["runtime_s"],
    )
