"""Parameter models: one definition of every parameter, with its unit, bounds and default.

The models are frozen pydantic models so that the web layer reuses them directly: Swagger shows
exactly what Python users see. Defaults are the paper's Table 1 where it gives a value; every
other default is ours and its field description says where it comes from.

Constructing a model directly from Python with a bad value raises
:class:`core.exceptions.InvalidParameterError` naming the field and the rule. (When the web
layer validates a request, pydantic's own error with the full field path is used instead.)
"""

from __future__ import annotations

import datetime as dt
import re
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Annotated, Any, Literal

from pydantic import (
    AwareDatetime,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PlainSerializer,
    ValidationError,
    ValidationInfo,
    WithJsonSchema,
    field_validator,
)
from pydantic_core import InitErrorDetails, PydanticCustomError

from core.exceptions import InvalidParameterError


def _iso_text(value: Any) -> Any:
    """Dates and times come as ISO 8601 text (or as Python's own objects), never as numbers."""
    if isinstance(value, str | dt.date | dt.time):
        return value
    raise ValueError("expected ISO 8601 text")


#: A calendar date from ISO text ("2026-07-15"); see :data:`IsoDateTime`.
IsoDate = Annotated[dt.date, BeforeValidator(_iso_text), Field(strict=False)]
#: An instant with its UTC offset from ISO text ("2026-07-15T09:00:00+02:00").
IsoDateTime = Annotated[AwareDatetime, BeforeValidator(_iso_text), Field(strict=False)]

#: A local clock time as the API writes it: HH:MM, 00:00–23:59.
HHMM_PATTERN = r"^([01]\d|2[0-3]):[0-5]\d$"


def clock_time(value: Any) -> dt.time:
    """``"09:30"`` → ``time(9, 30)``; a :class:`datetime.time` passes as it is."""
    if isinstance(value, dt.time):
        return value
    if isinstance(value, str) and re.fullmatch(HHMM_PATTERN, value):
        hour, minute = (int(part) for part in value.split(":"))
        return dt.time(hour, minute)
    raise ValueError("expected a local clock time HH:MM (00:00–23:59)")


#: A local clock time from "HH:MM" text.
ClockTime = Annotated[
    dt.time,
    BeforeValidator(clock_time),
    Field(strict=False),
    WithJsonSchema({"type": "string", "pattern": HHMM_PATTERN}),
    PlainSerializer(lambda value: value.strftime("%H:%M"), return_type=str),
]

#: Standard gravity [m/s²] (CGPM 1901).
GRAVITY_MPS2 = 9.80665
#: Duration of the New European Driving Cycle [s] (UNECE R83/R101), the paper's t_NEDC.
NEDC_DURATION_S = 1180.0


def describe_validation_error(error: ValidationError, prefix: str = "") -> str:
    """One line per pydantic error: ``field.path: rule``."""
    parts = []
    for item in error.errors():
        path = ".".join(str(p) for p in (prefix, *item["loc"]) if p != "")
        parts.append(f"{path or 'input'}: {item['msg']}")
    return "; ".join(parts)


_INSIDE_VALIDATION: ContextVar[bool] = ContextVar("coldroute_inside_validation", default=False)


@contextmanager
def inside_validation() -> Iterator[None]:
    """Mark a larger model's validation: nested parameter models then keep pydantic's own
    error, with its full field path, for the outer model to report."""
    token = _INSIDE_VALIDATION.set(True)
    try:
        yield
    finally:
        _INSIDE_VALIDATION.reset(token)


class Params(BaseModel):
    """Base of every parameter model: frozen, no unknown fields, no NaN or infinity."""

    # Strict: no number from a string or a boolean (JSON clients get what the schema says);
    # dates and times still come from their ISO text (strict=False on those fields).
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False, strict=True)

    def __init__(self, **data: Any) -> None:
        if _INSIDE_VALIDATION.get():
            super().__init__(**data)
            return
        try:
            with inside_validation():
                super().__init__(**data)
        except ValidationError as error:
            first = error.errors()[0]["loc"]
            raise InvalidParameterError(
                describe_validation_error(error, type(self).__name__),
                field=".".join(str(p) for p in first) or None,
            ) from None


