"""Request and response models of the HTTP API. Parameters reuse the core's definitions."""

from __future__ import annotations

import datetime as dt
from typing import TYPE_CHECKING, Annotated, Any, Literal, Optional, Self, get_args

from pydantic import (
    AwareDatetime,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ModelWrapValidatorHandler,
    ValidationError,
    ValidationInfo,
    create_model,
    field_validator,
    model_validator,
)
from pydantic_core import InitErrorDetails, PydanticCustomError

from core.exceptions import InvalidParameterError
from core.fleet import MAX_VEHICLES, UnassignedReason, shift_in_order
from core.geo import DistanceSource
from core.params import (
    DEFAULT_PRESET,
    HHMM_PATTERN,
    NORMAL_DRIVER,
    BatteryParams,
    CargoBoxParams,
    ClockTime,
    Depot,
    DoorOpening,
    Interval,
    IsoDate,
    IsoDateTime,
    Location,
    Objective,
    Params,
    Preset,
    RoadMatrix,
    Stop,
    StreetTypeName,
    VanParams,
    VehicleParams,
    Weather,
    get_preset,
    inside_validation,
)
from core.studies import Season
from core.tsp import SolverStatus
from core.weather import WeatherSource


class ApiModel(BaseModel):
    """Base of the API's own models: no unknown fields, no NaN or infinity."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True)

    @model_validator(mode="wrap")
    @classmethod
    def _keep_field_paths(cls, data: Any, handler: ModelWrapValidatorHandler[Any]) -> Any:
        # Nested core parameter models report pydantic's errors with their full path.
        with inside_validation():
            return handler(data)


def _refuse_null(value: Any) -> Any:
    if value is None:
        raise ValueError("null is not allowed here; leave the field out to keep the default")
    return value


def _schema_without_null(schema: dict[str, Any]) -> None:
    """The JSON schema of an optional field that may be absent but not null."""
    variants = schema.pop("anyOf", None)
    if variants is not None:
        kept = [v for v in variants if v.get("type") != "null"]
        if len(kept) == 1:
            schema.update(kept[0])
        else:
            schema["anyOf"] = kept
    schema.pop("default", None)


#: On a ``T | None`` field: it may be left out (None in Python) but, when given, is not null —
#: as its schema (:func:`absent`) says.
NotNull = BeforeValidator(_refuse_null)


def absent_or(annotation: Any) -> Any:
    """``Annotated[T | None, NotNull]`` for a type built at run time."""
    return Annotated[Optional[annotation], NotNull]  # noqa: UP045 (a run-time type)


def absent(description: str, **constraints: Any) -> Any:
    """The Field of an :func:`absent_or` field."""
    return Field(
        None, description=description, json_schema_extra=_schema_without_null, **constraints
    )


def _overrides(name: str, params: type[Params], doc: str, **extra: Any) -> type[ApiModel]:
    """A model with every field of ``params`` optional: the values to change in a preset.

    Each field keeps the core's type, bounds and description, so Swagger shows exactly the
    parameter the core uses. Absent means the preset's value; null is allowed only where the
    core's parameter itself may be null (``max_regen_power_w``: no cap), and means that.
    """
    fields: dict[str, Any] = dict(extra)
    for field_name, info in params.model_fields.items():
        default = info.get_default(call_default_factory=True)
        annotation: Any = (
            Annotated[(info.annotation, *info.metadata)] if info.metadata else info.annotation
        )
        description = f"{info.description} Preset value if absent (paper-generic: {default})."
        nullable = type(None) in get_args(info.annotation)
        if nullable:
            fields[field_name] = (annotation, Field(None, description=description))
        else:
            fields[field_name] = (absent_or(annotation), absent(description))
    return create_model(name, __base__=ApiModel, __doc__=doc, **fields)


if TYPE_CHECKING:  # the request models are built at run time from the core's parameters
    VehicleRequest = ApiModel
    CargoBoxRequest = ApiModel
    BatteryRequest = ApiModel
else:
    VehicleRequest = _overrides(
        "VehicleRequest",
        VehicleParams,
        "The van: a preset and any parameter to change in it.",
        preset=(
            str,
            Field(
                DEFAULT_PRESET,
                min_length=1,
                max_length=64,
                description="Preset name (GET /v1/presets).",
            ),
        ),
    )
    CargoBoxRequest = _overrides(
        "CargoBoxRequest",
        CargoBoxParams,
        "Cargo box and refrigeration unit: changes to the preset.",
    )
    BatteryRequest = _overrides("BatteryRequest", BatteryParams, "Battery: changes to the preset.")


class VanRequest(ApiModel):
    """The parts of a request that describe the van (shared by plans, simulation, studies)."""

    vehicle: VehicleRequest = Field(
        default_factory=VehicleRequest,
        description="The van: a preset (vehicle.preset) and any vehicle parameter to change.",
    )
    cargo_box: CargoBoxRequest = Field(
        default_factory=CargoBoxRequest,
        description="Cargo box and refrigeration unit: the parameters to change in the preset.",
    )
    battery: BatteryRequest = Field(
        default_factory=BatteryRequest,
        description="Battery: the parameters to change in the preset.",
    )
    payload_kg: Annotated[Annotated[float, Field(ge=0, le=40_000)] | None, NotNull] = absent(
        "Payload at departure [kg]; preset value if absent."
    )
    precondition_at_depot: Annotated[bool | None, NotNull] = absent(
        f"{VanParams.model_fields['precondition_at_depot'].description} Preset value if absent."
    )

    def van(self) -> VanParams:
        """The preset with this request's changes applied, validated by the core models; an
        error names the request section (``cargo_box.setpoint_c``)."""
        try:
            preset: Preset = get_preset(getattr(self.vehicle, "preset"))  # noqa: B009
        except InvalidParameterError as error:
            raise InvalidParameterError(error.message, "vehicle.preset") from None
        sections = {
            "vehicle": (VehicleParams, preset.vehicle),
            "cargo_box": (CargoBoxParams, preset.cargo_box),
            "battery": (BatteryParams, preset.battery),
        }
        built: dict[str, Any] = {}
        details: list[tuple[str, str]] = []
        for section, (model, base) in sections.items():
            changes: ApiModel = getattr(self, section)
            wanted = {k: getattr(changes, k) for k in changes.model_fields_set if k != "preset"}
            try:
                with inside_validation():  # pydantic's own errors, one per field
                    built[section] = model(**(base.model_dump() | wanted))
            except ValidationError as error:
                for item in error.errors():
                    path = ".".join(str(p) for p in item["loc"])
                    details.append((f"{section}.{path}" if path else section, item["msg"]))
        if details:
            message = "; ".join(f"{field}: {rule}" for field, rule in details)
            raise InvalidParameterError(message, details[0][0], details)
        payload = preset.payload_kg if self.payload_kg is None else self.payload_kg
        precondition = (
            preset.precondition_at_depot
            if self.precondition_at_depot is None
            else self.precondition_at_depot
        )
        return VanParams(**built, payload_kg=payload, precondition_at_depot=precondition)


class RoundRequest(ApiModel):
    """What a plan and a fleet plan share: the day, the places and the conditions."""

    date: IsoDate = Field(..., description="Day of the round, YYYY-MM-DD.")
    timezone: str | None = Field(
        None,
        max_length=64,
        description="IANA time zone (Europe/Vienna); absent: local mean solar time at the depot.",
    )
    depot: Depot = Field(..., description="Where the round starts and ends.")
    stops: list[Stop] = Field(..., min_length=1, description="The stops, in any order.")
    weather: Weather | None = Field(
        None, description="The day's forecast; absent: the climatology for date and latitude."
    )
    driver_aggressiveness: float = Field(
        NORMAL_DRIVER, ge=0, le=1, description="ε_d [–]: 0.2 calm, 0.5 normal, 1 aggressive."
    )
    traffic_density: float | None = Field(
        None, gt=0, lt=1, description="ε_t [–]; absent: the street type's default."
    )
    objective: Objective = Field("distance", description="What the tour minimises.")
    matrix: RoadMatrix | None = Field(
        None, description="Road distances/durations from your router: depot first, then stops."
    )
    time_limit_s: float = Field(
        1.0, gt=0, le=600, description="Solver budget [s], capped by the server's setting."
    )
    include_geometry: bool = Field(
        False,
        description="Return each leg's road as a GeoJSON LineString in legs[].geometry (the "
        "router's road with OSRM, else the straight line).",
    )


class PlanRequest(VanRequest, RoundRequest):
    """A delivery round to plan: depot, stops, date, van and conditions. Stops with
    time_windows are served inside them (the van waits when early); when no order can, the
    answer is a 422 naming the stop that cannot be reached in time."""

    start_time: str = Field(
        "08:00",
        pattern=HHMM_PATTERN,
        description="Departure, local HH:MM (with time windows: the earliest; the van leaves "
        "later when the first stop's window opens later).",
    )
    keep_order: bool = Field(False, description="Drive the stops in the given order.")


class EnergyKwh(ApiModel):
    """Electric energy per consumer [kWh]."""

    traction: float = Field(..., description="Drive train, net of regeneration [kWh].")
    auxiliaries: float = Field(..., description="Lights, radio, controls [kWh].")
    cabin: float = Field(..., description="Cab heating / air conditioning [kWh].")
    refrigeration: float = Field(..., description="Refrigeration unit and box heater [kWh].")
    total: float = Field(..., description="Sum of the consumers [kWh].")


class EnergyShare(ApiModel):
    """Each consumer's share of the total energy [–]."""

    traction: float = Field(..., description="Drive train's share of the total [–].")
    auxiliaries: float = Field(..., description="Auxiliaries' share of the total [–].")
    cabin: float = Field(..., description="Cab HVAC's share of the total [–].")
    refrigeration: float = Field(..., description="Refrigeration unit's share of the total [–].")


