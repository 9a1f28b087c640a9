"""Time: every instant is computed in UTC and shown in the round's time zone.

Adding seconds to a zone-aware ``datetime`` does wall-clock arithmetic in Python (a round that
crosses a daylight-saving change would come back an hour early or late), so the planner counts
seconds from a UTC instant and converts to local time only to show it or to read the local
clock (the daily temperature curve, the day of a multi-day round).
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass
from functools import cache
from zoneinfo import ZoneInfo, available_timezones

import numpy as np
from numpy.typing import ArrayLike, NDArray

from core.arrays import FloatArray
from core.exceptions import InvalidParameterError

UTC = dt.UTC
SECONDS_PER_DAY = 86_400.0
#: Spacing of the UTC offset look-ups along a trace [s]. Every time-zone transition in the IANA
#: database falls on a multiple of 15 minutes.
_OFFSET_GRID_S = 900.0
_EPOCH_DATE = dt.date(1970, 1, 1)


def zone_for(timezone: str | None, lon: float) -> tuple[dt.tzinfo, str]:
    """The time zone of a round and its display name.

    Parameters
    ----------
    timezone
        IANA name (``Europe/Vienna``), or None for local mean solar time at ``lon``.
    lon
        Longitude of the depot [°], east positive: without a zone the clock is UTC + lon/15 h.
    """
    if timezone is None:
        offset = dt.timedelta(minutes=round(lon * 4))
        minutes = abs(int(offset.total_seconds() // 60))
        sign = "+" if offset >= dt.timedelta(0) else "-"
        name = f"local mean solar time (UTC{sign}{minutes // 60:02d}:{minutes % 60:02d})"
        return dt.timezone(offset), name
    # Only a zone of the database: a folder of it ("Europe"), one of its files that is not a zone
    # ("zone.tab") or a path would otherwise reach the file system.
    if timezone not in _zone_names():
        shown = timezone if len(timezone) <= 64 else f"{timezone[:64]}…"
        raise InvalidParameterError(
            f"unknown time zone '{shown}'; use an IANA name like Europe/Vienna", "timezone"
        )
    return ZoneInfo(timezone), timezone


@cache
def _zone_names() -> frozenset[str]:
    """Every name of the IANA time-zone database (the tzdata package's, and the system's), but
    the system's "localtime": the server's own zone, not a client's."""
    return frozenset(available_timezones()) - {"localtime"}


def departure(
    date: dt.date, start_time: dt.time, timezone: str | None, lon: float
) -> tuple[dt.datetime, str]:
    """The zone-aware departure and the zone's display name.

    A local time that does not exist (skipped by a daylight-saving change, like 02:30 on the
    last Sunday of March in Europe) is an error naming ``start_time``; a time that exists twice
    (the autumn change) is its first occurrence, in summer time.
    """
    zone, name = zone_for(timezone, lon)
    start = dt.datetime.combine(date, start_time, tzinfo=zone)
    check_representable(start, 0.0, "date")
    if start.astimezone(UTC).astimezone(zone).replace(tzinfo=None) != start.replace(tzinfo=None):
        raise InvalidParameterError(
            f"{start_time:%H:%M} does not exist on {date} in {name}: the clocks skip it "
            "(daylight saving); pick a time before or after the change",
            "start_time",
        )
    return start, name


def at(start: dt.datetime, seconds: float) -> dt.datetime:
    """The instant ``seconds`` after ``start``, in ``start``'s zone (UTC arithmetic)."""
    return (start.astimezone(UTC) + dt.timedelta(seconds=seconds)).astimezone(start.tzinfo)


@dataclass(frozen=True)
class LocalClock:
    """UTC and local clock time along a trace.

    Attributes
    ----------
    utc_s
        Seconds since 1970-01-01T00:00Z of each moment [s].
    hour
        Local clock time of each moment [h since local midnight], with the UTC offset in force
        at that moment.
    day_index
        Local day of each moment, 0 for the start's day.
    dates
        The local calendar date of each day index.
    """

    utc_s: FloatArray
    hour: FloatArray
    day_index: NDArray[np.int_]
    dates: list[dt.date]

    def per_moment(self, per_day: ArrayLike) -> FloatArray:
        """Spread one value per day to every moment."""
        return np.asarray(per_day, dtype=float)[self.day_index]


def utc_offsets_s(zone: dt.tzinfo, utc_s: FloatArray) -> FloatArray:
    """UTC offset of ``zone`` at each instant [s], read on a 15-minute grid."""
    if utc_s.size == 0:
        return np.zeros(0)
    first = np.floor(utc_s.min() / _OFFSET_GRID_S) * _OFFSET_GRID_S
    grid = np.arange(first, utc_s.max() + _OFFSET_GRID_S, _OFFSET_GRID_S)
    offsets = np.array(
        [
            dt.datetime.fromtimestamp(t, UTC).astimezone(zone).utcoffset().total_seconds()  # type: ignore[union-attr]
            for t in grid
        ]
    )
    return offsets[np.searchsorted(grid, utc_s, side="right") - 1]


def local_clock(start: dt.datetime, offsets_s: FloatArray) -> LocalClock:
    """UTC and local clock time at ``start + offsets_s`` (true elapsed seconds).

    Parameters
    ----------
    start
        Timezone-aware start.
    offsets_s
        Seconds after the start [s], >= 0.
    """
    if start.tzinfo is None or start.utcoffset() is None:
        raise InvalidParameterError("start must carry a UTC offset or a time zone", "start")
    utc_s = start.timestamp() + np.asarray(offsets_s, dtype=float)
    local_s = utc_s + utc_offsets_s(start.tzinfo, utc_s)
    epoch_day = np.floor(local_s / SECONDS_PER_DAY).astype(int)
    first_day = (start.date() - _EPOCH_DATE).days
    day_index = epoch_day - first_day
    n_days = int(day_index.max()) + 1 if day_index.size else 1
    dates = [start.date() + dt.timedelta(days=d) for d in range(n_days)]
    hour = (local_s - epoch_day * SECONDS_PER_DAY) / 3600.0
    return LocalClock(utc_s, hour, day_index, dates)


def check_representable(start: dt.datetime, duration_s: float, field: str = "start") -> None:
    """Raise unless ``start`` to ``start + duration_s`` lies within the years 1 to 9999
    (Python's datetimes), with a day to spare at both ends for the UTC offset, the local clock
    and the weather of the first and the last day."""
    try:
        at(start, -SECONDS_PER_DAY)
    except OverflowError:
        raise InvalidParameterError(
            f"{_shown(start)} is too close to the start of the year 1, the first one "
            "the service can represent; start on 0001-01-03 or later",
            field,
        ) from None
    try:
        at(start, duration_s + SECONDS_PER_DAY)
    except OverflowError:
        raise InvalidParameterError(
            f"{_shown(start)} plus {duration_s / 3600:,.1f} h runs past the "
            "year 9999, the last one the service can represent",
            field,
        ) from None


def _shown(moment: dt.datetime) -> str:
    """A moment as a person reads it: ISO date (four-digit year) and HH:MM."""
    return f"{moment.date().isoformat()} {moment:%H:%M}"
