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

Or GPS traces — one row per fix: ``route_id``, ``date``, ``time`` (local HH:MM[:SS]), ``lat``,
``lon`` — each day's fixes together and in time order. The day starts when the van leaves the
depot (its last fix within :data:`AT_DEPOT_M`), ends when it is back for the last time (a van
passing its depot drives on; one back between two tours dwells there: a stop at the depot),
and a stop is where it stays within :data:`DWELL_RADIUS_M` for :data:`MIN_DWELL_S` or longer
(the dwell detection of telematics "stop" reports, e.g. Geotab's trips and stops): its place
the mean of those fixes, its service the dwell. In the stop rows too, a row at the depot
before the day's last is a visit there (a second tour), with its arrival and departure.
"""

from __future__ import annotations

import csv
import datetime as dt
import re
from typing import Any

import numpy as np
from pydantic import ValidationError

from app.operations.cells import delimiter_of, header_of, number
from core.clock import departure
from core.exceptions import InvalidParameterError
from core.params import Location
from core.routing.geo import metres_from

REQUIRED = ("route_id", "date", "stop_id", "lat", "lon", "arrival", "departure")
OPTIONAL = ("delivery_kg", "door_minutes")
#: The columns of GPS traces: one row per fix.
TRACE = ("route_id", "date", "time", "lat", "lon")
#: A van within this distance of its depot is at the depot [m].
AT_DEPOT_M = 150.0
#: A stop: the van stays within this distance of where it stopped [m] …
DWELL_RADIUS_M = 50.0
#: … for at least this long [s].
MIN_DWELL_S = 120.0
_CLOCK = re.compile(r"([01][0-9]|2[0-3]):([0-5][0-9])(?::([0-5][0-9]))?")
_DATE = re.compile(r"[0-9]{4}-[0-9]{2}-[0-9]{2}")
#: The longest stop id a study takes (as ``Stop.id``).
MAX_ID = 64
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
        """The row's date, YYYY-MM-DD only (Python would read 20260302 and 2026-W10-1 too)."""
        try:
            if not _DATE.fullmatch(self.text("date")):
                raise ValueError
            return dt.date.fromisoformat(self.text("date"))
        except ValueError:
            raise self.error(
                "date", f"{self.text('date')[:20]!r} is not a date YYYY-MM-DD"
            ) from None

    def starting(self, column: str, timezone: str | None, lon: float) -> None:
        """The day's start at this row's ``column`` is a moment of its zone: not skipped by
        the clocks (the spring change), as the study would find later."""
        start = dt.time.fromisoformat(_clock(self.seconds(column))[:5])
        try:
            departure(self.date(), start, timezone, lon)
        except InvalidParameterError as error:
            if error.field == "start_time":  # else the study's own field (its zone) is wrong
                raise self.error(column, error.message) from None


def _clock(seconds: int) -> str:
    return f"{seconds // 3600:02d}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


def _lines(text: str) -> tuple[list[_Line], bool]:
    """The rows of the file, and whether it is GPS traces (its header has ``time`` and no
    ``stop_id``) rather than stops."""
    rows = text.lstrip("\ufeff").splitlines()
    if not rows or not rows[0].strip():
        raise InvalidParameterError("the CSV has no header row", "history")
    delimiter = delimiter_of(rows[0])
    table = list(csv.reader(rows, delimiter=delimiter))
    header = header_of(table[0], "history")
    traces = "time" in header and "stop_id" not in header
    missing = [name for name in (TRACE if traces else REQUIRED) if name not in header]
    if missing:
        raise InvalidParameterError(
            f"the header has no column {missing[0]!r}; the columns are "
            f"{', '.join(REQUIRED)} and optionally {', '.join(OPTIONAL)} (one row per stop), "
            f"or {', '.join(TRACE)} (GPS traces: one row per fix)",
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
    return out, traces


class _Day:
    """A route's day being read: its start, its stops and the time reached."""

    def __init__(self, first: _Line, depot_id: str) -> None:
        if first.text("stop_id") != depot_id:
            raise first.error(
                "stop_id", f"a day begins with the departure from the depot '{depot_id}'"
            )
        self.date = first.date()
        self.start_s = self.clock_s = first.seconds("departure")
        self.stops: list[dict[str, Any]] = []
        self.depot_id = depot_id

    def add(self, row: _Line, last: bool) -> None:
        """The next row; ``last``: the day's last, where the depot is the return (before it,
        a visit to the depot — a second tour after lunch — is a stop there, so the day's
        kilometres and hours are all counted)."""
        arrival = row.seconds("arrival")
        if arrival < self.clock_s:
            raise row.error(
                "arrival", f"arrival {row.text('arrival')} is before {_clock(self.clock_s)}"
            )
        stop_id = row.text("stop_id")
        if stop_id == self.depot_id:
            if last:
                self.clock_s = arrival
                return
            if not row.text("departure"):
                raise row.error(
                    "departure",
                    "a return to the depot before the day's last row needs its departure "
                    "(the van sets off again)",
                )
            stop_id = f"{self.depot_id} ({row.text('arrival')})"
        departure = row.seconds("departure")
        if departure < arrival:
            raise row.error("departure", f"departure {row.text('departure')} is before arrival")
        if not stop_id or any(stop["id"] == stop_id for stop in self.stops):
            raise row.error("stop_id", f"stop {stop_id[:MAX_ID]!r} is empty or twice in the day")
        if len(stop_id) > MAX_ID:
            raise row.error(
                "stop_id", f"a stop id is at most {MAX_ID} characters, not {len(stop_id):,}"
            )
        service_s = float(departure - arrival)
        door_s = min(DEFAULT_DOOR_S, service_s)
        if row.text("door_minutes"):
            door_s = row.number("door_minutes", 0, service_s / 60.0) * 60.0
        self.stops.append(
            {
                "id": stop_id,
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
    lines, traces = _lines(text)
    year = body.get("year") if isinstance(body.get("year"), int) else None
    timezone = body.get("timezone") if isinstance(body.get("timezone"), str) else None
    days: list[list[dict[str, Any]]] = [[] for _ in routes]
    for route_id, group in _days(lines, by_id, year):
        depot = routes[by_id[route_id]]["depot"]
        if traces:
            try:
                Location.model_validate({"lat": depot.get("lat"), "lon": depot.get("lon")})
            except ValidationError:
                raise InvalidParameterError(
                    "a depot needs its lat (-90..90) and lon (-180..180) to find it in the traces",
                    f"routes[{by_id[route_id]}].depot",
                ) from None
        day = (
            _traced(route_id, group, depot, timezone)
            if traces
            else _visited(group, depot, timezone)
        )
        days[by_id[route_id]].append(day)
    for k, route_days in enumerate(days):
        if not route_days:
            raise InvalidParameterError("the file has no day of this route", f"routes[{k}]")
    return body | {"routes": [r | {"days": d} for r, d in zip(routes, days, strict=True)]}


def _days(
    lines: list[_Line], by_id: dict[str, int], year: int | None
) -> list[tuple[str, list[_Line]]]:
    """The rows of each route's day, in the file's order: a day's rows together, a route's
    days in date order, every date in the study's ``year``."""
    out: list[tuple[str, list[_Line]]] = []
    seen: set[tuple[str, dt.date]] = set()
    last: dict[str, dt.date] = {}
    key: tuple[str, dt.date] | None = None
    for row in lines:
        route_id = row.text("route_id")
        if route_id not in by_id:
            raise row.error("route_id", f"no route of the study has the id {route_id[:64]!r}")
        here = (route_id, row.date())
        if year is not None and here[1].year != year:
            raise row.error("date", f"{here[1]} is not in the study's year {year}")
        if here == key:
            out[-1][1].append(row)
            continue
        if here in seen:
            raise row.error("date", f"the rows of {route_id} on {here[1]} are not together")
        if route_id in last and last[route_id] > here[1]:
            raise row.error("date", f"{here[1]} comes after a later day of {route_id}")
        seen.add(here)
        last[route_id], key = here[1], here
        out.append((route_id, [row]))
    return out


def _visited(group: list[_Line], depot: dict[str, Any], timezone: str | None) -> dict[str, Any]:
    """A day of one row per stop visited, starting at a moment of ``timezone``."""
    day = _Day(group[0], str(depot.get("id")))
    group[0].starting("departure", timezone, _lon(depot))
    for k, row in enumerate(group[1:], start=2):
        day.add(row, last=k == len(group))
    return day.driven(group[-1])


def _lon(depot: dict[str, Any]) -> float:
    """The depot's longitude where it has one (the clock of a study without a zone)."""
    lon = depot.get("lon")
    return float(lon) if isinstance(lon, int | float) and -180 <= lon <= 180 else 0.0


def _traced(
    route_id: str, group: list[_Line], depot: dict[str, Any], timezone: str | None
) -> dict[str, Any]:
    """A day of GPS fixes: its departure from the depot (a moment of ``timezone``) and its
    stops (dwells)."""
    times = np.array([row.seconds("time") for row in group], dtype=float)
    for k in range(1, len(group)):
        if times[k] <= times[k - 1]:
            raise group[k].error(
                "time", f"time {group[k].text('time')} is not after the fix before"
            )
    lat = np.array([row.number("lat", -90, 90) for row in group])
    lon = np.array([row.number("lon", -180, 180) for row in group])
    place = Location.model_validate({"lat": depot.get("lat"), "lon": depot.get("lon")})
    from_depot_m = metres_from(place.lat, place.lon, lat, lon)
    away = np.flatnonzero(from_depot_m > AT_DEPOT_M)
    if from_depot_m[0] > AT_DEPOT_M or away.size == 0:
        raise group[0].error("lat", "a day's trace begins at the depot, then leaves it")
    # from the first fix away to the last return: a van that passes its depot, or comes back
    # between two tours, drives on (a stop there where it dwelt)
    leave, end = int(away[0]), int(away[-1]) + 1
    group[leave - 1].starting("time", timezone, _lon(depot))
    stops = _dwells(route_id, group[0].date(), times[leave:end], lat[leave:end], lon[leave:end])
    if not stops:
        raise group[0].error(
            "time",
            f"the trace of {group[0].date()} has no stop (a stop is {MIN_DWELL_S / 60:g} min "
            f"or more within {DWELL_RADIUS_M:g} m)",
        )
    return {
        "date": group[0].date().isoformat(),
        "start_time": _clock(int(times[leave - 1]))[:5],
        "stops": stops,
    }


def _dwells(
    route_id: str, date: dt.date, times: np.ndarray, lat: np.ndarray, lon: np.ndarray
) -> list[dict[str, Any]]:
    """The stops among fixes away from the depot: runs of fixes within
    :data:`DWELL_RADIUS_M` of the run's first for :data:`MIN_DWELL_S` or longer."""
    stops: list[dict[str, Any]] = []
    i = 0
    while i < len(times):
        j = _last_within(i, lat, lon)
        if times[j] - times[i] >= MIN_DWELL_S:
            service_s = float(times[j] - times[i])
            stops.append(
                {
                    "id": f"{route_id}-{date.isoformat()}-{len(stops) + 1}"[:64],
                    "lat": float(lat[i : j + 1].mean()),
                    "lon": float(lon[i : j + 1].mean()),
                    "service_time_s": service_s,
                    "door_open_s": min(DEFAULT_DOOR_S, service_s),
                    "delivery_kg": 0.0,
                }
            )
            i = j + 1
        else:
            i += 1
    return stops


def _last_within(i: int, lat: np.ndarray, lon: np.ndarray, chunk: int = 64) -> int:
    """The last fix of the run from fix ``i`` that stays within :data:`DWELL_RADIUS_M` of it
    (looked at a chunk at a time: a drive ends the run at once, a long dwell in a few)."""
    start = i + 1
    while start < len(lat):
        near = metres_from(lat[i], lon[i], lat[start : start + chunk], lon[start : start + chunk])
        out = np.flatnonzero(near > DWELL_RADIUS_M)
        if out.size:
            return start + int(out[0]) - 1
        start += chunk
    return len(lat) - 1