class LineString(ApiModel):
    """A GeoJSON LineString (RFC 7946): positions as [longitude, latitude]."""

    type: Literal["LineString"] = Field("LineString", description="Always LineString.")
    coordinates: list[tuple[float, float]] = Field(
        ..., description="Positions [lon, lat] in degrees (WGS 84)."
    )


class Point(ApiModel):
    """A GeoJSON Point (RFC 7946)."""

    type: Literal["Point"] = Field("Point", description="Always Point.")
    coordinates: tuple[float, float] = Field(..., description="[lon, lat] in degrees (WGS 84).")


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


class BatteryOut(ApiModel):
    """Whether the battery holds out with its reserve."""

    feasible: bool = Field(
        ..., description="True when the state of charge never falls below the reserve (min_soc)."
    )
    min_soc: float = Field(..., description="Lowest state of charge [–].")
    final_soc: float = Field(..., description="State of charge at the end [–].")
    margin_kwh: float = Field(..., description="Energy above the reserve at the lowest point.")
    required_capacity_kwh: float = Field(..., description="Smallest usable capacity that works.")
    usable_capacity_kwh: float | None = Field(
        None, description="Usable capacity on the day, after temperature derating [kWh]."
    )
    temperature_loss_kwh: float = Field(
        0.0,
        description="Battery energy beyond the consumers' lost to cold or heat "
        "(temperature derating) [kWh].",
    )
    recharge_kwh: float | None = Field(
        None,
        description="Grid energy to recharge the battery to its initial state of charge [kWh].",
    )
    first_infeasible_leg: int | None = Field(
        None,
        description="Index in legs[] of the leg (or the stop after it) that breaks the "
        "reserve first; null when feasible.",
    )


