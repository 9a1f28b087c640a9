"""POST /v1/plans: a round to plan, and the planned and simulated round."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field

from app.schemas.base import (
    ApiModel,
    AttributionOut,
    BatteryOut,
    BoxOut,
    ColdChainOut,
    DistanceSourceOut,
    EnergyKwh,
    EnergySeries,
    EnergyShare,
    LineString,
    Point,
    RefrigerationOut,
    VanRequest,
    WeatherOut,
)
from core.params import Objective
from core.planning.model import (
    BreakResult,
    ChargeResult,
    DayProfile,
    LegResult,
    PlanFields,
    ReloadResult,
    Solved,
    StopResult,
    VisitResult,
)


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


class LegOut(ApiModel, LegResult):
    """One driven leg."""

    energy_kwh: EnergyKwh = Field(  # type: ignore[assignment]
        ..., description="Energy of each consumer while driving this leg [kWh]."
    )
    geometry: LineString | None = Field(  # type: ignore[assignment]
        None, description="The leg's road; present when the request sets include_geometry."
    )


class StopOut(ApiModel, StopResult):
    """One stop, in visiting order."""

    energy_kwh: EnergyKwh = Field(  # type: ignore[assignment]
        ..., description="Energy used while standing here [kWh]."
    )


class ChargeOut(ApiModel, ChargeResult):
    """One charge of the round, where it happens in the timeline."""


class ReloadOut(ApiModel, ReloadResult):
    """A return to the depot to reload, where it happens in the timeline."""


class BreakOut(ApiModel, BreakResult):
    """A driver's break, parked (cab and refrigeration drawing)."""


class VisitOut(ApiModel, VisitResult):
    """One visit of the van's day, in time order."""

    energy_kwh: EnergyKwh = Field(  # type: ignore[assignment]
        ..., description="Energy of each consumer from arrival to departure [kWh]."
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


class SolverOut(ApiModel, Solved):
    """How the search ended."""

    objective: Objective = Field(
        ..., description="What the tour minimised: distance, duration or energy."
    )


class DayProfileOut(ApiModel, DayProfile):
    """The round minute by minute, from departure to return (the paper's Fig. 8)."""

    energy_kwh: EnergySeries = Field(  # type: ignore[assignment]
        ..., description="Energy of each consumer since departure, cumulative [kWh]."
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
    visits: list[VisitOut] = Field(
        default_factory=list,
        description="The day as one list in time order: every stop, charge, return to reload "
        "and break, each with its arrival, start and departure, the state of charge, the "
        "payload and the energy there, and the driving so far (what stops, charges, reloads "
        "and breaks hold, by kind).",
    )
    totals: Totals = Field(..., description="The whole round.")
    battery: BatteryOut = Field(..., description="Whether the battery holds out with its reserve.")
    weather: WeatherOut = Field(..., description="The weather the round was simulated with.")
    timezone: str = Field(..., description="Time zone of the times, or the solar-time note.")
    box: BoxOut = Field(..., description="Cargo-box temperatures (dynamic mode).")
    refrigeration: RefrigerationOut | None = Field(
        None,
        description="How the refrigeration unit ran (refrigeration.strategy): its energy from "
        "the battery and the grid, a thermostat's beside it, and its set-point schedule.",
    )
    cold_chain: ColdChainOut | None = Field(
        None,
        description="Whether the goods stayed inside their product band while aboard "
        "(cargo_box.product); null: the box has no product.",
    )
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
