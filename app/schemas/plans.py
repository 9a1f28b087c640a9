"""POST /v1/plans: a round to plan, and the planned and simulated round."""

from __future__ import annotations

import datetime as dt
from typing import Any, Literal

from pydantic import Field

from app.schemas.base import (
    ApiModel,
    AttributionOut,
    BatteryOut,
    BoxOut,
    DistanceSourceOut,
    EnergyKwh,
    EnergySeries,
    EnergyShare,
    LineString,
    Point,
    VanRequest,
    WeatherOut,
)
from core.params import Objective, StreetTypeName
from core.planning.model import PlanFields, ProvenPart
from core.routing.effort import SearchEnd
from core.routing.tsp import SolverStatus


class AnswerOptions(ApiModel):
    """What the answer carries beyond the legs and stops: each leg's road, the day minute by
    minute."""

    include_geometry: bool = Field(
        False,
        description="Return each leg's road as a GeoJSON LineString in legs[].geometry (the "
        "router's road with OSRM, else the straight line).",
    )
    include_profile: bool = Field(
        False,
        description="Return the day minute by minute in profile: the state of charge, the "
        "energy of each consumer so far and the box's temperature (the plan viewer's charts).",
    )


class PlanRequest(VanRequest, AnswerOptions, PlanFields):
    """A delivery round to plan: depot, stops, date, van and conditions. Stops with
    time_windows are served inside them (the van waits when early); when no order can, the
    answer is a 422 naming the stop that cannot be reached in time."""


class LegOut(ApiModel):
    """One driven leg."""

    from_id: str = Field(..., description="Where the leg starts: the depot's or a stop's id.")
    to_id: str = Field(..., description="Where the leg ends: a stop's or the depot's id.")
    depart: dt.datetime = Field(..., description="Departure, local time with offset.")
    arrive: dt.datetime = Field(..., description="Arrival, local time with offset.")
    distance_m: float = Field(..., description="Distance [m].")
    duration_s: float = Field(..., description="Driving time [s].")
    street_type: StreetTypeName = Field(
        ...,
        description="urban, highway or expressway: by the leg's speeds (router or client) "
        "or its length (estimate).",
    )
    grade: float = Field(..., description="Mean grade, rise over run [–].")
    energy_kwh: EnergyKwh = Field(
        ..., description="Energy of each consumer while driving this leg [kWh]."
    )
    soc_start: float = Field(..., description="State of charge at departure [–].")
    soc_end: float = Field(..., description="State of charge on arrival [–].")
    geometry: LineString | None = Field(
        None, description="The leg's road; present when the request sets include_geometry."
    )


class StopOut(ApiModel):
    """One stop, in visiting order."""

    id: str = Field(..., description="The stop's id.")
    arrival: dt.datetime = Field(..., description="Arrival, local time with UTC offset.")
    service_start: dt.datetime = Field(
        ..., description="Service begins (inside a time window), local time with UTC offset."
    )
    wait_s: float = Field(
        ..., description="Waiting for the stop's time window to open, parked [s]."
    )
    departure: dt.datetime = Field(
        ..., description="Departure after the service, local time with UTC offset."
    )
    door_heat_kwh: float = Field(..., description="Heat let in through the open door [kWh].")
    payload_after_kg: float = Field(..., description="Payload when leaving the stop [kg].")
    energy_kwh: EnergyKwh = Field(..., description="Energy used while standing here [kWh].")
    soc_arrival: float = Field(..., description="State of charge on arrival [–].")
    soc_departure: float = Field(..., description="State of charge when leaving [–].")
    snap_distance_m: float | None = Field(
        None,
        description="Distance from the stop to the road the router snapped it to [m]; null "
        "without a router.",
    )


class ChargeOut(ApiModel):
    """One charge of the round, where it happens in the timeline."""

    charger_id: str = Field(
        ..., description="Where: a charger's id, or \"depot\" for the depot's charger."
    )
    arrive: dt.datetime = Field(..., description="Arrival at the charger, local time.")
    depart: dt.datetime = Field(
        ..., description="Departure, plugging in and out included, local time."
    )
    soc_before: float = Field(..., description="State of charge when the charge starts [–].")
    soc_after: float = Field(..., description="State of charge when it ends [–].")
    grid_kwh: float = Field(
        ...,
        description="Energy from the grid: the charge (battery_kwh / charging_efficiency) and "
        "the cab and refrigeration, which run from the grid while plugged in [kWh].",
    )
    battery_kwh: float = Field(..., description="Energy stored in the battery [kWh].")
    minutes: float = Field(..., description="Minutes charging (plugging in and out aside).")
    cost: float = Field(..., description="grid_kwh at the charger's price_per_kwh.")
    lat: float = Field(..., description="The charger's latitude [°].")
    lon: float = Field(..., description="The charger's longitude [°].")


class ReloadOut(ApiModel):
    """A return to the depot to reload, where it happens in the timeline."""

    arrive: dt.datetime = Field(..., description="Arrival at the depot, local time.")
    depart: dt.datetime = Field(..., description="Departure with the new load, local time.")
    payload_kg: float = Field(..., description="Payload aboard when it leaves [kg].")


