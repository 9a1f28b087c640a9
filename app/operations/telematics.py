"""A telematics export — one CSV row per stop visited — as the days of an electrification
study's routes (``POST /v1/studies/electrification/from-csv``).

Each day of a route is its rows, together and in the order driven: first the departure from
the route's depot (a row whose ``stop_id`` is the depot's id: its ``departure`` is the day's
start), then one row per stop (``arrival`` and ``departure`` give its service time), and, if
the export has it, the return to the depot (its ``arrival``). Columns: ``route_id``, ``date``
(YYYY-MM-DD), ``stop_id``, ``lat``, ``lon``, ``arrival``, ``departure`` (local HH:MM or
HH:MM:SS, within the day), and optionally ``delivery_kg`` and ``door_minutes`` (default: the
stop's service, at most a minute). A bad cell is a 422 naming ``history[<line>].<column>``,
the line of the file (its header is line 1).
"""

from __future__ import annotations

import csv
import datetime as dt
import re
from typing import Any

from app.operations.cells import delimiter_of, number
from core.exceptions import InvalidParameterError

REQUIRED = ("route_id", "date", "stop_id", "lat", "lon", "arrival", "departure")
OPTIONAL = ("delivery_kg", "door_minutes")
_CLOCK = re.compile(r"([01][0-9]|2[0-3]):([0-5][0-9])(?::([0-5][0-9]))?")
#: Door minutes when the export has none: a minute, or the whole service when shorter [s].
DEFAULT_DOOR_S = 60.0


class _Line:
    """One row of the file and its line number, its cells by column."""

    def __init__(self, line: int, cells: dict[str, str], delimiter: str) -> None:
        self.line, self.cells, self.delimiter = line, cells, delimiter

    def field(self, column: str) -> str:
        return f"history[{self.line}].{column}"

    def error(self, column: str, rule: str) -> InvalidParameterError:
        return InvalidParameterError(f"line {self.line}: {rule}", self.field(column))

    def text(self, column: str) -> str:
        return self.cells.get(column, "").strip()

    def number(self, column: str, low: float, high: float) -> float:
        value = number(self.cells[column], self.delimiter, self.field(column))
        if not low <= value <= high:
            raise self.error(column, f"{column} must be within {low:g}..{high:g}, not {value:g}")
        return value

    def seconds(self, column: str) -> int:
        """A local time of the day [s after midnight]."""
        match = _CLOCK.fullmatch(self.text(column))
        if match is None:
            raise self.error(column, f"{self.text(column)[:20]!r} is not a time HH:MM[:SS]")
        hours, minutes, seconds = (int(g or 0) for g in match.groups())
        return hours * 3600 + minutes * 60 + seconds

    def date(self) -> dt.date:
        try:
            return dt.date.fromisoformat(self.text("date"))
        except ValueError:
            raise self.error(
                "date", f"{self.text('date')[:20]!r} is not a date YYYY-MM-DD"
            ) from None


def _clock(seconds: int) -> str:
    return f"{seconds // 3600:02d}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


