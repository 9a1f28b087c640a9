"""The places of a round: the depot, the stops with their time windows, and a client's road
matrices."""

from __future__ import annotations

import datetime as dt
from typing import Annotated, Literal, TypeVar

from pydantic import Field, ValidationError, ValidationInfo, field_validator
from pydantic_core import InitErrorDetails, PydanticCustomError

from core.params.base import ClockTime, Params
from core.params.conditions import StreetTypeName

T = TypeVar("T")


class Place(Params):
    """A point of a round: the depot or a stop."""

    id: str = Field("depot", min_length=1, max_length=64, description="Identifier of the depot.")
    lat: float = Field(..., ge=-90, le=90, description="Latitude [°], north positive.")
    lon: float = Field(..., ge=-180, le=180, description="Longitude [°], east positive.")
    elevation_m: float | None = Field(
        None, ge=-500, le=9000, description="Elevation above sea level [m]; gives leg grades."
    )


class TimeWindow(Params):
    """A span of local time on the round's date: when a stop takes deliveries (service starts
    inside) or a charger is open."""

    start: ClockTime = Field(..., description="Opens, local HH:MM.")
    end: ClockTime = Field(..., description="Closes, local HH:MM; after start.")

    @field_validator("end")
    @classmethod
    def _after_start(cls, value: dt.time, info: ValidationInfo) -> dt.time:
        if "start" in info.data and value <= info.data["start"]:
            raise ValueError("end must be after start")
        return value


def windows_in_order(value: list[TimeWindow]) -> list[TimeWindow]:
    """``value`` when its windows are sorted and do not overlap; else the error names the
    window that starts too early."""
    for k in range(1, len(value)):
        if value[k].start < value[k - 1].end:
            rule = PydanticCustomError(
                "windows_in_order",
                "starts at {start}, before window {previous} ends ({end}); windows must be "
                "sorted and must not overlap",
                {
                    "start": f"{value[k].start:%H:%M}",
                    "previous": k - 1,
                    "end": f"{value[k - 1].end:%H:%M}",
                },
            )
            raise ValidationError.from_exception_data(
                "TimeWindow", [InitErrorDetails(type=rule, loc=(k, "start"), input=None)]
            )
    return value


#: Most minutes to plug in, start and unplug a charge.
MAX_PLUG_MINUTES = 120.0


class ChargePoint(Params):
    """Charging points of one power at one place."""

    power_kw: float = Field(
        ...,
        ge=1,
        le=1000,
        description="Power of each point [kW], at least 1 kW; the van's charging curve and "
        "max_charge_power_kw cap it.",
    )
    points: int = Field(1, ge=1, le=100, description="How many vans charge at once, at least 1.")
    price_per_kwh: float = Field(
        0.0, ge=0, le=100, description="Price of the energy drawn from the grid [per kWh]."
    )
    plug_minutes: float = Field(
        2.0,
        ge=0,
        le=MAX_PLUG_MINUTES,
        description="Minutes to plug in, start and unplug, besides the charge itself.",
    )


class Depot(Place):
    """Where the round starts and ends, and its chargers."""

    charger: ChargePoint | None = Field(
        None,
        description="The depot's charge points: a van whose battery would not last comes back "
        "between stops to charge what the rest of its round needs. Absent: no charging.",
    )


#: Most time windows of one stop.
MAX_TIME_WINDOWS = 8
#: Most stops of one request any server takes; a server's own limit (``COLDROUTE_MAX_STOPS``)
#: is at most this.
MAX_STOPS = 5000


class Stop(Place):
    """A delivery stop."""

    id: str = Field(..., min_length=1, max_length=64, description="Unique identifier of the stop.")
    service_time_s: float = Field(300.0, ge=0, le=86_400, description="Time spent at the stop [s].")
    door_open_s: float = Field(
        60.0, ge=0, le=86_400, description="Time the cargo door is open, within the service [s]."
    )
    delivery_kg: float = Field(0.0, ge=0, le=40_000, description="Payload unloaded here [kg].")
    time_windows: list[TimeWindow] = Field(
        default_factory=list,
        max_length=MAX_TIME_WINDOWS,
        description="When the stop takes deliveries (local time on the round's date), sorted "
        "and not overlapping: the van may arrive early and wait; service starts inside a "
        "window. Empty: any time.",
    )

    @field_validator("time_windows")
    @classmethod
    def _windows_in_order(cls, value: list[TimeWindow]) -> list[TimeWindow]:
        return windows_in_order(value)

    @field_validator("door_open_s")
    @classmethod
    def _door_within_service(cls, value: float, info: ValidationInfo) -> float:
        if "service_time_s" in info.data and value > info.data["service_time_s"]:
            raise ValueError("door_open_s must not exceed service_time_s")
        return value


#: Most chargers on the way one request may list.
MAX_CHARGERS = 200


class Charger(Place, ChargePoint):
    """Charge points on the way: a van whose battery would not last drives there between
    stops and charges what the rest of its day needs."""

    id: str = Field(
        ...,
        min_length=1,
        max_length=64,
        description='Identifier of the charger, unique among the places ("depot" names the '
        "depot's own charger).",
    )
    opening_hours: list[TimeWindow] = Field(
        default_factory=list,
        max_length=MAX_TIME_WINDOWS,
        description="When vans may charge (local time on the round's date), sorted and not "
        "overlapping: a van waits for the opening and unplugs at the closing. Empty: always.",
    )

    @field_validator("opening_hours")
    @classmethod
    def _hours_in_order(cls, value: list[TimeWindow]) -> list[TimeWindow]:
        return windows_in_order(value)


#: Longest leg a matrix may hold: 100,000 km and 30 days (beyond, the numbers are mistakes).
MAX_MATRIX_DISTANCE_M = 1e8
MAX_MATRIX_DURATION_S = 30 * 86_400.0


#: A square table, row by row: a row's first bad cell is named (a row of 5,000 strings is
#: one error, not 5,000).
_Table = list[Annotated[list[T], Field(max_length=MAX_STOPS + 1, fail_fast=True)]]


class RoadMatrix(Params):
    """Distances and durations from the client's road router: depot first, then the stops in
    request order, then the chargers on the way (when the request has any)."""

    distances_m: _Table[Annotated[float, Field(ge=0, le=MAX_MATRIX_DISTANCE_M)]] = Field(
        ..., max_length=MAX_STOPS + 1, description="Road distance of each pair [m], 0–100,000 km."
    )
    durations_s: _Table[Annotated[float, Field(ge=0, le=MAX_MATRIX_DURATION_S)]] = Field(
        ..., max_length=MAX_STOPS + 1, description="Driving time of each pair [s], 0–30 days."
    )
    street_types: _Table[StreetTypeName] | None = Field(
        None,
        max_length=MAX_STOPS + 1,
        description="Street type of each pair; null chooses by leg length.",
    )


Objective = Literal["distance", "duration", "energy"]
