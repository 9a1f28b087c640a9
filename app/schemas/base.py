"""The API's base model and what every operation's models share: the van's parameters as
changes to a preset (built from the core's parameter models), the consumers' energy, the
battery, weather and box answers, and the problem document."""

from __future__ import annotations

import datetime as dt
from typing import TYPE_CHECKING, Annotated, Any, Literal, Optional, get_args

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ModelWrapValidatorHandler,
    ValidationError,
    create_model,
    model_validator,
)

from core.exceptions import InvalidParameterError
from core.params import (
    DEFAULT_PRESET,
    BatteryParams,
    CargoBoxParams,
    Params,
    RefrigerationStrategy,
    VanParams,
    VehicleParams,
    few_unknown,
    field_path,
    get_preset,
    inside_validation,
    plain_rule,
)
from core.physics.simulate import CONSUMERS
from core.physics.weather import DayWeather, WeatherSource
from core.planning.model import ColdChainResult, RefrigerationResult
from core.routing.geo import DistanceSource


class ApiModel(BaseModel):
    """Base of the API's own models: no unknown fields, no NaN or infinity."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True)

    @model_validator(mode="wrap")
    @classmethod
    def _keep_field_paths(cls, data: Any, handler: ModelWrapValidatorHandler[Any]) -> Any:
        # Nested core parameter models report pydantic's errors with their full path.
        with inside_validation():
            return handler(few_unknown(cls, data))


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


def _not_a_path_step(name: str) -> str:
    if name in (".", ".."):
        raise ValueError(
            f"{name!r} is a step in a URL path, not a name: its URL would not reach it"
        )
    return name


#: A vehicle profile's name: letters, digits, ``.``, ``_`` and ``-``, as in a URL path (not
#: ``.`` or ``..``, which a URL path reads as steps).
ProfileName = Annotated[
    str,
    Field(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9._-]+$"),
    AfterValidator(_not_a_path_step),
]


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
                description="Preset name (GET /v1/presets); not with `profile`.",
            ),
        ),
        profile=(
            absent_or(ProfileName),
            absent(
                "A vehicle profile's name (GET /v1/vehicle-profiles) to start from instead of "
                "a preset; the fields beside it change it for this request only."
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
    refrigeration: Annotated[RefrigerationStrategy | None, NotNull] = absent(
        'How the refrigeration unit is run through the day: {"strategy": "thermostat" | '
        '"optimal", "objective": "energy", "precool_minutes": 60}. Preset value '
        "(the thermostat) if absent."
    )

    def profile(self) -> str | None:
        """The vehicle profile this van starts from (``vehicle.profile``), if any; a preset
        named beside it is a 422."""
        name: str | None = getattr(self.vehicle, "profile")  # noqa: B009
        if name is not None and "preset" in self.vehicle.model_fields_set:
            raise InvalidParameterError("give a preset or a profile, not both", "vehicle.preset")
        return name

    def van(self, profile: VanParams | None = None) -> VanParams:
        """The preset — or ``profile``, the parameters this request starts from otherwise
        (``vehicle.profile``, read by the app from its database) — with this request's
        changes applied, validated by the core models; an error names the request section
        (``cargo_box.setpoint_c``)."""
        if profile is None:
            if self.profile() is not None:
                raise TypeError("a request that names vehicle.profile is built on that profile")
            try:
                profile = get_preset(getattr(self.vehicle, "preset"))  # noqa: B009
            except InvalidParameterError as error:
                raise InvalidParameterError(error.message, "vehicle.preset") from None
        return self._changed(profile)

    def _changed(self, base: VanParams) -> VanParams:
        sections: dict[str, tuple[type[Params], Params]] = {
            "vehicle": (VehicleParams, base.vehicle),
            "cargo_box": (CargoBoxParams, base.cargo_box),
            "battery": (BatteryParams, base.battery),
        }
        built: dict[str, Any] = {}
        details: list[tuple[str, str]] = []
        for section, (model, current) in sections.items():
            changes: ApiModel = getattr(self, section)
            wanted = {
                k: getattr(changes, k)
                for k in changes.model_fields_set
                if k not in ("preset", "profile")
            }
            try:
                with inside_validation():  # pydantic's own errors, one per field
                    built[section] = model(**model.changed_values(current.model_dump(), wanted))
            except ValidationError as error:
                for item in error.errors():
                    path = field_path(item["loc"])
                    details.append((f"{section}.{path}" if path else section, plain_rule(item)))
        if details:
            message = "; ".join(f"{field}: {rule}" for field, rule in details)
            raise InvalidParameterError(message, details[0][0], details)
        payload = base.payload_kg if self.payload_kg is None else self.payload_kg
        precondition = (
            base.precondition_at_depot
            if self.precondition_at_depot is None
            else self.precondition_at_depot
        )
        refrigeration = base.refrigeration if self.refrigeration is None else self.refrigeration
        try:
            with inside_validation():
                return VanParams(
                    **built,
                    payload_kg=payload,
                    precondition_at_depot=precondition,
                    refrigeration=refrigeration,
                )
        except ValidationError as error:
            rules = [(field_path(item["loc"]), plain_rule(item)) for item in error.errors()]
            message = "; ".join(f"{field}: {rule}" for field, rule in rules)
            raise InvalidParameterError(message, rules[0][0], rules) from None


def _per_consumer(
    name: str,
    doc: str,
    value: Any,
    unit: str,
    total: str | None = None,
    label: str = "{what}",
) -> type[ApiModel]:
    """A model with one field per consumer (:data:`core.physics.simulate.CONSUMERS`), each a
    ``value`` in ``unit`` described by ``label``, and ``total`` when it says what the total
    is."""
    fields: dict[str, Any] = {}
    for consumer, what in CONSUMERS.items():
        text = label.format(what=what)
        description = f"{text[0].upper()}{text[1:]} [{unit}]."
        fields[consumer] = (value, Field(..., description=description))
    if total is not None:
        fields["total"] = (value, Field(..., description=f"{total} [{unit}]."))
    return create_model(name, __base__=ApiModel, __doc__=doc, **fields)


if TYPE_CHECKING:  # built at run time from the consumers
    EnergyKwh = ApiModel
    EnergyShare = ApiModel
    PowerSeries = ApiModel
    EnergySeries = ApiModel
    ConsumptionWhPerKm = ApiModel
else:
    EnergyKwh = _per_consumer(
        "EnergyKwh", "Electric energy per consumer [kWh].", float, "kWh", "Sum of the consumers"
    )
    EnergyShare = _per_consumer(
        "EnergyShare",
        "Each consumer's share of the total energy [–].",
        float,
        "–",
        label="share of the total taken by the {what}",
    )
    PowerSeries = _per_consumer(
        "PowerSeries",
        "Mean power of each consumer over the step ending at each sample [W] (0 at the start).",
        list[float],
        "W",
    )
    EnergySeries = _per_consumer(
        "EnergySeries",
        "Energy of each consumer since departure at each moment [kWh].",
        list[float],
        "kWh",
        "Sum of the consumers",
    )
    ConsumptionWhPerKm = _per_consumer(
        "ConsumptionWhPerKm",
        "Energy per distance [Wh/km]; null for a trace that moves less than a metre.",
        float | None,
        "Wh/km",
        "All consumers",
    )


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


class RunsEmptyOut(ApiModel):
    """Where and when the battery would run empty, and the energy it lacks for the day."""

    at: dt.datetime = Field(
        ...,
        description="When the charge reaches 0, local time (by the charge's fall over the "
        "leg or the visit it falls in).",
    )
    where: str = Field(
        ...,
        description="On which leg (\"between 'a' and 'b'\") or at which visit (\"at 'b'\") it "
        "falls to 0.",
    )
    missing_kwh: float = Field(
        ...,
        description="The energy the day needs beyond a full use of the battery [kWh]: −min_soc × "
        "usable_capacity_kwh.",
    )


class BatteryOut(ApiModel):
    """Whether the battery holds out with its reserve."""

    feasible: bool = Field(
        ...,
        description="True when the state of charge never falls below the reserve (min_soc): "
        "min_soc ≥ reserve_soc, margin_kwh ≥ 0. An empty battery is never feasible.",
    )
    min_soc: float = Field(
        ...,
        description="Lowest state of charge [–]. Never clipped: below 0 it is the energy the "
        "battery does not hold, as a share of usable_capacity_kwh (the van would stop where "
        "runs_empty says).",
    )
    reserve_soc: float | None = Field(
        None, description="The reserve the battery was held to: battery.min_soc [–]."
    )
    final_soc: float = Field(..., description="State of charge at the end [–], as min_soc.")
    margin_kwh: float = Field(
        ...,
        description="Energy above the reserve at the lowest point [kWh]: (min_soc − "
        "reserve_soc) × usable_capacity_kwh; negative: the shortfall.",
    )
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
    runs_empty: RunsEmptyOut | None = Field(
        None,
        description="Where and when the battery would run empty and the energy it lacks "
        "(min_soc below 0); null while it holds any charge.",
    )


class DayWeatherOut(ApiModel, DayWeather):
    """One local day's temperatures."""


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


class ColdChainOut(ApiModel, ColdChainResult):
    """Whether the goods stayed inside their band while aboard."""


class RefrigerationOut(ApiModel, RefrigerationResult):
    """How the refrigeration unit ran, and what it drew."""


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
    product_limit_c: float | None = Field(
        None, description="The product's limit the box is held to: cargo_box.product_limit_c [°C]."
    )


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
    errors: list[FieldError] | None = Field(
        None, description="For invalid requests: the offending fields, at most 50."
    )
    errors_omitted: int | None = Field(
        None, description="How many more offending fields there are than errors lists."
    )
    service: str | None = Field(
        None,
        description="For a 503: the service that is down (workers, database, osrm, weather).",
    )
    request_id: str | None = Field(
        None, description="For a 500: the request id the error was logged with."
    )
