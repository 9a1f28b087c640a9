"""Named vans: the paper's generic van, FASTSim's Zoe and a real 3.5 t reefer."""

from __future__ import annotations

from pydantic import Field

from core.exceptions import InvalidParameterError
from core.params.van import BatteryParams, CargoBoxParams, VanParams, VehicleParams


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
        "validation vehicle of docs/validation.md): 1600 kg, c_d 0.33, "
        "A_f 2.5122 m², c_r 0.009 with no 1.25 factor, regeneration 0.773, 52 kWh.",
        vehicle=VehicleParams(
            mass_kg=1600.0,
            drag_coefficient=0.33,
            frontal_area_m2=2.5122,
            rolling_resistance_coefficient=0.009,
            rolling_resistance_factor=1.0,
            drivetrain_efficiency=0.85,
            regen_efficiency=0.773,
            max_regen_deceleration_mps2=None,
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
        "area c_d·A_f = 0.34 × 4.5 m²; light-truck tyres of EU label class B, c_r 0.0065; "
        "regeneration to 0.15 g, up to 70 kW): "
        "2,900 kg with driver, insulation kit and unit (the bare van's WLTP test mass is about "
        "2,450 kg), 500 kg payload (600 kg rated: 3,500 kg gross); a 9.5 m³ ATP 'IR' box "
        "(K = 0.35 W/(m²·K) ≤ 0.4) with an "
        "inverter-driven electric unit (2.5 kW cooling, 1.5 kW heating, 150 W standby, COP a "
        "Carnot fraction), strip curtain; cab HVAC off at stops; battery derated in the cold; "
        "pre-conditioned at the depot. Validated (docs/validation.md): WLTC 3b at the plug "
        "215–250 Wh/km, refrigeration 1–3 kW at 30 °C / 4 °C, 10 min of open door ≈ 2 h "
        "of wall gain.",
        vehicle=VehicleParams(
            mass_kg=2900.0,
            gross_mass_kg=3500.0,
            drag_coefficient=0.34,
            frontal_area_m2=4.5,
            rolling_resistance_coefficient=0.0065,
            rolling_resistance_factor=1.0,
            drivetrain_efficiency=0.9,
            regen_efficiency=0.8,
            max_regen_deceleration_mps2=1.5,
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
