"""POST /v1/calibrations: a van's measured trips, and the parameters fitted to them."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from app.schemas.base import ApiModel, NotNull, VanRequest, absent
from core.calibration.fit import (
    CHANNELS,
    FITTABLE,
    FitParameter,
    FittableName,
    FittedParameter,
    TripFit,
)
from core.params import MAX_INTERVALS, MAX_TRACE_SAMPLES, DoorOpening, IsoDateTime, Location

#: Most trips in one calibration.
MAX_TRIPS = 1000
#: A column of samples: the first bad value is named (trips[2].speed_mps[17]).
Column = Annotated[list[float], Field(max_length=MAX_TRACE_SAMPLES, fail_fast=True)]


class TripRequest(ApiModel):
    """One measured trip: samples as parallel arrays, one value per sample in each."""

    id: str = Field(..., min_length=1, max_length=128, description="The trip's name.")
    start: IsoDateTime = Field(..., description="When the first sample was taken (ISO 8601).")
    location: Location = Field(..., description="Where the trip began (sun and climatology).")
    role: Literal["fit", "validation"] = Field(
        "fit",
        description="fit: the parameters are fitted to it; validation: only predicted (when no "
        "trip is, the fitted trips are cross-validated, k-fold).",
    )
    time_s: Column = Field(
        ..., min_length=2, description="Sample times [s], strictly increasing, any step."
    )
    speed_mps: Column = Field(..., min_length=2, description="Speed at each sample [m/s].")
    grade: Annotated[Column | None, NotNull] = absent("Road grade at each sample [–]; flat.")
    payload_kg: Annotated[Column | None, NotNull] = absent(
        "Payload at each sample [kg]; absent: the van's payload."
    )
    ambient_c: Annotated[Column | None, NotNull] = absent(
        "Outside temperature at each sample [°C]; absent: the climatology."
    )
    door_openings: list[DoorOpening] = Field(
        default_factory=list,
        max_length=MAX_INTERVALS,
        description="Cargo-door openings, seconds after the first sample.",
    )
    battery_power_w: Annotated[Column | None, NotNull] = absent(
        "Measured battery power at each sample [W]: the mean since the sample before."
    )
    traction_power_w: Annotated[Column | None, NotNull] = absent(
        "Measured drive-train power [W], net of regeneration."
    )
    auxiliaries_power_w: Annotated[Column | None, NotNull] = absent(
        "Measured auxiliaries' power [W]."
    )
    cabin_power_w: Annotated[Column | None, NotNull] = absent("Measured cab HVAC power [W].")
    refrigeration_power_w: Annotated[Column | None, NotNull] = absent(
        "Measured refrigeration unit's power [W]."
    )

    def measured_w(self) -> dict[str, list[float]]:
        """What was measured, by channel."""
        return {c: getattr(self, c) for c in CHANNELS if getattr(self, c) is not None}

    def samples(self) -> int:
        return len(self.time_s)


class CalibrationRequest(VanRequest):
    """The starting van (a preset with overrides, as in plans), what to fit, the trips."""

    payload_kg: Annotated[Annotated[float, Field(ge=0, le=40_000)] | None, NotNull] = absent(
        "The load the measured trips carried [kg] where a trip has no payload_kg column; "
        "preset value if absent. A fact of the trips, not of the van: a profile made from "
        "this calibration keeps its preset's payload."
    )

    parameters: list[FittableName | FitParameter] = Field(
        default_factory=list,
        max_length=len(FITTABLE),
        description="What to fit: names, or {name, min, max} for bounds. Empty: "
        "drag_coefficient (at the given frontal_area_m2: the drag area), "
        "rolling_resistance_coefficient, drivetrain_efficiency, regen_efficiency and "
        "auxiliaries_power_w, and when the refrigeration is measured "
        "wall_heat_transfer_w_m2k and cop.",
    )
    trips: list[TripRequest] = Field(
        ..., min_length=1, max_length=MAX_TRIPS, description="The measured trips."
    )

    def fit_parameters(self) -> list[FitParameter]:
        return [p if isinstance(p, FitParameter) else FitParameter(name=p) for p in self.parameters]


class FittedParameterOut(ApiModel, FittedParameter):
    """One fitted parameter."""


class TripFitOut(ApiModel, TripFit):
    """How the fitted model follows one trip."""


class ValidationOut(ApiModel):
    """The model predicting trips it was not fitted to."""

    method: str = Field(
        ..., description="validation trips, k-fold cross-validation, or none (a single trip)."
    )
    trips: list[TripFitOut] = Field(..., description="Each predicted trip.")


class CalibrationResponse(ApiModel):
    """The fit."""

    id: str = Field(..., description="The calibration's identifier (a UUID).")
    parameters: dict[str, FittedParameterOut] = Field(..., description="Each fitted parameter.")
    trips: list[TripFitOut] = Field(..., description="Each fitted trip.")
    validation: ValidationOut = Field(..., description="Trips it was not fitted to.")
    vehicle: dict[str, float] = Field(
        ..., description="The fitted values by parameter name, ready as vehicle overrides."
    )
    cargo_box: dict[str, float] = Field(
        ..., description="The fitted box values by parameter name, as cargo_box overrides."
    )
    warnings: list[str] = Field(..., description="What the data could not tell apart.")