def _lines(text: str) -> list[_Line]:
    rows = text.lstrip("\ufeff").splitlines()
    if not rows or not rows[0].strip():
        raise InvalidParameterError("the CSV has no header row", "history")
    delimiter = delimiter_of(rows[0])
    table = list(csv.reader(rows, delimiter=delimiter))
    header = [cell.strip() for cell in table[0]]
    missing = [name for name in REQUIRED if name not in header]
    if missing:
        raise InvalidParameterError(
            f"the header has no column {missing[0]!r}; the columns are "
            f"{', '.join(REQUIRED)} and optionally {', '.join(OPTIONAL)}",
            "history",
        )
    out = []
    for index, row in enumerate(table[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise InvalidParameterError(
                f"line {index} has {len(row)} cells, the header {len(header)}",
                f"history[{index}]",
            )
        out.append(_Line(index, dict(zip(header, row, strict=True)), delimiter))
    return out


class _Day:
    """A route's day being read: its start and stops, the time reached, whether it is back."""

    def __init__(self, first: _Line, depot_id: str) -> None:
        if first.text("stop_id") != depot_id:
            raise first.error(
                "stop_id", f"a day begins with the departure from the depot '{depot_id}'"
            )
        self.date = first.date()
        self.start_s = self.clock_s = first.seconds("departure")
        self.stops: list[dict[str, Any]] = []
        self.back = False
        self.depot_id = depot_id

    def add(self, row: _Line) -> None:
        if self.back:
            raise row.error("stop_id", "a row after the return to the depot the same day")
        arrival = row.seconds("arrival")
        if arrival < self.clock_s:
            raise row.error(
                "arrival", f"arrival {row.text('arrival')} is before {_clock(self.clock_s)}"
            )
        if row.text("stop_id") == self.depot_id:
            self.back, self.clock_s = True, arrival
            return
        departure = row.seconds("departure")
        if departure < arrival:
            raise row.error("departure", f"departure {row.text('departure')} is before arrival")
        stop_id = row.text("stop_id")
        if not stop_id or any(stop["id"] == stop_id for stop in self.stops):
            raise row.error("stop_id", f"stop {stop_id!r} is empty or twice in the day")
        service_s = float(departure - arrival)
        door_s = min(DEFAULT_DOOR_S, service_s)
        if row.text("door_minutes"):
            door_s = row.number("door_minutes", 0, service_s / 60.0) * 60.0
        self.stops.append(
            {
                "id": stop_id[:64],
                "lat": row.number("lat", -90, 90),
                "lon": row.number("lon", -180, 180),
                "service_time_s": service_s,
                "door_open_s": door_s,
                "delivery_kg": row.number("delivery_kg", 0, 40_000)
                if row.text("delivery_kg")
                else 0.0,
            }
        )
        self.clock_s = departure

    def driven(self, row: _Line) -> dict[str, Any]:
        """The day as the study takes it."""
        if not self.stops:
            raise row.error("stop_id", "a day without a stop")
        return {
            "date": self.date.isoformat(),
            "start_time": _clock(self.start_s)[:5],  # to the minute, as a study's clock
            "stops": self.stops,
        }


def with_history(body: dict[str, Any], text: str) -> dict[str, Any]:
    """The study's JSON body (its routes each an ``id`` and a ``depot``) with each route's
    days from the telematics export ``text``."""
    routes = body.get("routes")
    if not isinstance(routes, list) or not all(isinstance(r, dict) for r in routes):
        raise InvalidParameterError("the study needs its routes[] (id, depot)", "routes")
    by_id: dict[str, int] = {}
    for k, route in enumerate(routes):
        depot = route.get("depot")
        if not isinstance(route.get("id"), str) or not isinstance(depot, dict):
            raise InvalidParameterError("a route needs its id and depot", f"routes[{k}]")
        for name in ("stops", "start_time", "days"):
            if name in route:
                raise InvalidParameterError(
                    f"{name} come from the file: leave them out", f"routes[{k}].{name}"
                )
        by_id[route["id"]] = k
    days: list[list[dict[str, Any]]] = [[] for _ in routes]
    seen: set[tuple[str, dt.date]] = set()
    day: _Day | None = None
    key: tuple[str, dt.date] | None = None
    last: _Line | None = None
    for row in _lines(text):
        route_id = row.text("route_id")
        if route_id not in by_id:
            raise row.error("route_id", f"no route of the study has the id {route_id[:64]!r}")
        here = (route_id, row.date())
        if here != key:
            if day is not None and key is not None and last is not None:
                days[by_id[key[0]]].append(day.driven(last))
            if here in seen:
                raise row.error("date", f"the rows of {route_id} on {here[1]} are not together")
            previous = days[by_id[route_id]]
            if previous and previous[-1]["date"] > here[1].isoformat():
                raise row.error("date", f"{here[1]} comes after a later day of {route_id}")
            seen.add(here)
            day, key = _Day(row, str(routes[by_id[route_id]]["depot"].get("id"))), here
        else:
            assert day is not None
            day.add(row)
        last = row
    if day is not None and key is not None and last is not None:
        days[by_id[key[0]]].append(day.driven(last))
    for k, route_days in enumerate(days):
        if not route_days:
            raise InvalidParameterError("the file has no day of this route", f"routes[{k}]")
    return body | {"routes": [r | {"days": d} for r, d in zip(routes, days, strict=True)]}
