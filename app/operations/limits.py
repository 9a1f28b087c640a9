"""The server's limits on a request, in one place."""

from __future__ import annotations

from app.settings import Settings
from core.exceptions import LimitExceededError
from core.planning.model import RoundFields


def check_round(request: RoundFields, settings: Settings) -> None:
    """A round within the server's limit of stops."""
    if len(request.stops) > settings.max_stops:
        raise LimitExceededError(
            f"{len(request.stops)} stops; this server plans at most {settings.max_stops}",
            "stops",
        )


def time_limit_s(requested_s: float, settings: Settings) -> float:
    """A request's solver budget within the server's cap [s]."""
    return min(requested_s, settings.max_time_limit_s)