class VehicleParams(Params):
    """The van: longitudinal dynamics (paper §2.1) and the cab's consumers (§2.3)."""

    mass_kg: float = Field(
        1680.0, gt=0, le=40_000, description="Empty vehicle mass incl. driver [kg] (Table 1 m)."
    )
    drag_coefficient: float = Field(
        0.329, gt=0, le=2, description="Aerodynamic drag coefficient c_d [–] (Table 1)."
    )
    frontal_area_m2: float = Field(
        4.27, gt=0, le=20, description="Frontal area A_f [m²] (Table 1)."
    )
    rolling_resistance_coefficient: float = Field(
        0.012, ge=0, le=0.1, description="Rolling-resistance coefficient c_r [–] (Table 1)."
    )
    rolling_resistance_factor: float = Field(
        1.25,
        gt=0,
        le=3,
        description="Factor on m·g·c_r in the rolling force [–]; 1.25 is the paper's eq. 4.",
    )
    drivetrain_efficiency: float = Field(
        0.85,
        ge=0.1,
        le=1,
        description="Battery-to-wheel efficiency when motoring η_el [–] (eq. 7); 0.85 is the "
        "typical BEV figure NREL FASTSim uses.",
    )
    regen_efficiency: float = Field(
        0.6,
        ge=0,
        le=1,
        description="Share of braking power at the wheels returned to the battery [–]; "
        "0 disables regeneration. 0.6 is a conservative van figure (FASTSim's Zoe: 0.773).",
    )
    max_regen_power_w: float | None = Field(
        None, gt=0, le=1_000_000, description="Cap on regenerated electric power [W]; none if null."
    )
    max_motor_power_w: float | None = Field(
        None,
        gt=0,
        le=1_000_000,
        description="Cap on the drive's mechanical power at the wheels [W]; none if null (the "
        "paper's model). A trace that asks for more is followed as closely as the cap allows: "
        "the van falls behind and catches up, so no energy is lost or invented.",
    )
    max_acceleration_mps2: float = Field(
        2.0,
        ge=0.1,
        le=10,
        description="Maximum acceleration v̇_max [m/s²] (§2.2); 2.0 ≈ 0–100 km/h in 14 s.",
    )
    air_density_kg_m3: float = Field(
        1.2, gt=0, le=2, description="Air density ρ for drag [kg/m³] (eq. 3); 1.2 at 20 °C."
    )
    auxiliaries_power_w: float = Field(
        400.0,
        ge=0,
        le=20_000,
        description="Constant auxiliaries (lights, radio, controls) [W]; 400 is the paper's §2.3.",
    )
    cabin_hvac_enabled: bool = Field(
        True, description="Heat or cool the cab to 20 °C (paper Table 2); false switches it off."
    )
    cab_hvac_at_stops: Literal["on", "off", "reduced"] = Field(
        "on",
        description="Cab heating/air conditioning while parked at a stop: 'on' holds 20 °C (the "
        "paper's assumption), 'off' lets the cab drift towards the outside air, 'reduced' runs at "
        "cab_reduced_share of the power. After the stop the HVAC brings the cab back to 20 °C.",
    )
    cab_reduced_share: float = Field(
        0.5,
        ge=0,
        le=1,
        description="Share of the Table 2 power the cab HVAC draws while parked in 'reduced' [–].",
    )
    cab_recovery_energy_j_k: float = Field(
        60_000.0,
        gt=0,
        le=1_000_000,
        description="Electric energy to move the cab's temperature by one kelvin [J/K]: its "
        "thermal mass (air ≈ 4 kJ/K plus seats, dashboard and trim) over a heater efficiency of "
        "1. With the Table 2 power it sets how fast a parked cab drifts (time constant = this "
        "value × |20 °C − outside| / Table 2 power).",
    )
    cab_hvac_max_power_w: float = Field(
        6000.0,
        gt=0,
        le=50_000,
        description="Most electric power of the cab HVAC [W]: how fast it brings the cab back "
        "after a stop or a departure with a cold or hot cab.",
    )


