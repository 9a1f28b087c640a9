"""The server's limits on a request, in one place."""

from __future__ import annotations

from typing import Any

import numpy as np

from app.settings import Settings
from core.exceptions import ServerLimitError
from core.planning.model import FleetFields, PlanFields, RoundFields
from core.routing.geo import great_circle_m

#: A replay's time: ``REPLAY_LIMIT_SHARE`` times the server's cap on time_limit_s, and
#: ``REPLAY_LIMIT_EXTRA_S`` more [s]. An answer's replay did at most the cap's work on the
#: machine that answered: this leaves room for a slower or busier one (and a small cap's
#: setup), and stops a replay whose work (replay.work_s beyond the cap, its stops emptied) no
#: answer did.
REPLAY_LIMIT_SHARE = 3.0
REPLAY_LIMIT_EXTRA_S = 10.0


def check_round(request: RoundFields, settings: Settings) -> None:
    """A round within the server's limit of stops."""
    if len(request.stops) > settings.max_stops:
        raise ServerLimitError(
            f"{len(request.stops)} stops; this server plans at most {settings.max_stops}",
            "stops",
        )


def check_fleet_size(request: FleetFields, vehicles: int, settings: Settings) -> None:
    """A fleet within the server's limits of stops and vans."""
    check_round(request, settings)
    if vehicles > settings.max_vehicles:
        raise ServerLimitError(
            f"{vehicles} vehicles; this server plans fleets of at most {settings.max_vehicles}",
            "vehicles",
        )


def search_limits(request: PlanFields | FleetFields, settings: Settings) -> dict[str, Any]:
    """A request's search within the server's cap: its time limit capped [s], its work from
    the limit the request asked for — so the same request does the same search whatever the
    server's cap, and a cap that stops it says so; a request that asks for no limit gets the
    default for its size within the cap, and the work of that. A replay, which the clock does
    not stop, gets a multiple of the cap (:data:`REPLAY_LIMIT_SHARE`)."""
    requested_s = request.time_limit_s
    if "time_limit_s" not in request.model_fields_set:  # the default fits within the cap
        requested_s = min(requested_s, settings.max_time_limit_s)
    return {
        "time_limit_s": min(requested_s, settings.max_time_limit_s),
        "work_s": request.work(requested_s),
        "replay_limit_s": REPLAY_LIMIT_SHARE * settings.max_time_limit_s + REPLAY_LIMIT_EXTRA_S,
    }


def far_stops(request: RoundFields, settings: Settings) -> list[str]:
    """A warning for each stop farther from the depot than the server's ``far_stop_km``."""
    places = [request.depot, *request.stops]
    lat = np.array([p.lat for p in places], dtype=float)
    lon = np.array([p.lon for p in places], dtype=float)
    away_km = great_circle_m(lat, lon)[0, 1:] / 1000.0
    return [
        f"stops[{k}] ('{stop.id}') is {away_km[k]:,.0f} km from the depot (more than "
        f"{settings.far_stop_km:g} km): check its coordinates (lat and lon swapped?)"
        for k, stop in enumerate(request.stops)
        if away_km[k] > settings.far_stop_km
    ]