class DayWeatherOut(ApiModel):
    """One local day's temperatures."""

    date: dt.date = Field(..., description="The local day.")
    t_min_c: float = Field(..., description="Lowest temperature of the day's moments [°C].")
    t_max_c: float = Field(..., description="Highest temperature of the day's moments [°C].")


class WeatherOut(ApiModel):
    """The temperatures used."""

    t_min_c: float = Field(..., description="Lowest temperature of the first day [°C].")
    t_max_c: float = Field(..., description="Highest temperature of the first day [°C].")
    source: WeatherSource = Field(
        ...,
        description="'request' (the request's weather), 'forecast' or 'archive' (the weather "
        "service's hourly data) or 'climatology'.",
    )
    days: list[DayWeatherOut] = Field(
        default_factory=list, description="Each local day of a round, with its own weather."
    )


class BoxOut(ApiModel):
    """Cargo-box temperatures (dynamic mode; null in steady mode)."""

    max_temperature_c: float | None = Field(
        ..., description="Highest cargo-air temperature [°C] (dynamic box; null in steady mode)."
    )
    minutes_above_product_limit: float | None = Field(
        ...,
        description="Time with the cargo air above the product limit [min] (dynamic box; "
        "null in steady mode).",
    )


class SolverOut(ApiModel):
    """How the tour search ended."""

    status: SolverStatus = Field(
        ...,
        description="optimal (proven over all arcs), feasible (the best found in the time "
        "limit) or fixed_order (keep_order).",
    )
    objective: Objective = Field(
        ..., description="What the tour minimised: distance, duration or energy."
    )
    objective_value: float = Field(..., description="Of the tour, in m, s or Wh (estimate).")
    runtime_s: float = Field(..., description="Time the tour search took [s].")