class CargoBoxParams(Params):
    """The insulated cargo box and its refrigeration unit (paper §3)."""

    volume_m3: float = Field(8.0, ge=0.1, le=100, description="Inner volume V [m³] (Table 1).")
    wall_heat_transfer_w_m2k: float = Field(
        2.172,
        gt=0,
        le=20,
        description="Wall heat-transfer coefficient α [W/(m²·K)] (Table 1, eq. 11).",
    )
    roof_area_m2: float = Field(8.0, gt=0, le=100, description="Roof area A_r [m²] (Table 1).")
    side_area_m2: float = Field(
        4.182, gt=0, le=100, description="Area of one side wall A_s [m²] (Table 1)."
    )
    back_area_m2: float = Field(
        3.12, gt=0, le=100, description="Back wall area A_b [m²] (Table 1)."
    )
    wall_area_m2: float | None = Field(
        None,
        gt=0,
        le=500,
        description="Total heat-transfer area A [m²] (eq. 11); null means 2·(A_r + A_s + A_b).",
    )
    setpoint_c: float = Field(
        4.0, ge=-40, le=25, description="Cargo-air set-point ϑ_CB [°C]; 4 °C for chilled goods."
    )
    cop: float = Field(
        1.5,
        ge=0.1,
        le=10,
        description="Coefficient of performance of the refrigeration unit η_RU [–] (eq. 12), "
        "used when cop_model is 'constant'; 1.5 is typical of small electric units at 30 °C "
        "ambient, chilled box.",
    )
    cop_model: Literal["constant", "carnot"] = Field(
        "constant",
        description="'constant': the paper's η_RU (cop). 'carnot': a fraction of the Carnot COP "
        "between an evaporator below the box and a condenser above the outside air, so the unit "
        "works harder on hot days and for frozen goods (see core.cargo.refrigeration_cop).",
    )
    carnot_fraction: float = Field(
        0.3,
        ge=0.05,
        le=1,
        description="Share of the Carnot COP the unit reaches [–] ('carnot' model). 0.3 is fitted "
        "to the paper's η_RU = 1.5 at 30 °C outside / 4 °C box (COP 1.57) and gives 0.97 at "
        "30 °C / −20 °C, within the 0.5–1.5 that Tassou, De-Lille & Ge (2009, Appl. Therm. Eng. "
        "29) report for transport units.",
    )
    evaporator_approach_k: float = Field(
        10.0, ge=0, le=40, description="Evaporator below the box air [K] ('carnot' model)."
    )
    condenser_approach_k: float = Field(
        15.0, ge=0, le=40, description="Condenser above the outside air [K] ('carnot' model)."
    )
    standby_power_w: float = Field(
        0.0,
        ge=0,
        le=5000,
        description="Draw of the unit's controls and evaporator fans whenever it runs [W]; 0 in "
        "the paper.",
    )
    structure_heat_capacity_j_k: float = Field(
        190_000.0,
        gt=0,
        le=10_000_000,
        description="Heat capacity of the box structure that follows the cargo air [J/K]: the "
        "inner GRP liner (2 mm, 1850 kg/m³, 1000 J/(kg·K)) and half the polyurethane foam "
        "(80 mm, 40 kg/m³, 1500 J/(kg·K)) over the 30.6 m² of the paper's box ≈ 187 kJ/K. "
        "Dynamic mode, and the pull-down of a box that was not pre-cooled.",
    )
    solar_absorptivity: float = Field(
        0.3,
        ge=0,
        le=1,
        description="Solar absorptivity of the box's outer surface [–]; 0.3 for white paint.",
    )
    outside_film_coefficient_w_m2k: float = Field(
        22.7,
        gt=0,
        le=200,
        description="Outside surface film coefficient h_o [W/(m²·K)]: the share α/h_o of the "
        "absorbed sun that crosses the wall (sol-air method, ASHRAE Fundamentals ch. 18).",
    )
    shadow_factor: float = Field(
        0.8,
        ge=0,
        le=1,
        description="Shadow factor b_sh [–] (eq. 17); 1 is full sun, 0.8 a partly shaded street.",
    )
    door_width_m: float = Field(1.2, gt=0, le=5, description="Door opening width W [m].")
    door_height_m: float = Field(1.5, gt=0, le=5, description="Door opening height H [m].")
    doorway_flow_factor: float = Field(
        0.25,
        gt=0,
        le=1.5,
        description="Doorway flow factor D_f [–] of the Gosney–Olama infiltration model, "
        "calibrated so that 10 min open at 30 K costs about two hours of wall gain of an "
        "ATP-class box (≈0.7 kWh; see core.cargo).",
    )
    curtain_effectiveness: float = Field(
        0.0, ge=0, lt=1, description="Effectiveness E of a door curtain [–]; strips ≈ 0.9."
    )
    cargo_specific_heat_j_kgk: float = Field(
        2300.0,
        gt=0,
        le=10_000,
        description="Specific heat of the cargo c_p [J/(kg·K)] (Table 1: 2.3 kJ/(kg·K)).",
    )
    mode: Literal["steady", "dynamic"] = Field(
        "steady",
        description="'steady': the paper's assumption, box at set-point, unit covers every load. "
        "'dynamic': box temperature integrated with a finite unit capacity.",
    )
    refrigeration_capacity_w: float = Field(
        3000.0,
        gt=0,
        le=100_000,
        description="Cooling capacity of the unit Q_0,max [W] (dynamic mode only).",
    )
    product_limit_c: float = Field(
        7.0,
        ge=-40,
        le=40,
        description="Highest cargo-air temperature the product tolerates [°C] (dynamic mode).",
    )
    heater_enabled: bool = Field(
        False,
        description="When the box loses heat (outside colder than the set-point), heat it to hold "
        "the set-point (chilled produce must not freeze). The paper's van has no heater.",
    )
    heating_cop: float = Field(
        1.0,
        ge=0.5,
        le=6,
        description="Heat delivered per electric energy when the box is heated [–]: 1 for an "
        "electric or hot-gas heater, 2–3 for a reversible heat pump.",
    )
    heating_capacity_w: float = Field(
        2000.0,
        gt=0,
        le=100_000,
        description="Most heat the box heater delivers [W] (dynamic mode only).",
    )

    @field_validator("product_limit_c")
    @classmethod
    def _limit_above_setpoint(cls, value: float, info: ValidationInfo) -> float:
        if "setpoint_c" in info.data and value <= info.data["setpoint_c"]:
            raise ValueError("product_limit_c must be above setpoint_c")
        return value

    @property
    def heat_transfer_area_m2(self) -> float:
        """Wall area A [m²] used in eq. 11."""
        if self.wall_area_m2 is not None:
            return self.wall_area_m2
        return 2.0 * (self.roof_area_m2 + self.side_area_m2 + self.back_area_m2)


