"""The routes' days simulated: each route laid out once per candidate — its drives, its stops
and door openings, its breaks, the same on every day it is driven — and simulated on each of
its days with the sun and the temperatures of that date (:func:`core.physics.simulate.simulate`;
a date's weather is the climatology of the depot's place, :mod:`core.physics.weather`).

A day is covered when the battery keeps its reserve all day
(:class:`core.physics.battery.BatteryVerdict`: from the state of charge never clipped); with
charges allowed, also when the charge it lacks fits in them along the van's charging curve
(:func:`topped_up`). Telematics
"EV suitability" assessments (Geotab's EVSA) leave the refrigeration unit out; here it is in,
with every door opening, and the cold chain's verdict of each day.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from pydantic import ValidationError

from core.clock import departure
from core.exceptions import CoreError, InvalidParameterError, ServiceUnavailableError
from core.params import Location, Stop, VanParams, plain_rule, product_band
from core.physics.battery import JOULES_PER_KWH, BatteryVerdict
from core.physics.charging import WATTS_PER_KW, charge_curve
from core.physics.cold_chain import box_check
from core.physics.simulate import CONSUMERS, SimulationResult, simulate, with_battery
from core.physics.weather import HourlyWeather, WeatherService
from core.planning.day.scene import legs_for, round_places
from core.planning.day.timeline import Timeline, build_timeline, rest_after
from core.planning.electrification.model import (
    WEEKDAYS,
    ChargeOption,
    DrivenDay,
    DrivenRoute,
    ElectrificationProblem,
    ElectrificationResult,
    RouteOutcome,
    StudyFields,
    WeatherSourceName,
    Weekdays,
)
from core.planning.electrification.summary import (
    DayOutcome,
    DepotRecharge,
    fleet_outcome,
    route_outcome,
)
from core.planning.itinerary import Itinerary
from core.planning.model import PLAN_DT_S, PlanProblem
from core.planning.round.planner import check
from core.planning.search.day import leg_roads
from core.routing.geo import great_circle_m
from core.routing.roads import RoadRouter

#: A day as driven: its departure and its stops.
Driven = tuple[dt.time, list[Stop]]
#: A route is driven once a day: its day lasts at most this [s].
DAY_S = 86_400.0


def route_dates(route: DrivenRoute, year: int, field: str) -> list[dt.date]:
    """The dates ``route`` is driven in ``year``; a date of another year names its field."""
    return list(driven(route, year, field))


def driven(route: DrivenRoute, year: int, field: str) -> dict[dt.date, Driven]:
    """Each date ``route`` is driven in ``year``, in order, with that day's departure and
    stops (its own, or the route's); a date of another year names its field."""
    if isinstance(route.days, Weekdays):
        wanted = {WEEKDAYS.index(day) for day in route.days.weekdays}
        every = (dt.date(year, 1, 1) + dt.timedelta(days=k) for k in range(366))
        dates = [d for d in every if d.year == year and d.weekday() in wanted]
        return {d: _as_route(route) for d in dates}
    out: dict[dt.date, Driven] = {}
    days: list[dt.date | DrivenDay] = list(route.days)
    for k, day in enumerate(days):
        date = day.date if isinstance(day, DrivenDay) else day
        if date.year != year:
            raise InvalidParameterError(
                f"{date} is not in the study's year {year}",
                f"{field}[{k}].date" if isinstance(day, DrivenDay) else f"{field}[{k}]",
            )
        out[date] = (day.start_time, day.stops) if isinstance(day, DrivenDay) else _as_route(route)
    return out


def _as_route(route: DrivenRoute) -> Driven:
    assert route.start_time is not None and route.stops is not None  # DrivenRoute checks it
    return route.start_time, route.stops


def route_days(problem: StudyFields) -> int:
    """How many route-days the study simulates (each for every candidate)."""
    return sum(
        len(route_dates(r, problem.year, f"routes[{i}].days")) for i, r in enumerate(problem.routes)
    )


#: The speed a round's size is judged at before it is simulated [m/s] (50 km/h, as the
#: crow flies: a city's roads are longer and slower, so the judgement errs small).
SIZING_SPEED_MPS = 50 / 3.6


def simulated_days(problem: StudyFields) -> int:
    """What the study simulates, in days: each route-day counted once for every day (or part
    of one) it lasts — its stops' service and its legs as the crow flies at
    :data:`SIZING_SPEED_MPS` — so that a limit on it weighs a round of six
    days six times, not as one of an hour."""
    total = 0
    for i, route in enumerate(problem.routes):
        for _, stops in driven(route, problem.year, f"routes[{i}].days").values():
            lat = np.array([route.depot.lat, *(s.lat for s in stops), route.depot.lat])
            lon = np.array([route.depot.lon, *(s.lon for s in stops), route.depot.lon])
            legs_m = float(np.sum(np.diag(great_circle_m(lat, lon), 1)))
            span_s = legs_m / SIZING_SPEED_MPS + sum(stop.service_time_s for stop in stops)
            total += max(math.ceil(span_s / 86_400.0), 1)
    return total


def check_study(problem: ElectrificationProblem) -> None:
    """Everything that can be checked before simulating: unique ids, the dates in the year,
    each route a round every candidate can drive on each different day (its stops' ids, its
    payload, its start time). Raises :class:`core.exceptions.CoreError` naming the field."""
    ids = {
        "routes": [r.id for r in problem.routes],
        "candidates": [c.id for c in problem.candidates],
    }
    for name, listed in ids.items():
        seen: dict[str, int] = {}
        for k, item_id in enumerate(listed):
            if item_id in seen:
                raise InvalidParameterError(
                    f"id '{item_id}' is used twice (also by {name}[{seen[item_id]}]); ids must "
                    "be unique",
                    f"{name}[{k}].id",
                )
            seen[item_id] = k
    for i, route in enumerate(problem.routes):
        days = driven(route, problem.year, f"routes[{i}].days")
        if not days:
            raise InvalidParameterError("no day of the year is driven", f"routes[{i}].days")
        for date in _firsts(days):
            for candidate in problem.candidates:
                try:
                    check(_round(problem, route, candidate.van, date, days[date]))
                except CoreError as error:
                    if error.field == "timezone":  # the study's own
                        raise
                    said = f"with candidate '{candidate.id}': {error.message}"
                    where = _day_field(route, date, f"routes[{i}]")
                    raise type(error)(said, error.field).under(where) from None


#: A place's weather for the year: by (lat, lon), the service's hours (None: climatology).
YearWeather = dict[tuple[float, float], HourlyWeather]


@dataclass(frozen=True)
class Weather:
    """The weather a study runs on: the archive's hours of the year at each place, or none
    (each date's climatology); where it came from, and what the answer must say of it."""

    hours: YearWeather
    source: WeatherSourceName
    warnings: list[str]


def year_weather(problem: ElectrificationProblem, service: WeatherService | None) -> Weather:
    """The year's hourly archive at each place of the study (``location``, or each depot),
    fetched once, when the study asks for the archive and a service is configured; else, or
    when it fails, the climatology and a warning that says so."""
    if problem.weather_source == "climatology":
        return Weather({}, "climatology", [])
    if service is None:
        said = "no weather service is configured (COLDROUTE_WEATHER_URL)"
        return Weather({}, "climatology", [f"{said}: used each date's climatology"])
    first = dt.datetime(problem.year, 1, 1, tzinfo=dt.UTC) - dt.timedelta(days=1)
    last = dt.datetime(problem.year, 12, 31, tzinfo=dt.UTC) + dt.timedelta(days=2)
    hours: YearWeather = {}
    for place in {_place(problem, route) for route in problem.routes}:
        try:
            hours[place] = service.hourly(place[0], place[1], first, last)
        except ServiceUnavailableError as error:
            said = f"the weather archive is unavailable ({error.message})"
            return Weather({}, "climatology", [f"{said}: used each date's climatology"])
    return Weather(hours, "archive", [])


def _place(problem: ElectrificationProblem, route: DrivenRoute) -> tuple[float, float]:
    where = problem.location or route.depot
    return (where.lat, where.lon)


@dataclass(frozen=True)
class StudyPart:
    """Some of a study's routes simulated: their outcomes in order, the depot's recharge of
    each one's days, their route-days and how long they took [s]. Parts of one study merge
    into its answer (:func:`merged`) whatever process each ran in, the same figures however
    the routes were split (the recharges are added route by route, in order)."""

    first: int
    routes: list[RouteOutcome]
    depot: list[DepotRecharge]
    route_days: int
    runtime_s: float


def study(
    problem: ElectrificationProblem,
    router: RoadRouter | None = None,
    weather_service: WeatherService | None = None,
    progress: Callable[[int], None] | None = None,
) -> ElectrificationResult:
    """Simulate every route on each of its days for each candidate and sum it up per route
    and per candidate (:mod:`core.planning.electrification.summary`), on the weather
    :func:`year_weather` gives. ``progress`` is told the route-days done after each route."""
    started = time.perf_counter()
    check_study(problem)
    weather = year_weather(problem, weather_service)
    part = study_part(problem, range(len(problem.routes)), weather, router, progress)
    return merged(problem, [part], weather, time.perf_counter() - started)


def study_part(
    problem: ElectrificationProblem,
    indices: range,
    weather: Weather,
    router: RoadRouter | None = None,
    progress: Callable[[int], None] | None = None,
) -> StudyPart:
    """The routes at ``indices`` of a checked study (:func:`check_study`) simulated on
    ``weather``."""
    started = time.perf_counter()
    outcomes = []
    years: list[dict[str, list[DayOutcome]]] = []
    vans = {c.id: c.van for c in problem.candidates}
    for i in indices:
        route = problem.routes[i]
        dates = route_dates(route, problem.year, f"routes[{i}].days")
        try:
            hours = weather.hours.get(_place(problem, route))
            year = route_year(problem, route, vans, dates, router, hours)
        except CoreError as error:
            raise error.under(f"routes[{i}]") from None
        years.append(year)
        outcomes.append(route_outcome(route.id, year, problem.chargers, problem.include_days))
        if progress is not None:
            progress(len(dates))
    return StudyPart(
        first=indices.start,
        routes=outcomes,
        depot=[DepotRecharge.of(year) for year in years],
        route_days=sum(len(next(iter(year.values()))) for year in years),
        runtime_s=time.perf_counter() - started,
    )


def merged(
    problem: ElectrificationProblem,
    parts: Sequence[StudyPart],
    weather: Weather,
    runtime_s: float,
) -> ElectrificationResult:
    """The study's answer from its ``parts`` (together its routes, each once, on
    ``weather``), which took ``runtime_s`` in all [s]."""
    ordered = sorted(parts, key=lambda part: part.first)
    outcomes = [route for part in ordered for route in part.routes]
    depot = DepotRecharge({}, {})
    for part in ordered:
        for route_depot in part.depot:
            depot = depot.plus(route_depot)
    count = sum(part.route_days for part in parts)
    return ElectrificationResult(
        routes=outcomes,
        fleet=[fleet_outcome(c.id, outcomes, depot, problem.chargers) for c in problem.candidates],
        route_days=count,
        route_days_per_s=count * len(problem.candidates) / max(runtime_s, 1e-9),
        runtime_s=runtime_s,
        weather_source=weather.source,
        warnings=weather.warnings,
    )


def parts_of(problem: ElectrificationProblem, count: int) -> list[range]:
    """The routes in at most ``count`` consecutive ranges of about as many route-days each."""
    days = [
        len(route_dates(r, problem.year, f"routes[{i}].days")) for i, r in enumerate(problem.routes)
    ]
    ranges: list[range] = []
    total, first, done = sum(days), 0, 0
    for i, n in enumerate(days):
        done += n
        if done >= total * (len(ranges) + 1) / count or i == len(days) - 1:
            ranges.append(range(first, i + 1))
            first = i + 1
    return ranges


def carrying(van: VanParams, route: DrivenRoute) -> VanParams:
    """``van`` with the route's goods in its box (:attr:`DrivenRoute.product`), checked whole:
    a strategy the study gave every candidate (``refrigeration``) may need the goods; without
    them it is an error naming the route's product."""
    box = van.cargo_box
    if route.product is not None:
        band = product_band(route.product)
        inside = band.min_c <= box.setpoint_c <= band.max_c
        setpoint_c = box.setpoint_c if inside else band.middle_c
        box = box.model_copy(update={"product": route.product, "setpoint_c": setpoint_c})
    try:
        return VanParams.model_validate(van.model_dump() | {"cargo_box": box.model_dump()})
    except ValidationError as error:
        rule = plain_rule(error.errors()[0])
        raise InvalidParameterError(
            f"{rule}: give the route its product, or the candidate's box its goods", "product"
        ) from None


def _day_field(route: DrivenRoute, date: dt.date, field: str) -> str:
    """Where a day's stops and departure are in the request: the route's own, or the day's."""
    if isinstance(route.days, list):
        for k, day in enumerate(route.days):
            if isinstance(day, DrivenDay) and day.date == date:
                return f"{field}.days[{k}]"
    return field


def _firsts(days: dict[dt.date, Driven]) -> list[dt.date]:
    """The first date of each different day (its departure and stops) among ``days``."""
    seen: dict[tuple[dt.time, int], dt.date] = {}
    for date, (start_time, stops) in days.items():
        seen.setdefault((start_time, id(stops)), date)
    return list(seen.values())


def _round(
    problem: ElectrificationProblem,
    route: DrivenRoute,
    van: VanParams,
    date: dt.date,
    day: Driven,
) -> PlanProblem:
    """The route's ``day`` on ``date`` as a round driven in its order by ``van`` (with the
    route's goods)."""
    start_time, stops = day
    return PlanProblem(
        date=date,
        timezone=problem.timezone,
        depot=route.depot,
        stops=stops,
        start_time=start_time,
        keep_order=True,
        van=carrying(van, route),
    )


def route_year(
    problem: ElectrificationProblem,
    route: DrivenRoute,
    vans: dict[str, VanParams],
    dates: Sequence[dt.date],
    router: RoadRouter | None = None,
    hours: HourlyWeather | None = None,
) -> dict[str, list[DayOutcome]]:
    """The route laid out once for each kind of van among ``vans`` (by candidate id) and
    simulated on each of ``dates`` with the ``hours`` of the year (None: each date's
    climatology); vans that differ in their battery alone share the simulation
    (:func:`core.physics.simulate.with_battery`)."""
    kinds: dict[str, list[str]] = {}
    for candidate_id, van in vans.items():
        key = carrying(van, route).model_dump_json(exclude={"battery"})
        kinds.setdefault(key, []).append(candidate_id)
    out: dict[str, list[DayOutcome]] = {candidate_id: [] for candidate_id in vans}
    location = problem.location or Location(lat=route.depot.lat, lon=route.depot.lon)
    days = {date: day for date, day in driven(route, problem.year, "days").items() if date in dates}
    groups: dict[tuple[dt.time, int], list[dt.date]] = {}
    for date, (start_time, stops) in days.items():  # days driven alike are laid out once
        groups.setdefault((start_time, id(stops)), []).append(date)
    for ids, group in itertools.product(kinds.values(), groups.values()):
        first = _round(problem, route, vans[ids[0]], group[0], days[group[0]])
        timeline = _laid_out(first, router)
        if timeline.duration_s > DAY_S:  # it could not be driven again the next day
            raise InvalidParameterError(
                f"the route's day of {group[0]} lasts {timeline.duration_s / 3600:.1f} h (its "
                "drives, stops and breaks in the order given): longer than a day",
                f"{_day_field(route, group[0], '')}.stops".lstrip("."),
            )
        for date in group:
            start, _ = departure(date, first.start_time, problem.timezone, route.depot.lon)
            result = simulate(
                timeline.speed,
                PLAN_DT_S,
                start,
                location,
                first.van,
                hours,
                timeline.along(),
            )
            for candidate_id in ids:
                battery = vans[candidate_id].battery
                own = result if candidate_id == ids[0] else with_battery(result, battery)
                van = first.van.model_copy(update={"battery": battery})
                out[candidate_id].append(_day(date, van, own, problem.chargers))
    return {candidate_id: sorted(days, key=lambda d: d.date) for candidate_id, days in out.items()}


def _laid_out(problem: PlanProblem, router: RoadRouter | None) -> Timeline:
    """The route's day: its drives (the router's roads when it has them), stops, door
    openings and breaks, in the order given, from its departure."""
    start, _ = check(problem)
    places = round_places(problem)
    legs = legs_for(problem, router, places)
    order = [*range(len(places)), 0]
    roads = leg_roads(router, places, order) if router and legs.source == "osrm" else None
    rest = rest_after(problem, start)
    return build_timeline(problem, places, legs, Itinerary.of(order), roads, None, rest)


def _day(
    date: dt.date, van: VanParams, result: SimulationResult, chargers: Sequence[ChargeOption]
) -> DayOutcome:
    band, product_c = van.cargo_box.band, result.box.product_c
    holds = band is None or product_c is None or box_check(band, result.box, PLAN_DT_S).holds
    return DayOutcome(
        date=date,
        energy_kwh={
            **{name: result.energy_kwh[name] for name in CONSUMERS},
            "battery_loss": result.battery_loss_kwh,
            "total": result.energy_kwh["total"] + result.battery_loss_kwh,
        },
        battery=result.battery,
        cold_chain_holds=holds,
        t_min_c=float(result.ambient_c.min()),
        t_max_c=float(result.ambient_c.max()),
        distance_m=result.distance_m,
        duration_s=result.duration_s,
        covered_with_charging=topped_up(result.battery, van, chargers),
    )


def topped_up(battery: BatteryVerdict, van: VanParams, chargers: Sequence[ChargeOption]) -> bool:
    """Whether a day with this ``battery`` verdict is covered with ``chargers``: it keeps its
    reserve on one charge, or the charge it lacks (``-margin_kwh``) is stored within the
    charges' minutes — each along the van's charging curve at the charger's power from the
    reserve, where a day that lacks charge takes it (:func:`core.physics.charging.charge_curve`:
    capped by the charger and the van, at its efficiency, on the day's usable capacity), the
    one charge-time model the planners and their verification use too."""
    if battery.feasible:
        return True
    share = battery.usable_capacity_kwh / van.battery.usable_capacity_kwh
    stored_j = sum(
        charge_curve(van.battery, c.power_kw * WATTS_PER_KW, share).stored_j(
            van.battery.min_soc, c.minutes * 60.0
        )
        for c in chargers
    )
    return bool(chargers) and -battery.margin_kwh * JOULES_PER_KWH <= stored_j