#: Where an answer's distances came from, and the credit owed for its map data.
DistanceSourceOut = Annotated[
    DistanceSource,
    Field(
        description="Where the legs' distances and durations came from: the OSRM router, the "
        "request's matrix, or the great-circle estimate."
    ),
]
AttributionOut = Annotated[
    str | None, Field(description="Credit for the map data the legs were routed on.")
]


class PlanResponse(ApiModel):
    """The planned and simulated round."""

    tour: list[str] = Field(..., description="Ids in driving order, depot first and last.")
    legs: list[LegOut] = Field(..., description="The driven legs, in order.")
    stops: list[StopOut] = Field(..., description="The stops, in visiting order.")
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


class FleetVehicleRequest(VanRequest):
    """One van of the fleet: the van exactly as in /v1/plans (a preset and the parameters to
    change) and its driver's shift."""

    id: str = Field(
        ..., min_length=1, max_length=64, description="Identifier of the van, unique in the fleet."
    )
    shift_start: ClockTime = Field(
        dt.time(8, 0), description="Earliest departure from the depot, local HH:MM."
    )
    shift_end: ClockTime = Field(
        dt.time(18, 0),
        description="Latest return to the depot, local HH:MM, after shift_start (same day).",
    )

    @field_validator("shift_end")
    @classmethod
    def _after_start(cls, value: dt.time, info: ValidationInfo) -> dt.time:
        return shift_in_order(info.data.get("shift_start"), value)


class FleetPlanRequest(RoundRequest):
    """The day's stops and the fleet that serves them from one depot."""

    vehicles: list[FleetVehicleRequest] = Field(
        ...,
        min_length=1,
        max_length=MAX_VEHICLES,
        description="The vans that may drive, each with its van, battery, payload and shift; "
        "those listed first drive first when as good.",
    )
    minimize_vehicles: bool = Field(
        True, description="Fewer vans first, then the objective; false: the objective alone."
    )
    time_limit_s: float = Field(
        5.0, gt=0, le=600, description="Solver budget [s], capped by the server's setting."
    )


class FleetRouteOut(PlanResponse):
    """The planned and simulated day of one van, as a /v1/plans answer, with the van's id."""

    vehicle_id: str = Field(..., description="The van that drives this route.")


class UnassignedOut(ApiModel):
    """A stop no van serves."""

    id: str = Field(..., description="The stop's id.")
    reason: UnassignedReason = Field(
        ...,
        description="time_window (no van reaches it inside a window), capacity (no payload "
        "left or too heavy), battery (the charge would fall below a reserve), shift (no van "
        "back in time) or unreachable (no road).",
    )
    detail: str = Field(..., description="Why, in a sentence.")


class FleetTotals(ApiModel):
    """Every route of the fleet together."""

    distance_m: float = Field(..., description="Distance driven by every van [m].")
    duration_s: float = Field(
        ..., description="Sum of each van's time from departure to return [s]."
    )
    energy_kwh: EnergyKwh = Field(..., description="Energy of each consumer over the fleet [kWh].")
    grid_kwh: float = Field(
        ..., description="Pre-conditioning from the grid at the depot, every van [kWh]."
    )
    vehicles_used: int = Field(..., description="Vans that drive.")


class FleetSolverOut(ApiModel):
    """How the fleet search ended."""

    status: SolverStatus = Field(
        ..., description="feasible: the best found in the time limit (no proof of optimality)."
    )
    objective: Objective = Field(..., description="What the routes minimised.")
    objective_value: float = Field(
        ..., description="Of every route together, in m, s or Wh (estimate)."
    )
    runtime_s: float = Field(..., description="Time the search and the verification took [s].")
    verification_rounds: int = Field(
        ...,
        description="How often the routes were simulated in full; above 1 when a simulation "
        "broke a rule the estimates missed and the fleet was solved again.",
    )