#: Smallest usable state-of-charge window ``initial_soc − min_soc`` [–].
MIN_SOC_WINDOW = 0.01


class BatteryParams(Params):
    """Traction battery as seen by the energy balance."""

    usable_capacity_kwh: float = Field(
        40.0, ge=0.1, le=2000, description="Usable battery capacity [kWh]."
    )
    initial_soc: float = Field(1.0, gt=0, le=1, description="State of charge at departure [–].")
    min_soc: float = Field(
        0.1, ge=0, lt=1, description="Reserve: lowest acceptable state of charge [–]."
    )
    temperature_derating: bool = Field(
        False,
        description="Derate the battery in cold and heat: less usable energy and more energy per "
        "km of every consumer, from AAA's 2019 dynamometer tests of five EVs with HVAC off "
        "(see core.battery). False: the paper's temperature-independent battery.",
    )
    charging_efficiency: float = Field(
        0.9,
        ge=0.5,
        le=1,
        description="Energy stored per energy drawn from the grid when charging [–]; sets the "
        "energy to recharge at the plug.",
    )

    @field_validator("min_soc")
    @classmethod
    def _reserve_below_start(cls, value: float, info: ValidationInfo) -> float:
        if "initial_soc" in info.data and value > info.data["initial_soc"] - MIN_SOC_WINDOW:
            raise ValueError(f"min_soc must be at least {MIN_SOC_WINDOW} below initial_soc")
        return value


