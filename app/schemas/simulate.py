"""POST /v1/simulate: one speed trace, and its energy."""

from __future__ import annotations

from typing import Annotated, Self

from pydantic import ConfigDict, Field, ValidationError, model_validator
from pydantic_core import InitErrorDetails, PydanticCustomError

from app.schemas.base import (
    ApiModel,
    BatteryOut,
    BoxOut,
    ColdChainOut,
    ConsumptionWhPerKm,
    EnergyKwh,
    NotNull,
    PowerSeries,
    VanRequest,
    WeatherOut,
    absent,
)
from core.params import (
    MAX_INTERVALS,
    MAX_TRACE_SAMPLES,
    NORMAL_DRIVER,
    DoorOpening,
    Interval,
    IsoDateTime,
    Location,
    SetpointSpan,
    StreetTypeName,
    TrafficDensity,
    Weather,
)

#: A trace's samples: the first bad one is named (a million strings are one error, not a
#: million).
Samples = Field(max_length=MAX_TRACE_SAMPLES, fail_fast=True)
Trace = Annotated[list[float], Samples, Field(min_length=2)]


class CycleRequest(ApiModel):
    """Generate a speed trace (paper §2.2) instead of sending one."""

    street_type: StreetTypeName = Field("urban", description="Street type preset.")
    distance_m: float = Field(..., ge=1, le=1_000_000, description="Distance [m], 1 m–1000 km.")
    driver_aggressiveness: float = Field(NORMAL_DRIVER, ge=0, le=1, description="ε_d [–].")
    traffic_density: TrafficDensity | None = Field(None, description="ε_t [–], 0.01–0.99.")


class SimulateRequest(VanRequest):
    """One trace: either ``speed_mps`` with ``dt_s`` or a ``cycle`` to generate."""

    model_config = ConfigDict(
        json_schema_extra={"oneOf": [{"required": ["speed_mps"]}, {"required": ["cycle"]}]}
    )

    speed_mps: Annotated[Annotated[list[float], Samples, Field(min_length=2)] | None, NotNull] = (
        absent("Speed samples [m/s], 0–69.4, every dt_s seconds, at least 2; give this or cycle.")
    )
    dt_s: float = Field(1.0, ge=0.01, le=3600, description="Sampling interval [s].")
    grade: float | Annotated[list[float], Samples] = Field(
        0.0, description="Road grade [–], one number or one per sample, within ±0.5."
    )
    cycle: Annotated[CycleRequest | None, NotNull] = absent(
        "Generate the trace from a street type instead; give this or speed_mps."
    )
    start: IsoDateTime = Field(..., description="Start time, ISO 8601 with UTC offset.")
    location: Location = Field(..., description="Where the van drives (sun, climatology).")
    weather: Weather | None = Field(
        None,
        description="The day's extremes; absent: the weather service's hourly forecast when "
        "the server has one, else the climatology for date and latitude.",
    )
    door_openings: list[DoorOpening] = Field(
        default_factory=list,
        max_length=MAX_INTERVALS,
        description="Cargo-door openings, seconds after the start.",
    )
    parked: list[Interval] = Field(
        default_factory=list,
        max_length=MAX_INTERVALS,
        description="When the van stands at a stop, seconds after the start: the cab HVAC's "
        "duty while parked (vehicle.cab_hvac_at_stops).",
    )
    air_setpoints: list[SetpointSpan] = Field(
        default_factory=list,
        max_length=MAX_INTERVALS,
        description="A refrigeration schedule to replay instead of the strategy: the air "
        "set-point from start_s for duration_s, seconds after the start, in time order and "
        "not overlapping (a plan's refrigeration.schedule, against the day as it went: its "
        "doors, its weather); outside the spans the unit holds cargo_box.setpoint_c. Needs "
        "cargo_box.product and the thermostat strategy.",
    )
    include_series: bool = Field(False, description="Return the time series too.")

    @model_validator(mode="after")
    def _one_trace(self) -> Self:
        if (self.speed_mps is None) == (self.cycle is None):
            # Named on a field: cycle when both came, speed_mps when neither did.
            field = "cycle" if self.cycle is not None else "speed_mps"
            rule = PydanticCustomError("one_of", "give exactly one of speed_mps and cycle")
            raise ValidationError.from_exception_data(
                type(self).__name__, [InitErrorDetails(type=rule, loc=(field,), input=None)]
            )
        return self


class Series(ApiModel):
    """Time series at the trace's samples."""

    time_s: list[float] = Field(..., description="Seconds since the start [s].")
    speed_mps: list[float] = Field(..., description="Speed at each sample [m/s].")
    power_w: PowerSeries = Field(
        ..., description="Each consumer's mean power over the step ending at each sample [W]."
    )
    soc: list[float] = Field(..., description="State of charge at each sample [–].")
    air_temperature_c: list[float] = Field(
        default_factory=list,
        description="The box air at each sample [°C] (steady box: the set-point; the first "
        "sample's is the first step's).",
    )
    air_setpoint_c: list[float] = Field(
        default_factory=list,
        description="The air set-point the unit followed at each sample [°C] (the optimal "
        "strategy's schedule; else cargo_box.setpoint_c).",
    )
    product_temperature_c: list[float | None] | None = Field(
        None,
        description="The goods at each sample [°C], null while none are aboard; null without "
        "a product in cargo_box.",
    )


class SimulateResponse(ApiModel):
    """Energy of one trace."""

    distance_m: float = Field(..., description="Distance of the trace [m].")
    duration_s: float = Field(..., description="Duration of the trace [s].")
    energy_kwh: EnergyKwh = Field(..., description="Energy of each consumer [kWh].")
    consumption_wh_per_km: ConsumptionWhPerKm = Field(
        ..., description="Energy per km of each consumer [Wh/km]."
    )
    battery: BatteryOut = Field(..., description="Whether the battery holds out with its reserve.")
    weather: WeatherOut = Field(..., description="The weather the trace was simulated with.")
    box: BoxOut = Field(..., description="Cargo-box temperatures (dynamic mode).")
    cold_chain: ColdChainOut | None = Field(
        None,
        description="Whether the goods stayed inside their product band (cargo_box.product); "
        "null: the box has no product.",
    )
    series: Series | None = Field(None, description="The time series, when include_series is true.")
    grid_kwh: float = Field(
        0.0, description="Energy from the grid to pre-condition cab and box before the start."
    )
    warnings: list[str] = Field(
        default_factory=list, description="What the simulation had to do without."
    )