class FleetPlanResponse(ApiModel):
    """The fleet's day: every route verified by the full simulation."""

    routes: list[FleetRouteOut] = Field(
        ...,
        description="One per van that drives, in the order of vehicles[]: everything a "
        "/v1/plans answer holds.",
    )
    unassigned: list[UnassignedOut] = Field(
        ..., description="Stops no van serves, in request order, each with its reason."
    )
    totals: FleetTotals = Field(..., description="Every route together.")
    solver: FleetSolverOut = Field(..., description="How the search ended.")
    timezone: str = Field(..., description="Time zone of the times, or the solar-time note.")
    distance_source: DistanceSourceOut
    warnings: list[str] = Field(
        default_factory=list, description="What the plan had to do without."
    )
    attribution: AttributionOut = None


class Feature(ApiModel):
    """A GeoJSON Feature (RFC 7946)."""

    type: Literal["Feature"] = Field("Feature", description="Always Feature.")
    geometry: Point | LineString = Field(
        ..., description="A stop's Point or a leg's LineString, [lon, lat]."
    )
    properties: dict[str, Any] = Field(..., description="What the feature is, with its figures.")


class PlanFeatureCollection(ApiModel):
    """The plan as a GeoJSON FeatureCollection: the depot and stops as Points (id, arrival,
    door heat, state of charge), the legs as LineStrings (energy per consumer, state of charge
    at both ends)."""

    type: Literal["FeatureCollection"] = Field(
        "FeatureCollection", description="Always FeatureCollection."
    )
    features: list[Feature] = Field(
        ..., description="The depot and the stops (Points), then the legs (LineStrings)."
    )
    attribution: str | None = Field(None, description="Credit for the map data.")


class CycleRequest(ApiModel):
    """Generate a speed trace (paper §2.2) instead of sending one."""

    street_type: StreetTypeName = Field("urban", description="Street type preset.")
    distance_m: float = Field(..., gt=0, le=1_000_000, description="Distance [m].")
    driver_aggressiveness: float = Field(NORMAL_DRIVER, ge=0, le=1, description="ε_d [–].")
    traffic_density: float | None = Field(None, gt=0, lt=1, description="ε_t [–].")