class Weather(Params):
    """Daily extremes of the ambient temperature (paper §3.1); t_min_c must not exceed t_max_c."""

    t_min_c: float = Field(
        ..., ge=-60, le=60, description="Lowest temperature of the day [°C]; at most t_max_c."
    )
    t_max_c: float = Field(
        ..., ge=-60, le=60, description="Highest temperature of the day [°C]; at least t_min_c."
    )

    @field_validator("t_max_c")
    @classmethod
    def _ordered(cls, value: float, info: ValidationInfo) -> float:
        if "t_min_c" in info.data and info.data["t_min_c"] > value:
            raise ValueError("t_min_c must not exceed t_max_c")
        return value


class Location(Params):
    """A point on the Earth (WGS 84)."""

    lat: float = Field(..., ge=-90, le=90, description="Latitude [°], north positive.")
    lon: float = Field(..., ge=-180, le=180, description="Longitude [°], east positive.")


class Interval(Params):
    """A span of time within a simulated trace."""

    start_s: float = Field(..., ge=0, description="Start, seconds after the trace start [s].")
    duration_s: float = Field(..., ge=0, le=86_400, description="How long it lasts [s].")


class DoorOpening(Interval):
    """One opening of the cargo door during a simulated trace."""

    duration_s: float = Field(..., ge=0, le=86_400, description="How long it stays open [s].")


class StreetType(Params):
    """Shape of the generated speed trace on one kind of street (paper §2.2)."""

    mean_speed_mps: float = Field(..., gt=0, le=60, description="Mean speed v̄ [m/s].")
    speed_variation: float = Field(
        ..., ge=0, le=1, description="Relative amplitude dv of the trapezoid [–]."
    )
    period_divisor: float = Field(
        ..., gt=0, le=1000, description="k in t_p = t_NEDC / k [–]: more k, shorter waves."
    )
    traffic_density: float = Field(
        ..., gt=0, lt=1, description="Default traffic density ε_t on this street type [–]."
    )


#: Street-type presets. Mean speeds are typical free-flow averages (urban with lights,
#: rural highway, motorway); the shape parameters are tuned so that a calm and an aggressive
#: driver differ by the paper's 10–12 % on an urban leg (tests/core/test_cycles.py).
STREET_TYPES: dict[str, StreetType] = {
    "urban": StreetType(
        mean_speed_mps=30 / 3.6, speed_variation=0.8, period_divisor=16, traffic_density=0.5
    ),
    "highway": StreetType(
        mean_speed_mps=70 / 3.6, speed_variation=0.3, period_divisor=8, traffic_density=0.3
    ),
    "expressway": StreetType(
        mean_speed_mps=100 / 3.6, speed_variation=0.15, period_divisor=4, traffic_density=0.2
    ),
}
StreetTypeName = Literal["urban", "highway", "expressway"]

#: Driver aggressiveness ε_d of a calm and of an aggressive driver (paper §2.2, Fig. 9).
CALM_DRIVER = 0.2
NORMAL_DRIVER = 0.5
AGGRESSIVE_DRIVER = 1.0


