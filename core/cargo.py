"""Cargo box heat balance and refrigeration power (paper §3, eqs 9–12).

Heat balance ``m·c_p·dϑ_CB/dt = Q_z − Q_0`` with ``Q_z = Q_α + Q_sol + Q_door`` (eqs 9, 10).
In the paper's steady state the box stays at its set-point and the unit removes every load
(``Q_0 = Q_z``). In dynamic mode the unit's capacity is finite and the box warms when the load
exceeds it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray, reflected_cumsum
from core.params import GRAVITY_MPS2, CargoBoxParams

#: Specific gas constant of dry air [J/(kg·K)].
AIR_GAS_CONSTANT_J_KGK = 287.05
#: Specific heat of air at constant pressure [J/(kg·K)].
AIR_SPECIFIC_HEAT_J_KGK = 1006.0
#: Standard sea-level pressure [Pa].
STANDARD_PRESSURE_PA = 101_325.0
#: Celsius to kelvin offset [K].
KELVIN_OFFSET = 273.15


def air_density_kg_m3(temperature_c: ArrayLike) -> FloatArray:
    """Density of dry air at sea-level pressure, ideal gas ``ρ = p/(R·T)`` [kg/m³]."""
    return STANDARD_PRESSURE_PA / (
        AIR_GAS_CONSTANT_J_KGK * (np.asarray(temperature_c, dtype=float) + KELVIN_OFFSET)
    )


def wall_heat_w(box: CargoBoxParams, ambient_c: ArrayLike, box_c: ArrayLike) -> FloatArray:
    """Heat through the walls ``Q_α = α·A·(ϑ_amb − ϑ_CB)`` [W] (eq. 11); negative when cold."""
    difference = np.asarray(ambient_c, dtype=float) - np.asarray(box_c, dtype=float)
    return box.wall_heat_transfer_w_m2k * box.heat_transfer_area_m2 * difference


def door_heat_w(box: CargoBoxParams, ambient_c: ArrayLike, box_c: ArrayLike) -> FloatArray:
    """Infiltration heat through the open door [W] (Gosney & Olama 1975; ASHRAE Refrigeration
    Handbook ch. 24, eqs 13–16).

    ``V̇ = 0.221·W·H·√(g·H)·√(1 − ρ_warm/ρ_cold)·F_m``,
    ``F_m = (2/(1 + (ρ_cold/ρ_warm)^(1/3)))^1.5``,
    ``Q_door = ρ_box·V̇·c_p,air·(ϑ_amb − ϑ_box)·D_f·(1 − E)``.

    The doorway flow factor ``D_f`` is calibrated (default 0.25) so that ten minutes of open
    door on the 8 m³ box at 30 K costs about two hours of closed-door wall gain of an ATP-class
    box (K = 0.4 W/(m²·K), 30.6 m²: ≈ 0.73 kWh), as field measurements on small delivery vans
    show: the box air is exchanged within seconds, after which the driving temperature
    difference collapses, so the cold-store value D_f ≈ 0.8–1.0 would overstate it fourfold.
    Negative when the outside air is colder than the box.
    """
    ambient = np.asarray(ambient_c, dtype=float)
    inside = np.asarray(box_c, dtype=float)
    rho_amb = air_density_kg_m3(ambient)
    rho_box = air_density_kg_m3(inside)
    rho_cold = np.maximum(rho_amb, rho_box)
    rho_warm = np.minimum(rho_amb, rho_box)
    density_factor = (2.0 / (1.0 + (rho_cold / rho_warm) ** (1.0 / 3.0))) ** 1.5
    height = box.door_height_m
    flow_m3_s = (
        0.221
        * box.door_width_m
        * height
        * np.sqrt(GRAVITY_MPS2 * height)
        * np.sqrt(1.0 - rho_warm / rho_cold)
        * density_factor
    )
    return (
        rho_box
        * flow_m3_s
        * AIR_SPECIFIC_HEAT_J_KGK
        * (ambient - inside)
        * box.doorway_flow_factor
        * (1.0 - box.curtain_effectiveness)
    )


def heat_capacity_j_k(box: CargoBoxParams, payload_kg: ArrayLike) -> FloatArray:
    """Thermal capacity of the box contents ``m·c_p`` [J/K] (eq. 9): cargo plus box air."""
    air = air_density_kg_m3(box.setpoint_c) * box.volume_m3 * AIR_SPECIFIC_HEAT_J_KGK
    return np.asarray(payload_kg, dtype=float) * box.cargo_specific_heat_j_kgk + air


@dataclass(frozen=True)
class BoxResult:
    """Refrigeration of one trace, per step.

    Attributes
    ----------
    power_w
        Electric power of the refrigeration unit and box heater [W] (eq. 12).
    wall_heat_w, solar_heat_w, door_heat_w
        Heat flows into the box [W] (eqs 11, 17, Gosney–Olama).
    temperature_c
        Cargo-air temperature at the end of each step [°C].
    max_temperature_c
        Highest cargo-air temperature [°C].
    minutes_above_limit
        Time with the cargo air above ``product_limit_c`` [min].
    """

    power_w: FloatArray
    wall_heat_w: FloatArray
    solar_heat_w: FloatArray
    door_heat_w: FloatArray
    temperature_c: FloatArray
    max_temperature_c: float
    minutes_above_limit: float


def refrigeration(
    box: CargoBoxParams,
    ambient_c: FloatArray,
    solar_heat: FloatArray,
    door_open: FloatArray,
    payload_kg: ArrayLike,
    dt_s: float,
) -> BoxResult:
    """Heat loads and electric refrigeration power of every step (eqs 9–12).

    Parameters
    ----------
    box
        Cargo box and refrigeration unit.
    ambient_c
        Ambient temperature of each step [°C].
    solar_heat
        Absorbed solar heat of each step [W] (:func:`core.solar.absorbed_solar_heat_w`).
    door_open
        Fraction of each step with the door open [–], 0…1.
    payload_kg
        Cargo mass of each step [kg] (heat capacity in dynamic mode).
    dt_s
        Step length [s].

    Notes
    -----
    Steady mode (paper §4): ``Q_0 = max(Q_z, 0)``, ``P = Q_0/COP`` (eq. 12), plus ``−Q_z`` of
    electric heating when the box loses heat and the heater is enabled.

    Dynamic mode: the heat stored above the set-point ``E = m·c_p·(ϑ_CB − ϑ_set)`` follows
    ``E_k = max(0, E_{k−1} + (Q_z − Q_0,max)·Δt)``: an ideal thermostat runs the unit at full
    capacity while the box is above its set-point and matches the load at the set-point. The
    loads are evaluated at the set-point, which slightly overstates the warming (a warmer box
    gains less through its walls), i.e. errs on the safe side for the product.
    """
    setpoint = box.setpoint_c
    wall = wall_heat_w(box, ambient_c, setpoint)
    door = np.zeros_like(wall)
    is_open = door_open > 0
    door[is_open] = door_heat_w(box, ambient_c[is_open], setpoint) * door_open[is_open]
    load = wall + solar_heat + door
    if box.mode == "steady":
        removed = np.maximum(load, 0.0)
        temperature = np.full_like(load, setpoint)
    else:
        stored_j = reflected_cumsum((load - box.refrigeration_capacity_w) * dt_s)
        previous_j = np.concatenate(([0.0], stored_j[:-1]))
        removed = np.maximum(load - (stored_j - previous_j) / dt_s, 0.0)
        temperature = setpoint + stored_j / heat_capacity_j_k(box, payload_kg)
    heating = np.maximum(-load, 0.0) if box.heater_enabled else np.zeros_like(load)
    above = temperature > box.product_limit_c
    return BoxResult(
        power_w=removed / box.cop + heating,
        wall_heat_w=wall,
        solar_heat_w=solar_heat,
        door_heat_w=door,
        temperature_c=temperature,
        max_temperature_c=float(temperature.max()) if temperature.size else setpoint,
        minutes_above_limit=float(above.sum() * dt_s / 60.0),
    )