class SimulateRequest(VanRequest):
    """One trace: either ``speed_mps`` with ``dt_s`` or a ``cycle`` to generate."""

    model_config = ConfigDict(
        json_schema_extra={"oneOf": [{"required": ["speed_mps"]}, {"required": ["cycle"]}]}
    )

    speed_mps: Annotated[Annotated[list[float], Field(min_length=2)] | None, NotNull] = absent(
        "Speed samples [m/s], 0–69.4, every dt_s seconds, at least 2; give this or cycle."
    )
    dt_s: float = Field(1.0, ge=0.01, le=3600, description="Sampling interval [s].")
    grade: float | list[float] = Field(
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
        default_factory=list, description="Cargo-door openings, seconds after the start."
    )
    parked: list[Interval] = Field(
        default_factory=list,
        description="When the van stands at a stop, seconds after the start: the cab HVAC's "
        "duty while parked (vehicle.cab_hvac_at_stops).",
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


class SpeedSweepRequest(VanRequest):
    """Constant-speed trips on a flat road at several speeds (paper Fig. 11)."""

    speeds_kmh: list[float] = Field(
        default_factory=lambda: [float(v) for v in range(20, 121, 10)],
        min_length=1,
        max_length=100,
        description="Mean speeds to try [km/h], each in (0, 200].",
    )
    distance_m: float = Field(
        20_000.0, ge=100, le=500_000, description="Trip length [m], at least 100 m."
    )
    date: IsoDate = Field(..., description="Day of the trips, YYYY-MM-DD.")
    start_time: str = Field("12:00", pattern=HHMM_PATTERN, description="Departure, local HH:MM.")
    timezone: str | None = Field(
        None, max_length=64, description="IANA time zone; absent: local mean solar time."
    )
    location: Location = Field(..., description="Where (sun, climatology).")
    weather: Weather | None = Field(
        None, description="The day's forecast; absent: the climatology for date and latitude."
    )
    traffic_density: float | None = Field(None, gt=0, lt=1, description="ε_t [–].")
    driver_aggressiveness: float = Field(
        0.0, ge=0, le=1, description="ε_d [–]; 0 holds each speed exactly (paper Fig. 11)."
    )


class SpeedPointOut(ApiModel):
    """One speed of the sweep."""

    speed_kmh: float = Field(..., description="The trip's mean speed [km/h].")
    energy_wh_per_km: ConsumptionWhPerKm = Field(
        ..., description="Energy per km of each consumer at that speed [Wh/km]."
    )


class SpeedSweepResponse(ApiModel):
    """Energy per km at each speed, and the speed with the lowest total."""

    points: list[SpeedPointOut] = Field(
        ..., description="One point per requested speed, in request order."
    )
    optimum_speed_kmh: float = Field(
        ..., description="The speed with the lowest total energy per km [km/h]."
    )


class ScenariosRequest(ApiModel):
    """One round over seasons × driver aggressiveness × traffic density (paper Figs. 9, 10)."""

    plan: PlanRequest = Field(..., description="The round and its baseline conditions.")
    seasons: list[Season] | None = Field(
        None,
        min_length=1,
        max_length=12,
        description="Absent: winter (15 Jan) and summer (15 Jul) of the plan's year.",
    )
    driver_aggressiveness: list[Annotated[float, Field(ge=0, le=1)]] | None = Field(
        None,
        min_length=1,
        max_length=10,
        description="ε_d values [–]; absent: calm 0.2, normal 0.5, aggressive 1.0.",
    )
    traffic_density: list[Annotated[float, Field(gt=0, lt=1)]] | None = Field(
        None,
        min_length=1,
        max_length=10,
        description="ε_t values [–]; absent: light 0.2, heavy 0.8.",
    )


class ScenarioCellOut(ApiModel):
    """One cell of the grid."""

    season: str = Field(..., description="The season's name.")
    driver_aggressiveness: float = Field(..., description="ε_d of the cell [–].")
    traffic_density: float | None = Field(
        ..., description="ε_t of the cell [–]; null: each street type's default."
    )
    energy_kwh: EnergyKwh = Field(..., description="Energy of each consumer in this cell [kWh].")
    change_vs_baseline_pct: float = Field(..., description="Total energy against the baseline.")
    feasible: bool = Field(..., description="The battery holds out with its reserve.")


class ScenariosResponse(ApiModel):
    """The grid, one row per cell, on the baseline's tour."""

    tour: list[str] = Field(
        ..., description="The baseline's tour, driven in every cell: ids, depot first and last."
    )
    baseline_energy_kwh: EnergyKwh = Field(
        ..., description="Energy of the round in its own conditions [kWh]."
    )
    cells: list[ScenarioCellOut] = Field(
        ..., description="One row per season × driver × traffic combination."
    )


class PowerSeries(ApiModel):
    """Mean power of each consumer over the step ending at each sample [W] (0 at the start)."""

    traction: list[float] = Field(..., description="Drive-train power [W].")
    auxiliaries: list[float] = Field(..., description="Auxiliaries' power [W].")
    cabin: list[float] = Field(..., description="Cab HVAC power [W].")
    refrigeration: list[float] = Field(..., description="Refrigeration unit's power [W].")


class Series(ApiModel):
    """Time series at the trace's samples."""

    time_s: list[float] = Field(..., description="Seconds since the start [s].")
    speed_mps: list[float] = Field(..., description="Speed at each sample [m/s].")
    power_w: PowerSeries = Field(
        ..., description="Each consumer's mean power over the step ending at each sample [W]."
    )
    soc: list[float] = Field(..., description="State of charge at each sample [–].")


class ConsumptionWhPerKm(ApiModel):
    """Energy per distance [Wh/km]; null for a trace that moves less than a metre."""

    traction: float | None = Field(..., description="Drive train [Wh/km].")
    auxiliaries: float | None = Field(..., description="Auxiliaries [Wh/km].")
    cabin: float | None = Field(..., description="Cab HVAC [Wh/km].")
    refrigeration: float | None = Field(..., description="Refrigeration unit [Wh/km].")
    total: float | None = Field(..., description="All consumers [Wh/km].")


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
    series: Series | None = Field(None, description="The time series, when include_series is true.")
    grid_kwh: float = Field(
        0.0, description="Energy from the grid to pre-condition cab and box before the start."
    )
    warnings: list[str] = Field(
        default_factory=list, description="What the simulation had to do without."
    )


class PresetsResponse(ApiModel):
    """Every preset with every value."""

    presets: list[Preset] = Field(..., description="Every preset with every parameter value.")


class FieldError(ApiModel):
    """One offending field."""

    field: str = Field(..., description="Path of the field, like stops[3].lat.")
    message: str = Field(..., description="The rule it breaks.")
    type: str = Field(..., description="Machine-readable error kind.")


class Problem(ApiModel):
    """An error, RFC 9457 (application/problem+json)."""

    type: str = Field(..., description="Problem kind, a relative URI.")
    title: str = Field(..., description="A short summary of the problem kind.")
    status: int = Field(..., description="The HTTP status code.")
    detail: str = Field(..., description="What went wrong, for a person.")
    errors: list[FieldError] | None = Field(None, description="For invalid requests.")


class Health(ApiModel):
    """Liveness."""

    status: Literal["ok"] = Field("ok", description="Always ok: the process answers.")
    version: str = Field(..., description="Version of the service.")


class Check(ApiModel):
    """One dependency of the service."""

    name: str = Field(..., description="workers, database, broker, osrm or weather.")
    ok: bool = Field(..., description="Whether it answered.")
    detail: str = Field(..., description="What was checked, or what went wrong.")
    critical: bool = Field(
        ...,
        description="Whether the service is unready without it (the weather service is not: "
        "plans fall back to the climatology).",
    )


class Readiness(ApiModel):
    """Whether the service can take work, dependency by dependency."""

    status: Literal["ready", "degraded", "unavailable"] = Field(
        ...,
        description="ready; degraded (a non-critical service is down); unavailable (503).",
    )
    checks: list[Check] = Field(..., description="Each dependency's answer.")


JobType = Literal["plan", "fleet-plan", "scenarios"]
#: The request of each job type: the synchronous endpoint's body.
JobRequest = PlanRequest | FleetPlanRequest | ScenariosRequest
JobStatus = Literal["queued", "running", "succeeded", "failed", "cancelled"]


class JobSubmission(ApiModel):
    """A job: the type and the body the synchronous endpoint would take."""

    type: JobType = Field(
        ...,
        description="plan: the body of POST /v1/plans; fleet-plan: of /v1/fleet-plans; "
        "scenarios: of /v1/studies/scenarios.",
    )
    request: dict[str, Any] = Field(
        ...,
        description="The request, exactly as for the synchronous endpoint; validated before "
        "the job is accepted (422 naming request.… otherwise).",
        json_schema_extra={
            "oneOf": [
                {"$ref": "#/components/schemas/PlanRequest"},
                {"$ref": "#/components/schemas/FleetPlanRequest"},
                {"$ref": "#/components/schemas/ScenariosRequest"},
            ]
        },
    )


class JobSummary(ApiModel):
    """A job's state."""

    id: str = Field(..., description="The job's identifier (a UUID).")
    type: JobType = Field(..., description="plan, fleet-plan or scenarios.")
    status: JobStatus = Field(..., description="queued, running, succeeded, failed or cancelled.")
    created_at: AwareDatetime = Field(..., strict=False, description="When it was accepted (UTC).")
    started_at: AwareDatetime | None = Field(
        None, strict=False, description="When its last run began (UTC)."
    )
    finished_at: AwareDatetime | None = Field(
        None, strict=False, description="When it ended (UTC)."
    )
    attempts: int = Field(..., description="Runs so far (a lost worker means another run).")


class JobOut(JobSummary):
    """A job, with its answer once it has one."""

    result: PlanResponse | FleetPlanResponse | ScenariosResponse | None = Field(
        None,
        description="When succeeded: exactly what the synchronous endpoint returns.",
    )
    error: Problem | None = Field(None, description="When failed: why, as a problem document.")


class JobList(ApiModel):
    """Jobs, newest first."""

    jobs: list[JobSummary] = Field(
        ..., description="The jobs, newest first, without their results."
    )