class VanParams(Params):
    """Everything about the van that a simulation needs."""

    vehicle: VehicleParams = Field(
        default_factory=VehicleParams, description="Longitudinal dynamics and cab consumers."
    )
    cargo_box: CargoBoxParams = Field(
        default_factory=CargoBoxParams, description="Cargo box and refrigeration unit."
    )
    battery: BatteryParams = Field(default_factory=BatteryParams, description="Traction battery.")
    payload_kg: float = Field(
        550.0, ge=0, le=40_000, description="Payload at departure [kg] (Table 1: 550 kg)."
    )
    precondition_at_depot: bool = Field(
        True,
        description="Bring the cab to 20 °C and the box structure to its set-point on grid power "
        "before departure (reported as grid_kwh, not taken from the battery). False: the van "
        "leaves with the cab and the box structure at the outside temperature and the battery "
        "pays for the pull-down.",
    )


class Preset(VanParams):
    """A named, complete set of van parameters."""

    name: str = Field(..., description="Preset identifier.")
    description: str = Field(..., description="What the preset represents and where it is from.")

    def van(self) -> VanParams:
        """The preset's parameters without its name and description."""
        return VanParams(**{name: getattr(self, name) for name in VanParams.model_fields})


PRESETS: dict[str, Preset] = {
    "paper-generic": Preset(
        name="paper-generic",
        description="The paper's generic refrigerated e-van (Table 1: 1680 kg + 550 kg payload, "
        "c_d 0.329, c_r 0.012, A_f 4.27 m², 8 m³ box, α 2.172 W/(m²·K)); a 40 kWh usable battery.",
    ),
    "reference-zoe": Preset(
        name="reference-zoe",
        description="NREL FASTSim's 2022 Renault Zoe ZE50 R135 as a longitudinal model (the "
        "validation vehicle of shared/reference/cycles/REFERENCE.md): 1600 kg, c_d 0.33, "
        "A_f 2.5122 m², c_r 0.009 with no 1.25 factor, regeneration 0.773, 52 kWh.",
        vehicle=VehicleParams(
            mass_kg=1600.0,
            drag_coefficient=0.33,
            frontal_area_m2=2.5122,
            rolling_resistance_coefficient=0.009,
            rolling_resistance_factor=1.0,
            drivetrain_efficiency=0.85,
            regen_efficiency=0.773,
            air_density_kg_m3=1.2,
            auxiliaries_power_w=250.0,
            cabin_hvac_enabled=False,
        ),
        battery=BatteryParams(usable_capacity_kwh=52.0),
        payload_kg=0.0,
    ),
    "ev-van-3.5t-reefer": Preset(
        name="ev-van-3.5t-reefer",
        description="A 3.5 t battery-electric large panel van converted to a chilled reefer, from "
        "published data of the class (68 kWh usable, 317 km WLTP, 135 kW motor; high roof, drag "
        "area c_d·A_f = 0.34 × 4.5 m²; light-truck tyres of EU label class B, c_r 0.0065): "
        "2,900 kg with driver, insulation kit and unit (the bare van's WLTP test mass is about "
        "2,450 kg), 500 kg payload; a 9.5 m³ ATP 'IR' box (K = 0.35 W/(m²·K) ≤ 0.4) with an "
        "inverter-driven electric unit (2.5 kW cooling, 1.5 kW heating, 150 W standby, COP a "
        "Carnot fraction), strip curtain; cab HVAC off at stops; battery derated in the cold; "
        "pre-conditioned at the depot. Validated in tests/core/test_presets.py: WLTC 3b at the "
        "plug 215–250 Wh/km, refrigeration 1–3 kW at 30 °C / 4 °C, 10 min of open door ≈ 2 h "
        "of wall gain.",
        vehicle=VehicleParams(
            mass_kg=2900.0,
            drag_coefficient=0.34,
            frontal_area_m2=4.5,
            rolling_resistance_coefficient=0.0065,
            rolling_resistance_factor=1.0,
            drivetrain_efficiency=0.9,
            regen_efficiency=0.8,
            max_regen_power_w=70_000.0,
            max_motor_power_w=135_000.0,
            max_acceleration_mps2=1.8,
            auxiliaries_power_w=400.0,
            cab_hvac_at_stops="off",
        ),
        cargo_box=CargoBoxParams(
            volume_m3=9.5,
            wall_heat_transfer_w_m2k=0.35,
            roof_area_m2=5.6,
            side_area_m2=5.8,
            back_area_m2=2.8,
            door_width_m=1.4,
            door_height_m=1.6,
            curtain_effectiveness=0.4,
            mode="dynamic",
            refrigeration_capacity_w=2500.0,
            cop_model="carnot",
            standby_power_w=150.0,
            structure_heat_capacity_j_k=173_000.0,
            heater_enabled=True,
            heating_capacity_w=1500.0,
        ),
        battery=BatteryParams(usable_capacity_kwh=68.0, temperature_derating=True),
        payload_kg=500.0,
    ),
}
DEFAULT_PRESET = "paper-generic"


