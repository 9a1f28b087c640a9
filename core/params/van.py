"""The van: longitudinal dynamics and the cab (paper §2.1, §2.3), the cargo box and its
refrigeration unit (§3), the traction battery."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, ValidationError, ValidationInfo, field_validator, model_validator
from pydantic_core import InitErrorDetails, PydanticCustomError

from core.exceptions import InvalidParameterError
from core.params.base import Params
from core.params.product import PRODUCT_CLASSES, Celsius, Product, ProductBand, product_band


class VehicleParams(Params):
    """The van: longitudinal dynamics (paper §2.1) and the cab's consumers (§2.3)."""

    mass_kg: float = Field(
        1680.0,
        ge=100,
        le=40_000,
        description="Empty vehicle mass incl. driver [kg] (Table 1 m); at least 100 kg.",
    )
    gross_mass_kg: float | None = Field(
        None,
        ge=100,
        le=60_000,
        description="Technically permissible maximum laden mass (gross vehicle weight) [kg]: "
        "mass_kg plus payload_kg may not exceed it; null: not checked.",
    )
    drag_coefficient: float = Field(
        0.329,
        ge=0.05,
        le=2,
        description="Aerodynamic drag coefficient c_d [–] (Table 1); at least 0.05.",
    )
    frontal_area_m2: float = Field(
        4.27, ge=0.5, le=20, description="Frontal area A_f [m²] (Table 1); at least 0.5 m²."
    )
    rolling_resistance_coefficient: float = Field(
        0.012, ge=0, le=0.1, description="Rolling-resistance coefficient c_r [–] (Table 1)."
    )
    rolling_resistance_factor: float = Field(
        1.25,
        ge=0.1,
        le=3,
        description="Factor on m·g·c_r in the rolling force [–]; 1.25 is the paper's eq. 4; at "
        "least 0.1.",
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
    max_regen_deceleration_mps2: float | None = Field(
        0.98,
        ge=0.1,
        le=10,
        description="Deceleration the motor alone brakes with when it regenerates [m/s²]: 0.1 g, "
        "what lifting off the accelerator gives in an electric van's usual regeneration mode. "
        "Braking harder blends in the friction brakes, whose share is heat, not charge — why an "
        "aggressive driver, who brakes hard, regenerates less of it than a calm one. None: every "
        "braking regenerates (the paper's model; FASTSim's Zoe).",
    )
    max_regen_power_w: float | None = Field(
        None,
        ge=1,
        le=1_000_000,
        description="Cap on regenerated electric power [W]; none if null; at least 1 W.",
    )
    max_motor_power_w: float | None = Field(
        None,
        ge=1000,
        le=1_000_000,
        description="Cap on the drive's mechanical power at the wheels [W]; none if null (the "
        "paper's model). A trace that asks for more is driven as the cap allows: the van "
        "accelerates and climbs more slowly and the leg takes longer (the plan's times follow); "
        "the energy is delivered later, never dropped. At least 1 kW: less would not move a van.",
    )
    max_acceleration_mps2: float = Field(
        2.0,
        ge=0.1,
        le=10,
        description="Maximum acceleration v̇_max [m/s²] (§2.2); 2.0 ≈ 0–100 km/h in 14 s.",
    )
    air_density_kg_m3: float = Field(
        1.2,
        ge=0.5,
        le=2,
        description="Air density ρ for drag [kg/m³] (eq. 3); 1.2 at 20 °C; at least 0.5 kg/m³ (the "
        "air at 5,500 m).",
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
        ge=1000,
        le=1_000_000,
        description="Electric energy to move the cab's temperature by one kelvin [J/K]: its "
        "thermal mass (air ≈ 4 kJ/K plus seats, dashboard and trim) over a heater efficiency of "
        "1. With the Table 2 power it sets how fast a parked cab drifts (time constant = this "
        "value × |20 °C − outside| / Table 2 power); at least 1 kJ/K.",
    )
    cab_hvac_max_power_w: float = Field(
        6000.0,
        ge=100,
        le=50_000,
        description="Most electric power of the cab HVAC [W]: how fast it brings the cab back "
        "after a stop or a departure with a cold or hot cab; at least 100 W.",
    )

    @field_validator("gross_mass_kg")
    @classmethod
    def _gross_above_empty(cls, value: float | None, info: ValidationInfo) -> float | None:
        mass = info.data.get("mass_kg")
        if value is not None and mass is not None and value < mass:
            raise ValueError(f"gross_mass_kg must be at least mass_kg ({mass:g} kg)")
        return value


class BoxGeometry(Params):
    """The insulated box's size and walls (paper §3, Table 1)."""

    volume_m3: float = Field(8.0, ge=0.1, le=100, description="Inner volume V [m³] (Table 1).")
    wall_heat_transfer_w_m2k: float = Field(
        2.172,
        ge=0.01,
        le=20,
        description="Wall heat-transfer coefficient α [W/(m²·K)] (Table 1, eq. 11); at least 0.01 "
        "W/(m²·K), far below the best vacuum-panel boxes.",
    )
    roof_area_m2: float = Field(
        8.0, ge=0.01, le=100, description="Roof area A_r [m²] (Table 1); at least 0.01 m²."
    )
    side_area_m2: float = Field(
        4.182,
        ge=0.01,
        le=100,
        description="Area of one side wall A_s [m²] (Table 1); at least 0.01 m².",
    )
    back_area_m2: float = Field(
        3.12, ge=0.01, le=100, description="Back wall area A_b [m²] (Table 1); at least 0.01 m²."
    )
    wall_area_m2: float | None = Field(
        None,
        ge=0.1,
        le=500,
        description="Total heat-transfer area A [m²] (eq. 11); null means 2·(A_r + A_s + A_b); at "
        "least 0.1 m².",
    )

    @property
    def heat_transfer_area_m2(self) -> float:
        """Wall area A [m²] used in eq. 11."""
        if self.wall_area_m2 is not None:
            return self.wall_area_m2
        return 2.0 * (self.roof_area_m2 + self.side_area_m2 + self.back_area_m2)


class SwitchingUnit(Params):
    """How a fixed-speed (on-off) unit switches: its thermostat's differential and its
    shortest run and pause."""

    differential_k: float = Field(
        2.0,
        ge=0.2,
        le=10,
        description="An on-off unit's switching differential [K]: on at the set-point plus "
        "half of it, off at the set-point less half.",
    )
    min_on_minutes: float = Field(
        3.0, ge=0, le=120, description="An on-off unit's shortest run [min] (compressor wear)."
    )
    min_off_minutes: float = Field(
        3.0,
        ge=0,
        le=120,
        description="An on-off unit's shortest pause [min] (pressures equalise before a start).",
    )


class CargoBoxParams(BoxGeometry, SwitchingUnit):
    """The insulated cargo box, its goods and its refrigeration unit (paper §3)."""

    product: Product | None = Field(
        None,
        description="What the box carries: a class with its legal band (frozen, ice-cream: "
        "Directive 89/108/EEC and ATP Annex 2; the chilled classes: ATP Annex 3), or a band "
        "{min_c, max_c, excursion_c}. Given: the goods' own temperature is simulated beside the "
        "air's and each plan says whether the cold chain holds. Null: the air alone, as before.",
    )
    load_temperature_c: Celsius | None = Field(
        None,
        ge=-40,
        le=40,
        description="The goods' temperature when loaded [°C]; null: the product band's middle.",
    )
    product_conductance_w_kgk: float = Field(
        0.16,
        ge=0.001,
        le=10,
        description="Heat between the box air and the goods per kelvin and kg of goods "
        "[W/(kg·K)]: with the goods' specific heat it sets how fast they follow the air "
        "(2,300 J/(kg·K) / 0.16 ≈ 4 h, the half-cooling times of packaged foods in a moving "
        "air stream, ASHRAE Handbook — Refrigeration ch. 20).",
    )
    setpoint_c: float = Field(
        4.0,
        ge=-40,
        le=25,
        description="Cargo-air set-point ϑ_CB [°C]; 4 °C for chilled goods. With a product and "
        "no set-point: the product band's middle; inside the band.",
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
        "works harder on hot days and for frozen goods (see core.physics.cargo.refrigeration_cop).",
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
        description="Draw of the unit's controls and evaporator fans while it runs (cools or "
        "heats) [W], released in the box as heat the unit removes in turn; nothing while it is "
        "off. 0 in the paper.",
    )
    capacity_box_slope_per_k: float = Field(
        0.022,
        ge=0,
        le=0.05,
        description="Share of its rated capacity the unit gains per kelvin of box air above the "
        "rating's 0 °C [1/K] (dynamic mode): its compressor pumps denser vapour from a warmer "
        "evaporator. 0.022 puts −20 °C at 56 % of the 0 °C rating, as small van units' ATP "
        "ratings at 30 °C outside show (ATP Annex 1 Appendix 2 rates units at 30 °C "
        "outside, 0 °C and −20 °C inside); 0: a constant capacity.",
    )
    capacity_ambient_slope_per_k: float = Field(
        0.01,
        ge=0,
        le=0.05,
        description="Share of its rated capacity the unit loses per kelvin of outside air above "
        "the rating's 30 °C [1/K] (dynamic mode): a hotter condenser; about 1 %/K for "
        "reciprocating and scroll compressors (Stoecker & Jones, Refrigeration and Air "
        "Conditioning, ch. 12).",
    )
    min_modulation: float = Field(
        0.3,
        ge=0,
        le=1,
        description="Least share of its capacity a 'variable' unit runs at [–] (dynamic mode); "
        "below it the compressor cycles on and off and loses cycling_degradation. 0: an "
        "inverter that modulates to nothing.",
    )
    cycling_degradation: float = Field(
        0.25,
        ge=0,
        le=0.5,
        description="Degradation coefficient C_D of a compressor cycling on and off [–] "
        "(dynamic mode): at a run-time fraction x it draws its full power over x but "
        "delivers only PLF = 1 − C_D·(1 − x) of its capacity, the refrigerant redistributing "
        "at each start; 0.25 is AHRI 210/240's default. An 'on-off' unit loses it as a "
        "start-up ramp of time constant C_D·0.8·360 s (AHRI's cyclic test, 6 min on and 24 "
        "off). 0: no cycling losses.",
    )
    structure_heat_capacity_j_k: float = Field(
        190_000.0,
        ge=1000,
        le=10_000_000,
        description="Heat capacity of the box structure that follows the cargo air [J/K]: the "
        "inner GRP liner (2 mm, 1850 kg/m³, 1000 J/(kg·K)) and half the polyurethane foam "
        "(80 mm, 40 kg/m³, 1500 J/(kg·K)) over the 30.6 m² of the paper's box ≈ 187 kJ/K. "
        "Dynamic mode, and the pull-down of a box that was not pre-cooled; at least 1 kJ/K.",
    )
    solar_absorptivity: float = Field(
        0.3,
        ge=0,
        le=1,
        description="Solar absorptivity of the box's outer surface [–]; 0.3 for white paint.",
    )
    outside_film_coefficient_w_m2k: float = Field(
        22.7,
        ge=1,
        le=200,
        description="Outside surface film coefficient h_o [W/(m²·K)]: the share α/h_o of the "
        "absorbed sun that crosses the wall (sol-air method, ASHRAE Fundamentals ch. 18); at least "
        "1 W/(m²·K).",
    )
    shadow_factor: float = Field(
        0.8,
        ge=0,
        le=1,
        description="Shadow factor b_sh [–] (eq. 17); 1 is full sun, 0.8 a partly shaded street.",
    )
    door_width_m: float = Field(
        1.2, ge=0.1, le=5, description="Door opening width W [m]; at least 0.1 m."
    )
    door_height_m: float = Field(
        1.5, ge=0.1, le=5, description="Door opening height H [m]; at least 0.1 m."
    )
    doorway_flow_factor: float = Field(
        0.25,
        ge=0.01,
        le=1.5,
        description="Doorway flow factor D_f [–] of the Gosney–Olama infiltration model, "
        "calibrated so that 10 min open at 30 K costs about two hours of wall gain of an "
        "ATP-class box (≈0.7 kWh; see core.physics.cargo); at least 0.01.",
    )
    curtain_effectiveness: float = Field(
        0.0, ge=0, lt=1, description="Effectiveness E of a door curtain [–]; strips ≈ 0.9."
    )
    cargo_specific_heat_j_kgk: float = Field(
        2300.0,
        ge=100,
        le=10_000,
        description="Specific heat of the cargo c_p [J/(kg·K)] (Table 1: 2.3 kJ/(kg·K)); at least "
        "100 J/(kg·K).",
    )
    mode: Literal["steady", "dynamic"] = Field(
        "steady",
        description="'steady': the paper's assumption, box at set-point, unit covers every load. "
        "'dynamic': box temperature integrated with a finite unit capacity.",
    )
    refrigeration_capacity_w: float = Field(
        3000.0,
        ge=10,
        le=100_000,
        description="Cooling capacity of the unit Q_0,max [W] (dynamic mode only) at ATP's "
        "rating conditions, 0 °C in the box and 30 °C outside; it varies with both "
        "(capacity_box_slope_per_k, capacity_ambient_slope_per_k). At least 10 W.",
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
        ge=10,
        le=100_000,
        description="Most heat the box heater delivers [W] (dynamic mode only); at least 10 W.",
    )
    control: Literal["variable", "on-off"] = Field(
        "variable",
        description="How the unit's compressor runs: 'variable' (an inverter: any power up to "
        "refrigeration_capacity_w), or 'on-off' (a fixed-speed unit: full capacity or none, "
        "switched by a thermostat with differential_k, each run and each pause at least "
        "min_on_minutes and min_off_minutes). 'on-off' needs the dynamic mode and a product.",
    )

    @classmethod
    def changed_values(cls, current: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
        """A product changed without a set-point takes its band's (:meth:`_setpoint_of_product`),
        not the preset's."""
        if changes.get("product") is not None and "setpoint_c" not in changes:
            current = {k: v for k, v in current.items() if k != "setpoint_c"}
        return current | changes

    @model_validator(mode="before")
    @classmethod
    def _setpoint_of_product(cls, data: Any) -> Any:
        """The set-point a product's band implies when the request gives none."""
        if isinstance(data, dict) and "setpoint_c" not in data:
            product = data.get("product")
            band = PRODUCT_CLASSES.get(product) if isinstance(product, str) else None
            if isinstance(product, ProductBand):
                band = product
            elif isinstance(product, dict):
                low, high = product.get("min_c"), product.get("max_c")
                if isinstance(low, int | float) and isinstance(high, int | float):
                    return data | {"setpoint_c": 0.5 * (low + high)}
            if band is not None:
                return data | {"setpoint_c": band.middle_c}
        return data

    @field_validator("setpoint_c")
    @classmethod
    def _setpoint_in_band(cls, value: float, info: ValidationInfo) -> float:
        product = info.data.get("product")
        if product is not None:
            band = product_band(product)
            if not band.min_c <= value <= band.max_c:
                raise ValueError(
                    f"setpoint_c must be inside the product's band, {band.min_c:g} to "
                    f"{band.max_c:g} °C"
                )
        return value

    @field_validator("control")
    @classmethod
    def _on_off_needs_a_capacity(cls, value: str, info: ValidationInfo) -> str:
        data = info.data
        if value == "on-off" and (data.get("mode") != "dynamic" or data.get("product") is None):
            raise ValueError(
                "control 'on-off' needs mode 'dynamic' (a finite capacity to switch) and a "
                "product (the two-node box it is simulated in)"
            )
        return value

    def check_day(self, day_s: float) -> None:
        """An error naming ``min_on_minutes`` when an on-off unit's shortest run is longer
        than the day of ``day_s`` [s]: a strategy the unit cannot follow."""
        if self.control == "on-off" and self.min_on_minutes * 60.0 > day_s:
            raise InvalidParameterError(
                f"an on-off unit cannot follow a day of {day_s / 60:.0f} min with a shortest "
                f"run of {self.min_on_minutes:g} min",
                "cargo_box.min_on_minutes",
            )

    @property
    def band(self) -> ProductBand | None:
        """The product's band (None: no product)."""
        return None if self.product is None else product_band(self.product)

    @property
    def load_c(self) -> float:
        """The goods' temperature when loaded [°C]."""
        if self.load_temperature_c is not None:
            return self.load_temperature_c
        band = self.band
        return self.setpoint_c if band is None else band.middle_c

    @field_validator("product_limit_c")
    @classmethod
    def _limit_above_setpoint(cls, value: float, info: ValidationInfo) -> float:
        if "setpoint_c" in info.data and value <= info.data["setpoint_c"]:
            raise ValueError("product_limit_c must be above setpoint_c")
        return value


#: Smallest usable state-of-charge window ``initial_soc − min_soc`` [–].
MIN_SOC_WINDOW = 0.01


class ChargingPoint(Params):
    """One point of a charging curve: the power the battery takes at a state of charge."""

    soc: float = Field(..., ge=0, le=1, description="State of charge [–], 0–1.")
    power_kw: float = Field(
        ...,
        ge=0.1,
        le=1000,
        description="Charging power drawn from the charger here [kW], at least 0.1 kW.",
    )


#: Where the default charging curve begins to taper [–] and the share of the van's maximum
#: power it reaches at full: lithium-ion cells charge at constant current to about 80 %,
#: then at constant voltage with a falling current (CC-CV).
TAPER_SOC = 0.8
FULL_POWER_SHARE = 0.2


def _point_error(k: int, name: str, rule: str, value: float) -> None:
    """Raise the rule a charging curve's point ``k`` breaks, located at its field ``name``."""
    error = PydanticCustomError("charging_curve", rule, {"previous": k - 1, "value": f"{value:g}"})
    raise ValidationError.from_exception_data(
        "ChargingPoint", [InitErrorDetails(type=error, loc=(k, name), input=None)]
    )


class BatteryParams(Params):
    """Traction battery as seen by the energy balance."""

    usable_capacity_kwh: float = Field(
        40.0, ge=0.1, le=2000, description="Usable battery capacity [kWh]."
    )
    initial_soc: float = Field(1.0, ge=0.01, le=1, description="State of charge at departure [–].")
    min_soc: float = Field(
        0.1, ge=0, lt=1, description="Reserve: lowest acceptable state of charge [–]."
    )
    temperature_derating: bool = Field(
        False,
        description="Derate the battery in cold and heat: less usable energy and more energy per "
        "km of every consumer, from AAA's 2019 dynamometer tests of five EVs with HVAC off "
        "(see core.physics.battery). False: the paper's temperature-independent battery.",
    )
    charging_efficiency: float = Field(
        0.9,
        ge=0.5,
        le=1,
        description="Energy stored per energy drawn from the grid when charging [–]; sets the "
        "energy to recharge at the plug.",
    )
    max_charge_power_kw: float = Field(
        50.0,
        ge=1,
        le=1000,
        description="Most power the van takes from a charger [kW], at least 1 kW (its on-board "
        "AC charger or its DC inlet); caps every charger and the charging curve.",
    )
    charging_curve: list[ChargingPoint] | None = Field(
        None,
        min_length=2,
        max_length=50,
        description="Charging power by state of charge: points of `soc` (increasing) and "
        "`power_kw` (non-increasing), linear between, the first point's power below it and "
        "the last's above. Null: max_charge_power_kw up to 80 % (CC), then falling linearly "
        "to 20 % of it at full (CV).",
    )
    charge_to_full: bool = Field(
        False,
        description="Charge to full at every charge. False: charge what the rest of the day "
        "needs, with its reserve and a margin (partial recharge).",
    )

    @field_validator("charging_curve")
    @classmethod
    def _curve_tapers(cls, value: list[ChargingPoint] | None) -> list[ChargingPoint] | None:
        for k in range(1, len(value or ())):
            previous, point = value[k - 1], value[k]  # type: ignore[index]
            if point.soc <= previous.soc:
                _point_error(k, "soc", "must be above point {previous}'s ({value})", previous.soc)
            if point.power_kw > previous.power_kw:
                _point_error(
                    k,
                    "power_kw",
                    "must not be above point {previous}'s ({value}): the charging power does "
                    "not rise with the soc",
                    previous.power_kw,
                )
        return value

    @field_validator("min_soc")
    @classmethod
    def _reserve_below_start(cls, value: float, info: ValidationInfo) -> float:
        if "initial_soc" in info.data and value > info.data["initial_soc"] - MIN_SOC_WINDOW:
            raise ValueError(f"min_soc must be at least {MIN_SOC_WINDOW} below initial_soc")
        return value


class RefrigerationStrategy(Params):
    """How the refrigeration unit is run through the day."""

    strategy: Literal["thermostat", "optimal"] = Field(
        "thermostat",
        description="'thermostat': the unit holds the air at its set-point. 'optimal': the air "
        "set-point through the day that draws the least battery energy (or costs least) with "
        "the goods inside their band at every moment, planned with the route (pre-cooling at "
        "the depot on grid power, the air let float within the band, cooling while plugged "
        "in), then simulated; needs cargo_box.product.",
    )
    objective: Literal["energy", "cost"] = Field(
        "energy",
        description="What the optimal strategy spares: 'energy', the battery's (the grid's, "
        "while plugged in or before departure, counts a tenth); 'cost', the money — the "
        "battery's kWh at the depot's price over the charging efficiency (refilled there), "
        "the grid's at the price where the van is plugged in (depot_price_per_kwh, the "
        "chargers' price_per_kwh).",
    )
    depot_price_per_kwh: float | None = Field(
        None,
        ge=0,
        le=100,
        description="The depot's price of energy [per kWh] for the 'cost' objective: "
        "pre-cooling there, and refilling the battery. Absent: the depot charger's "
        "price_per_kwh (plans), required otherwise.",
    )
    precool_minutes: float = Field(
        60.0,
        ge=0,
        le=240,
        description="Minutes plugged in at the depot before departure the optimal strategy may "
        "cool the box and the goods on grid power (a van that leaves the depot); it does where "
        "the simulated day, followed with and without them, costs less by its objective.",
    )

    def priced(self, depot_price_per_kwh: float | None) -> RefrigerationStrategy:
        """The strategy with the depot's price when it has none of its own; the 'cost'
        objective without a price above 0 is an error naming ``objective``."""
        price = self.depot_price_per_kwh
        price = depot_price_per_kwh if price is None else price
        if self.objective == "cost" and not price:
            raise InvalidParameterError(
                "objective 'cost' needs a price above 0: refrigeration.depot_price_per_kwh "
                "or the depot charger's price_per_kwh",
                "refrigeration.objective",
            )
        return self.model_copy(update={"depot_price_per_kwh": price})


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
    refrigeration: RefrigerationStrategy = Field(
        default_factory=RefrigerationStrategy,
        description="How the refrigeration unit is run: a thermostat, or the optimal schedule.",
    )

    def priced(self, depot_price_per_kwh: float | None) -> VanParams:
        """The van with the depot's price of energy for its refrigeration's objective
        (:meth:`RefrigerationStrategy.priced`)."""
        return self.model_copy(
            update={"refrigeration": self.refrigeration.priced(depot_price_per_kwh)}
        )

    @field_validator("payload_kg")
    @classmethod
    def _within_gross_mass(cls, value: float, info: ValidationInfo) -> float:
        vehicle = info.data.get("vehicle")
        if vehicle is not None and vehicle.gross_mass_kg is not None:
            rated = vehicle.gross_mass_kg - vehicle.mass_kg
            if value > rated:
                raise ValueError(
                    f"payload_kg must be at most the van's rated payload, {rated:g} kg "
                    f"(vehicle.gross_mass_kg {vehicle.gross_mass_kg:g} less vehicle.mass_kg "
                    f"{vehicle.mass_kg:g})"
                )
        return value

    @field_validator("refrigeration")
    @classmethod
    def _optimal_needs_a_band(
        cls, value: RefrigerationStrategy, info: ValidationInfo
    ) -> RefrigerationStrategy:
        box = info.data.get("cargo_box")
        if value.strategy == "optimal" and box is not None and box.product is None:
            raise ValueError(
                "strategy 'optimal' needs cargo_box.product: the band it keeps the goods in"
            )
        return value
