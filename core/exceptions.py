"""Exceptions raised by the core, with messages a dispatcher understands.

Every exception names the offending field (``field``, a dotted path) and the rule it broke, so
that the web layer can turn it into a 4xx problem response without guessing.
"""

from __future__ import annotations

from typing import Any


class CoreError(ValueError):
    """Base class of every error the core raises on bad input.

    Parameters
    ----------
    message
        Human-readable explanation naming the field and the rule.
    field
        Dotted path of the offending field (``"stops[3].lat"``), or ``None`` for a whole request.
    details
        Every offending field and its rule, when there are several; by default the one.
    """

    def __init__(
        self,
        message: str,
        field: str | None = None,
        details: list[tuple[str, str]] | None = None,
    ) -> None:
        super().__init__(message)
        self.message = message
        self.field = field
        self.details = details if details is not None else [(field or "body", message)]

    def under(self, prefix: str) -> CoreError:
        """The same error with every field it names under ``prefix``: ``stops[1].lat`` under
        ``request`` is ``request.stops[1].lat``; an error of the whole body names ``prefix``."""

        def scoped(field: str | None) -> str:
            if field in (None, "", "body"):
                return prefix
            return f"{prefix}{field}" if field.startswith("[") else f"{prefix}.{field}"

        return type(self)(
            self.message, scoped(self.field), [(scoped(f), rule) for f, rule in self.details]
        )

    def at(self, field: str) -> CoreError:
        """The same error naming ``field`` instead of its own (a rule of one field that the
        caller knows by another name)."""
        return type(self)(self.message, field, [(field, rule) for _, rule in self.details])

    def __reduce__(
        self,
    ) -> tuple[type[CoreError], tuple[str, str | None, list[tuple[str, str]]]]:
        # Errors cross process boundaries (worker pool, job queue) with their fields.
        return type(self), (self.message, self.field, self.details)


class InvalidParameterError(CoreError):
    """A parameter or input array breaks its documented rule (sign, range, finiteness...)."""


class InvalidMatrixError(CoreError):
    """A client-supplied distance or duration matrix is mis-sized or holds a bad entry."""


class InvalidStopsError(CoreError):
    """The stops of a round are empty, duplicated or otherwise unusable."""


class NoRouteError(InvalidStopsError):
    """A road router finds no road between two places."""


class OffRoadError(InvalidStopsError):
    """A place lies farther from any road than a router accepts; ``place`` is its index in
    the places the router was given (0 the depot, then the stops), for the planner to name
    a place beyond the stops (:func:`off_road`)."""

    place: int | None = None

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        return _off_road_at, (self.message, self.field, self.details, self.place)


def off_road(message: str, place: int) -> OffRoadError:
    """The error of place ``place`` (by index) off the road, naming the depot or its stop."""
    return _off_road_at(message, "depot" if place == 0 else f"stops[{place - 1}]", None, place)


def _off_road_at(
    message: str, field: str | None, details: list[tuple[str, str]] | None, place: int | None
) -> OffRoadError:
    error = OffRoadError(message, field, details)
    error.place = place
    return error


class LimitExceededError(CoreError):
    """An input is larger than the configured limit (stops, samples...)."""


class ServerLimitError(LimitExceededError):
    """A request larger than the server is configured to plan (its stops, its vans): the size,
    not the content, is refused."""


class TooMuchToWaitForError(LimitExceededError):
    """A request that is valid but implies more work than a synchronous answer may take (the
    simulated time of a study): it can run as a job."""


class ServiceUnavailableError(Exception):
    """An outside service (road router, weather service) is down, too slow or answered
    garbage. Not the client's fault: the web layer answers 503 naming ``service``.

    Parameters
    ----------
    service
        Which service (``"osrm"``, ``"weather"``).
    message
        What went wrong, for the operator.
    """

    def __init__(self, service: str, message: str) -> None:
        super().__init__(message)
        self.service = service
        self.message = message

    def __reduce__(self) -> tuple[type[ServiceUnavailableError], tuple[str, str]]:
        return type(self), (self.service, self.message)
