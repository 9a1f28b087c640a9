"""What every simulation of one day shares — the places, their legs, the zone and the weather
(:class:`Scene`) — which places a round has (:func:`round_places`) and where their legs come
from (:func:`legs_for`)."""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from core.exceptions import InvalidStopsError, OffRoadError
from core.params import ChargePoint, Place
from core.physics.weather import Forecast, WeatherService, forecast_for
from core.planning.model import START_ID, PlanProblem, RoundFields
from core.routing.geo import Legs, build_legs
from core.routing.roads import RoadRouter

#: The weather to simulate a span with: ``(start, span_s) -> (forecast or None, warnings)``.
WeatherFor = Callable[[dt.datetime, float], tuple[Forecast | None, list[str]]]


@dataclass(frozen=True)
class Scene:
    """The places (the depot, then the stops), every ordered pair's leg, the zone's name for
    the answers, the weather of a day, and what every answer of it should warn of."""

    places: list[Place]
    legs: Legs
    timezone_name: str
    weather_for: WeatherFor
    notes: tuple[str, ...] = ()


def round_places(problem: PlanProblem) -> list[Place]:
    """The places of a round by index: the depot (0), the stops, the van's position when the
    day starts under way, then the chargers on the way."""
    state = problem.start_state
    start = [] if state is None else [Place(id=START_ID, lat=state.lat, lon=state.lon)]
    return [*problem.places, *start, *problem.chargers]


def charge_points(problem: PlanProblem, places: Sequence[Place]) -> dict[int, ChargePoint]:
    """Where a round may charge, by index of ``places`` (a round's, :func:`round_places`, or
    a fleet's; the chargers on the way last): the depot's charger and the chargers on the
    way."""
    first = len(places) - len(problem.chargers)
    points: dict[int, ChargePoint] = {first + k: c for k, c in enumerate(problem.chargers)}
    if problem.depot.charger is not None:
        points[0] = problem.depot.charger
    return points


def round_field(
    problem: RoundFields,
    places: list[Place],
    index: int,
    start_fields: Sequence[str] = ("start_state",),
) -> str:
    """The request field of place ``index`` of ``places`` (the depot, a stop, a van's
    position — ``start_fields`` name them in order — or a charger on the way)."""
    if index == 0:
        return "depot"
    if index <= len(problem.stops):
        return f"stops[{index - 1}]"
    first_charger = len(places) - len(problem.chargers)
    if index < first_charger:
        return start_fields[index - len(problem.stops) - 1]
    return f"chargers[{index - first_charger}]"


def legs_for(
    problem: RoundFields,
    router: RoadRouter | None,
    places: list[Place] | None = None,
    start_fields: Sequence[str] = ("start_state",),
) -> Legs:
    """Every ordered pair's leg between ``places`` (by default the depot and the stops): the
    client's matrix, else the router's table, else the estimate. A place off the road is an
    error naming its field (:func:`round_field`)."""
    places = problem.places if places is None else places
    try:
        table = router.table(places) if router is not None and problem.matrix is None else None
    except OffRoadError as error:
        if error.place is None or error.place <= len(problem.stops):
            raise
        raise InvalidStopsError(
            error.message, round_field(problem, places, error.place, start_fields)
        ) from None
    return build_legs(places, problem.matrix, table)


def weather_service_for(problem: RoundFields, service: WeatherService | None) -> WeatherFor:
    """The weather of each simulated span: the request's own, else the service's forecast at
    the depot, else the climatology (with a warning when the service failed)."""

    def weather_for(begin: dt.datetime, span_s: float) -> tuple[Forecast | None, list[str]]:
        return forecast_for(
            problem.weather, service, problem.depot.lat, problem.depot.lon, begin, span_s
        )

    return weather_for