def get_preset(name: str) -> Preset:
    """The preset called ``name``; raises :class:`InvalidParameterError` if unknown."""
    try:
        return PRESETS[name]
    except KeyError:
        known = ", ".join(sorted(PRESETS))
        raise InvalidParameterError(
            f"unknown preset '{name}'; known presets: {known}", field="preset"
        ) from None


class Depot(Params):
    """Where the round starts and ends."""

    id: str = Field("depot", min_length=1, max_length=64, description="Identifier of the depot.")
    lat: float = Field(..., ge=-90, le=90, description="Latitude [°], north positive.")
    lon: float = Field(..., ge=-180, le=180, description="Longitude [°], east positive.")
    elevation_m: float | None = Field(
        None, ge=-500, le=9000, description="Elevation above sea level [m]; gives leg grades."
    )


class TimeWindow(Params):
    """When a stop takes deliveries, local time on the round's date: service starts inside."""

    start: ClockTime = Field(..., description="Opens, local HH:MM.")
    end: ClockTime = Field(..., description="Closes, local HH:MM; after start.")

    @field_validator("end")
    @classmethod
    def _after_start(cls, value: dt.time, info: ValidationInfo) -> dt.time:
        if "start" in info.data and value <= info.data["start"]:
            raise ValueError("end must be after start")
        return value


#: Most time windows of one stop.
MAX_TIME_WINDOWS = 8


class Stop(Depot):
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

    @field_validator("door_open_s")
    @classmethod
    def _door_within_service(cls, value: float, info: ValidationInfo) -> float:
        if "service_time_s" in info.data and value > info.data["service_time_s"]:
            raise ValueError("door_open_s must not exceed service_time_s")
        return value


#: Longest leg a matrix may hold: 100,000 km and 30 days (beyond, the numbers are mistakes).
MAX_MATRIX_DISTANCE_M = 1e8
MAX_MATRIX_DURATION_S = 30 * 86_400.0


class RoadMatrix(Params):
    """Distances and durations from the client's road router: depot first, then the stops in
    request order."""

    distances_m: list[list[Annotated[float, Field(ge=0, le=MAX_MATRIX_DISTANCE_M)]]] = Field(
        ..., description="Road distance of each pair [m], 0–100,000 km."
    )
    durations_s: list[list[Annotated[float, Field(ge=0, le=MAX_MATRIX_DURATION_S)]]] = Field(
        ..., description="Driving time of each pair [s], 0–30 days."
    )
    street_types: list[list[StreetTypeName]] | None = Field(
        None, description="Street type of each pair; null chooses by leg length."
    )


Objective = Literal["distance", "duration", "energy"]
