"""What every simulation of one day shares — the places, their legs, the zone and the weather
(:class:`Scene`) — and where the legs come from (:func:`legs_for`)."""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable
from dataclasses import dataclass

from core.exceptions import InvalidStopsError, OffRoadError
from core.params import Place
from core.physics.weather import Forecast, WeatherService, forecast_for
from core.planning.model import RoundFields
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


def legs_for(
    problem: RoundFields, router: RoadRouter | None, places: list[Place] | None = None
) -> Legs:
    """Every ordered pair's leg between ``places`` (by default the depot and the stops): the
    client's matrix, else the router's table, else the estimate."""
    places = problem.places if places is None else places
    try:
        table = router.table(places) if router is not None and problem.matrix is None else None
    except OffRoadError as error:
        if error.place is None or error.place <= len(problem.stops):
            raise
        raise InvalidStopsError(error.message, "start_state") from None  # the van's position
    return build_legs(places, problem.matrix, table)


def weather_service_for(problem: RoundFields, service: WeatherService | None) -> WeatherFor:
    """The weather of each simulated span: the request's own, else the service's forecast at
    the depot, else the climatology (with a warning when the service failed)."""

    def weather_for(begin: dt.datetime, span_s: float) -> tuple[Forecast | None, list[str]]:
        return forecast_for(
            problem.weather, service, problem.depot.lat, problem.depot.lon, begin, span_s
        )

    return weather_for