class BreakOut(ApiModel):
    """A driver's break, parked (cab and refrigeration drawing)."""

    start: dt.datetime = Field(..., description="Start, local time.")
    end: dt.datetime = Field(..., description="End, local time.")
    kind: str = Field(
        ...,
        description='"eu-561": the driving limit of Regulation (EC) No 561/2006 (also a wait '
        'or a charge of 45 min that counts as the break); "fixed": one of the listed breaks.',
    )


class Totals(ApiModel):
    """The whole round."""

    distance_m: float = Field(..., description="Distance of the round [m].")
    duration_s: float = Field(..., description="From departure to return, stops included [s].")
    energy_kwh: EnergyKwh = Field(..., description="Energy of each consumer over the round [kWh].")
    energy_share: EnergyShare = Field(
        ..., description="Each consumer's share of the round's energy [–]."
    )
    grid_kwh: float = Field(
        0.0,
        description="Energy from the grid before departure to pre-condition cab and box [kWh] "
        "(not from the battery).",
    )


class SolverOut(ApiModel):
    """How the search ended."""

    status: SolverStatus = Field(
        ...,
        description="optimal: the whole answer is proven optimal for its objective — the order "
        "proven over every arc, and no charge or reload placed by a heuristic; feasible: the "
        "best found (see proven for the parts that carry a proof); fixed_order: keep_order.",
    )
    objective: Objective = Field(
        ..., description="What the tour minimised: distance, duration or energy."
    )
    objective_value: float = Field(..., description="Of the tour, in m, s or Wh (estimate).")
    runtime_s: float = Field(
        ..., description="Time the search took [s]. A timing field: it differs between runs."
    )
    stopped_by: SearchEnd = Field(
        "work",
        description="work: the search did all its work (work_s); proof: it proved its optimum "
        "first; time_limit: time_limit_s stopped it first — the answer may then differ on a "
        "retry (a warning says so). The same request gives the same answer unless time_limit.",
    )
    proven: list[ProvenPart] = Field(
        default_factory=list,
        description="The parts of the answer that carry a proof: order (the stops' order is "
        "the optimum of the round trip) — also when charges or reloads were placed after it.",
    )


class DayProfileOut(ApiModel):
    """The round minute by minute, from departure to return (the paper's Fig. 8)."""

    time: list[dt.datetime] = Field(..., description="Each minute, local time with UTC offset.")
    soc: list[float] = Field(..., description="State of charge at each moment [–].")
    energy_kwh: EnergySeries = Field(
        ..., description="Energy of each consumer since departure, cumulative [kWh]."
    )
    box_temperature_c: list[float] | None = Field(
        ...,
        description="Cargo-air temperature at each moment [°C] (dynamic box; null in steady "
        "mode, where the unit holds the set-point).",
    )


class PlanResponse(ApiModel):
    """The planned and simulated round."""

    tour: list[str] = Field(
        ...,
        description='Ids in driving order, depot first and last ("start", the van\'s position, '
        "first with start_state); a charger's id (or the depot) between stops is a charge.",
    )
    legs: list[LegOut] = Field(..., description="The driven legs, in order.")
    stops: list[StopOut] = Field(..., description="The stops, in visiting order.")
    charges: list[ChargeOut] = Field(
        default_factory=list,
        description="The charges between stops (the tour shows each charger visited), in "
        "order; the legs' and stops' states of charge and the battery verdict include them.",
    )
    reloads: list[ReloadOut] = Field(
        default_factory=list,
        description="The returns to the depot to reload (the tour shows each), in order.",
    )
    breaks: list[BreakOut] = Field(
        default_factory=list, description="The driver's breaks, in order (between stops)."
    )
    totals: Totals = Field(..., description="The whole round.")
    battery: BatteryOut = Field(..., description="Whether the battery holds out with its reserve.")
    weather: WeatherOut = Field(..., description="The weather the round was simulated with.")
    timezone: str = Field(..., description="Time zone of the times, or the solar-time note.")
    box: BoxOut = Field(..., description="Cargo-box temperatures (dynamic mode).")
    solver: SolverOut = Field(..., description="How the tour search ended.")
    distance_source: DistanceSourceOut
    warnings: list[str] = Field(
        default_factory=list,
        description="What the plan had to do without (e.g. the weather service was down and "
        "the climatology was used).",
    )
    attribution: AttributionOut = None
    profile: DayProfileOut | None = Field(
        None, description="The day minute by minute; present when the request sets include_profile."
    )


class Feature(ApiModel):
    """A GeoJSON Feature (RFC 7946)."""

    type: Literal["Feature"] = Field("Feature", description="Always Feature.")
    geometry: Point | LineString = Field(
        ..., description="A stop's Point or a leg's LineString, [lon, lat]."
    )
    properties: dict[str, Any] = Field(..., description="What the feature is, with its figures.")


class PlanFeatureCollection(ApiModel):
    """The plan as a GeoJSON FeatureCollection: the depot and stops as Points (id, arrival,
    door heat, state of charge), each charge as a Point where it happens (kind "charge", the
    fields of `charges[]`), each reload at the depot (kind "reload"), the legs as LineStrings
    (energy per consumer, state of charge at both ends)."""

    type: Literal["FeatureCollection"] = Field(
        "FeatureCollection", description="Always FeatureCollection."
    )
    features: list[Feature] = Field(
        ...,
        description="The depot, the stops and the charges (Points), then the legs (LineStrings).",
    )
    attribution: str | None = Field(None, description="Credit for the map data.")
