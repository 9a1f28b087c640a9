"""Cargo box heat balance and refrigeration power (paper §3, eqs 9–12).

Heat balance ``m·c_p·dϑ_CB/dt = Q_z − Q_0`` with ``Q_z = Q_α + Q_sol + Q_door`` (eqs 9, 10).
In the paper's steady state the box stays at its set-point and the unit removes every load
(``Q_0 = Q_z``). In dynamic mode the unit's cooling and heating capacities are finite: the box
warms (or cools) when the load exceeds them, and every load is taken at the box's current
temperature, so the gain shrinks as the box warms.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import Blocks, FloatArray
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
    """Thermal capacity of the box and its contents ``m·c_p`` [J/K] (eq. 9): cargo, box air and
    the box structure that follows the air."""
    cargo = np.asarray(payload_kg, dtype=float) * box.cargo_specific_heat_j_kgk
    return cargo + air_heat_capacity_j_k(box)


def air_heat_capacity_j_k(box: CargoBoxParams) -> float:
    """Thermal capacity of the box air at the set-point and the structure that follows it
    [J/K]."""
    air = float(air_density_kg_m3(box.setpoint_c)) * box.volume_m3 * AIR_SPECIFIC_HEAT_J_KGK
    return air + box.structure_heat_capacity_j_k


#: Highest COP of the 'carnot' model [–]: small lifts (a cool day) cannot make the compressor
#: arbitrarily efficient; its minimum pressure ratio and the fans bound it.
MAX_CARNOT_COP = 6.0


def refrigeration_cop(box: CargoBoxParams, ambient_c: ArrayLike, box_c: ArrayLike) -> FloatArray:
    """Coefficient of performance of the unit when cooling [–] (η_RU of eq. 12).

    'constant': the parameter ``cop`` (a scalar array). 'carnot': ``f·T_e/(T_c − T_e)`` with
    the evaporator ``T_e = ϑ_box − ΔT_e`` and the condenser ``T_c = ϑ_amb + ΔT_c`` in kelvin
    (the ideal vapour-compression limit scaled by the unit's Carnot fraction f; Stoecker & Jones,
    *Refrigeration and Air Conditioning*, ch. 3), at most :data:`MAX_CARNOT_COP`.
    """
    ambient = np.asarray(ambient_c, dtype=float)
    if box.cop_model == "constant":
        return np.asarray(box.cop)
    evaporator_k = np.asarray(box_c, dtype=float) - box.evaporator_approach_k + KELVIN_OFFSET
    condenser_k = ambient + box.condenser_approach_k + KELVIN_OFFSET
    lift_k = np.maximum(condenser_k - evaporator_k, 1e-9)
    return np.minimum(box.carnot_fraction * evaporator_k / lift_k, MAX_CARNOT_COP)


#: ATP's rating conditions of a unit's capacity: the box air [°C] and the outside air [°C].
RATING_BOX_C = 0.0
RATING_AMBIENT_C = 30.0
#: Least share of its rating a unit delivers however cold the box or hot the day [–].
MIN_CAPACITY_SHARE = 0.1


def capacity_line_w(box: CargoBoxParams, ambient_c: ArrayLike) -> tuple[FloatArray, float]:
    """The unit's cooling capacity as a line in the box air's temperature [W]: its value at
    0 °C in each step's ``ambient_c`` and its slope [W/K] (``capacity_box_slope_per_k``,
    ``capacity_ambient_slope_per_k``). The paper's steady box assumes the unit removes every
    load; only the check of its rating (:func:`core.physics.cold_chain.box_with_goods`) uses
    this there."""
    ambient = np.asarray(ambient_c, dtype=float)
    rated = box.refrigeration_capacity_w
    at_zero = rated * (
        1.0
        - box.capacity_box_slope_per_k * RATING_BOX_C
        - box.capacity_ambient_slope_per_k * (ambient - RATING_AMBIENT_C)
    )
    return at_zero, rated * box.capacity_box_slope_per_k


def cooling_capacity_w(box: CargoBoxParams, ambient_c: ArrayLike, box_c: ArrayLike) -> FloatArray:
    """The unit's cooling capacity Q_0,max [W] with the box air at ``box_c`` and the outside
    air at ``ambient_c`` [°C]: its rating at 0 °C / 30 °C (ATP's conditions) along
    :func:`capacity_line_w`, at least :data:`MIN_CAPACITY_SHARE` of it (the paper's steady
    mode too: its rating)."""
    at_zero, slope = capacity_line_w(box, ambient_c)
    line = at_zero + slope * np.asarray(box_c, dtype=float)
    return np.maximum(line, MIN_CAPACITY_SHARE * box.refrigeration_capacity_w)


def part_load_factor(box: CargoBoxParams, load_share: ArrayLike) -> FloatArray:
    """The share of its full-load COP a 'variable' unit reaches removing ``load_share`` of its
    capacity [–]: 1 down to ``min_modulation``, below it cycling, ``PLF = 1 − C_D·(1 − x)``
    with the run-time fraction ``x = load_share/min_modulation`` (AHRI 210/240; ASHRAE
    Handbook — HVAC Systems and Equipment). An 'on-off' unit's losses are its start-up ramp
    (:func:`core.physics.cold_chain.two_nodes`); the paper's steady unit has none."""
    share = np.asarray(load_share, dtype=float)
    if box.mode == "steady" or box.control == "on-off" or box.min_modulation <= 0:
        return np.ones_like(share)
    run_share = np.clip(share / box.min_modulation, 0.0, 1.0)
    return 1.0 - box.cycling_degradation * (1.0 - run_share)


def unit_power_w(
    box: CargoBoxParams,
    ambient_c: ArrayLike,
    air_c: ArrayLike,
    removed_w: FloatArray,
    added_w: FloatArray | float,
    paid_w: FloatArray | None = None,
) -> FloatArray:
    """Electric power of the unit [W] (eq. 12): the heat it removes over its COP at the
    air's and the outside temperature and its part-load factor (:func:`part_load_factor`),
    the heater's over its COP, and the standby draw (controls, evaporator fans) while it
    runs. ``paid_w``: the heat an 'on-off' compressor is paid for (its capacity while on,
    however much its start-up ramp delivers); None: ``removed_w``."""
    cop = refrigeration_cop(box, ambient_c, air_c)
    added = np.asarray(added_w, dtype=float)
    if paid_w is None:
        share = removed_w / cooling_capacity_w(box, ambient_c, air_c)
        paid_w = removed_w / part_load_factor(box, share)
    running = (removed_w > 0) | (added > 0)
    return paid_w / cop + added / box.heating_cop + box.standby_power_w * running


def door_conductance_w_k(box: CargoBoxParams, ambient_c: ArrayLike) -> FloatArray:
    """Heat let in through the fully open door per kelvin between outside and box [W/K].

    The Gosney–Olama flow at the set-point, ``Q_door(ϑ_amb, ϑ_set)/(ϑ_amb − ϑ_set)``; the flow
    itself weakens as the difference shrinks, so using it at a warmer box errs on the safe
    side.
    """
    ambient = np.asarray(ambient_c, dtype=float)
    difference = ambient - box.setpoint_c
    # Below 0.1 K the density difference vanishes, and so does the flow.
    usable = np.abs(difference) > 0.1
    safe = np.where(usable, difference, 1.0)
    return np.where(usable, door_heat_w(box, ambient, box.setpoint_c) / safe, 0.0)


def door_conductances_w_k(
    box: CargoBoxParams, ambient_c: FloatArray, door_open: FloatArray
) -> FloatArray:
    """The open door's conductance in each step [W/K]: :func:`door_conductance_w_k` times the
    share of the step it is open."""
    conductance = np.zeros_like(ambient_c)
    is_open = door_open > 0
    conductance[is_open] = door_open[is_open] * door_conductance_w_k(box, ambient_c[is_open])
    return conductance


def precondition_energy_j(box: CargoBoxParams, ambient_c: float) -> float:
    """Electric energy to bring the box structure from the outside temperature to its
    set-point [J]: cooling over the COP, or heating over the heating COP (no heater: 0)."""
    heat_j = box.structure_heat_capacity_j_k * (ambient_c - box.setpoint_c)
    if heat_j >= 0:
        return heat_j / float(refrigeration_cop(box, ambient_c, box.setpoint_c))
    return -heat_j / box.heating_cop if box.heater_enabled else 0.0


#: What a refrigeration unit followed through a trace: the thermostat at its set-point, a
#: schedule (the optimal strategy's, or one replayed), or the best constant set-point.
Followed = Literal["thermostat", "schedule", "best-constant"]


@dataclass(frozen=True)
class BoxResult:
    """Refrigeration of one trace, per step.

    Attributes
    ----------
    power_w
        Electric power of the refrigeration unit, box heater and standby draw [W] (eq. 12).
    wall_heat_w, solar_heat_w, door_heat_w
        Heat flows into the box [W] (eqs 11, 17, Gosney–Olama), at the box's temperature.
    temperature_c
        Cargo-air temperature at the end of each step [°C].
    max_temperature_c
        Highest cargo-air temperature [°C].
    minutes_above_limit
        Time with the cargo air above ``product_limit_c`` [min].
    product_c
        The goods' temperature at the end of each step [°C], NaN while none are aboard
        (:mod:`core.physics.cold_chain`); None: the box has no product.
    setpoint_c
        The air set-point of each step the unit followed [°C] (the optimal strategy's
        schedule); None: ``setpoint_c`` throughout.
    thermostat
        With the optimal strategy: the day of a thermostat at ``setpoint_c``, for comparison.
    precool_grid_j
        Electric energy the optimal strategy spent cooling at the depot before departure,
        from the grid [J].
    product_before_c, seconds_before_s
        The goods before the trace [°C] and how long each value lasted [s]: as loaded (or as
        the van's state says, no length), then the optimal strategy's pre-cooling at the
        depot (:func:`core.physics.cold_chain.goods_history`).
    followed
        What the unit followed: the thermostat at ``setpoint_c``, the optimal strategy's
        schedule, or the best constant set-point where that beat the schedule.
    best_constant
        With a product: the best constant set-point's day on demand (it costs a search of
        set-points; :func:`core.physics.cold_chain.best_constant`).
    unheld
        With a product: the first step in which the unit cannot hold the band's ceiling even
        with the door shut, and why in words (None: it can).
    notes
        Warnings about the box's day (goods loaded outside their band, a unit too weak for
        it, a band too narrow for the strategy).
    """

    power_w: FloatArray
    wall_heat_w: FloatArray
    solar_heat_w: FloatArray
    door_heat_w: FloatArray
    temperature_c: FloatArray
    max_temperature_c: float
    minutes_above_limit: float
    product_c: FloatArray | None = None
    setpoint_c: FloatArray | None = None
    thermostat: BoxResult | None = None
    precool_grid_j: float = 0.0
    product_before_c: FloatArray = field(default_factory=lambda: np.zeros(0))
    seconds_before_s: FloatArray = field(default_factory=lambda: np.zeros(0))
    followed: Followed = "thermostat"
    best_constant: Callable[[], Any] | None = None
    unheld: tuple[int, str] | None = None
    notes: tuple[str, ...] = ()

    @property
    def goods_before(self) -> tuple[FloatArray, FloatArray]:
        """The goods before the trace [°C] and how long each value lasted [s]."""
        return self.product_before_c, self.seconds_before_s


#: Step of the dynamic box integration [s]: the box's time constant is many minutes even with
#: the door open (an empty 8 m³ box: about 15 min), so 10 s steps of the exact exponential
#: solution lose nothing and keep the Python loop short.
BOX_STEP_S = 10.0


def refrigeration(
    box: CargoBoxParams,
    ambient_c: FloatArray,
    solar_heat: FloatArray,
    door_open: FloatArray,
    payload_kg: ArrayLike,
    dt_s: float,
    initial_c: float | None = None,
) -> BoxResult:
    """Heat loads and electric refrigeration power of every step (eqs 9–12).

    Parameters
    ----------
    box
        Cargo box and refrigeration unit.
    ambient_c
        Ambient temperature of each step [°C].
    solar_heat
        Absorbed solar heat of each step [W] (:func:`core.physics.solar.absorbed_solar_heat_w`).
    door_open
        Fraction of each step with the door open [–], 0…1.
    payload_kg
        Cargo mass of each step [kg] (heat capacity in dynamic mode).
    dt_s
        Step length [s].
    initial_c
        Temperature of the box structure and air at the start [°C] (the cargo is loaded at the
        set-point); None: everything at the set-point (pre-cooled at the depot).

    Notes
    -----
    Steady mode (paper §4): the loads at the set-point, ``Q_0 = max(Q_z, 0)``,
    ``P = Q_0/COP`` (eq. 12), plus ``−Q_z/COP_heat`` when the box loses heat and the heater is
    enabled, plus the standby draw while the unit runs (its fans' heat among the loads). A box
    structure that starts warm is pulled down at the unit's capacity from the start.

    Dynamic mode: ``C·dϑ/dt = G·(ϑ_eq − ϑ) − Q_0`` with ``G = α·A + G_door`` and
    ``ϑ_eq = ϑ_amb + Q_sol/G``, solved exactly over steps of :data:`BOX_STEP_S` with constant
    inputs. An ideal thermostat runs the unit at full cooling capacity (at the box's and the
    outside temperature, :func:`cooling_capacity_w`) while the box is above its set-point, at
    full heating capacity (if enabled) while below, and matches the load at the set-point; its
    fans' heat joins the load while it runs, and it is off while the box drifts below its
    set-point without a heater. The state is the temperature, so unloading cargo changes only
    the heat capacity, never the temperature.
    """
    door_conductance = door_conductances_w_k(box, ambient_c, door_open)
    if box.mode == "steady":
        temperature, cooling, heating = _steady(
            box, ambient_c, solar_heat, door_conductance, dt_s, initial_c
        )
    else:
        capacity = heat_capacity_j_k(box, np.broadcast_to(payload_kg, ambient_c.shape))
        start_c = box.setpoint_c
        if initial_c is not None:  # the cargo comes in at the set-point; the rest is warm
            cargo = np.asarray(payload_kg, dtype=float).flat[0] * box.cargo_specific_heat_j_kgk
            start_c += (capacity[0] - cargo) / capacity[0] * (initial_c - box.setpoint_c)
        temperature, cooling, heating = _integrate_box(
            box, ambient_c, solar_heat, door_conductance, capacity, dt_s, start_c
        )
    power = unit_power_w(box, ambient_c, temperature, cooling, heating)
    above = temperature > box.product_limit_c
    return BoxResult(
        power_w=power,
        wall_heat_w=wall_heat_w(box, ambient_c, temperature),
        solar_heat_w=solar_heat,
        door_heat_w=door_conductance * (ambient_c - temperature),
        temperature_c=temperature,
        max_temperature_c=float(temperature.max()) if temperature.size else box.setpoint_c,
        minutes_above_limit=float(above.sum() * dt_s / 60.0),
    )


def _steady(
    box: CargoBoxParams,
    ambient_c: FloatArray,
    solar_heat: FloatArray,
    door_conductance: FloatArray,
    dt_s: float,
    initial_c: float | None,
) -> tuple[FloatArray, FloatArray, FloatArray | float]:
    """The paper's steady box: at its set-point, the unit removing every load and its fans'
    heat (and the heater adding what it loses, if enabled), a structure that starts warm
    pulled down at the unit's capacity from the start. Temperature [°C], heat removed and
    added in each step [W]."""
    setpoint = box.setpoint_c
    load = wall_heat_w(box, ambient_c, setpoint) + solar_heat
    load = load + door_conductance * (ambient_c - setpoint)
    if initial_c is not None:
        pulldown_j = box.structure_heat_capacity_j_k * (initial_c - setpoint)
        rate_w = box.refrigeration_capacity_w if pulldown_j > 0 else box.heating_capacity_w
        load = load + _front_loaded(pulldown_j, rate_w, load.size, dt_s)
    # the fans' heat while the unit runs: cooling, or heating what the box loses
    running = (load >= 0) | box.heater_enabled
    load = load + box.standby_power_w * running
    heating = np.maximum(-load, 0.0) if box.heater_enabled else 0.0
    return np.full_like(ambient_c, setpoint), np.maximum(load, 0.0), heating


def _front_loaded(energy_j: float, power_w: float, n_steps: int, dt_s: float) -> FloatArray:
    """Per-step power [W] that delivers ``energy_j`` (signed) at ``power_w`` from the start."""
    elapsed_j = np.arange(n_steps + 1) * dt_s * power_w
    done = np.minimum(elapsed_j, abs(energy_j))
    return np.sign(energy_j) * np.diff(done) / dt_s


def _integrate_box(
    box: CargoBoxParams,
    ambient_c: FloatArray,
    solar_heat: FloatArray,
    door_conductance: FloatArray,
    capacity_j_k: FloatArray,
    dt_s: float,
    start_c: float,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Box temperature at the end of each step [°C] and the heat removed and added in each
    step [W], with the exact exponential solution over blocks of :data:`BOX_STEP_S`.

    While the box sits at its set-point and the unit can match the load, the block is settled
    in one vectorised pass; the Python loop runs only through excursions (an open door beyond
    the unit's capacity, a warm start, a cold drift without heater).
    """
    n = ambient_c.size
    blocks = Blocks(n, round(BOX_STEP_S / dt_s))
    edges, counts, block_mean = blocks.edges, blocks.counts, blocks.mean

    wall_g = box.wall_heat_transfer_w_m2k * box.heat_transfer_area_m2
    conductance = wall_g + block_mean(door_conductance)
    ambient = block_mean(ambient_c)
    equilibrium = ambient + block_mean(solar_heat) / conductance
    capacity = block_mean(capacity_j_k)
    seconds = counts * dt_s
    setpoint = box.setpoint_c
    fan_w = box.standby_power_w
    at_zero, slope = capacity_line_w(box, ambient)
    least_w = MIN_CAPACITY_SHARE * box.refrigeration_capacity_w
    heat_w = box.heating_capacity_w if box.heater_enabled else 0.0
    # At the set-point the unit must remove (or add) exactly the load, its fans' heat with it;
    # without a heater it is off while the box loses heat, and the box drifts.
    load_w = conductance * (equilibrium - setpoint)
    net_w = load_w + fan_w
    holds = (load_w >= 0) | (heat_w > 0)
    holds &= (net_w <= np.maximum(at_zero + slope * setpoint, least_w)) & (net_w >= -heat_w)
    ends = np.full(edges.size, setpoint)
    removed = np.maximum(net_w, 0.0)
    added = np.maximum(-net_w, 0.0)
    breaks = np.flatnonzero(~holds)
    g_list, eq_list, c_list, h_list, zero_list = (
        x.tolist() for x in (conductance, equilibrium, capacity, seconds, at_zero)
    )
    t = start_c
    i = 0
    while i < edges.size:
        if t == setpoint and holds[i]:
            i = (
                int(breaks[np.searchsorted(breaks, i)])
                if breaks.size and breaks[-1] >= i
                else edges.size
            )
            continue
        g, eq, c, h = g_list[i], eq_list[i], c_list[i], h_list[i]
        decay = math.exp(-g * h / c)
        free = eq + (t - eq) * decay
        reach = (1.0 - decay) / g
        running = eq + fan_w / g  # the equilibrium with the fans' heat
        free_on = running + (t - running) * decay
        cool_j = heat_j = 0.0
        if free > setpoint:
            cool_w = max(zero_list[i] + slope * t, least_w)
            end = max(free_on - cool_w * reach, setpoint)
            mean_gain = g * h * (running - 0.5 * (t + end))
            cool_j = min(max(mean_gain - c * (end - t), 0.0), cool_w * h)
        elif free < setpoint and heat_w > 0:
            end = min(free_on + heat_w * reach, setpoint)
            mean_gain = g * h * (running - 0.5 * (t + end))
            heat_j = min(max(c * (end - t) - mean_gain, 0.0), heat_w * h)
        else:
            end = free
        ends[i], removed[i], added[i] = end, cool_j / h, heat_j / h
        t = end
        i += 1
    block_start = np.concatenate(([start_c], ends[:-1]))
    # Within a block, the temperature moves linearly from its start to its end.
    position = (np.arange(n) - np.repeat(edges, counts) + 1) / np.repeat(counts, counts)
    temperature = np.repeat(block_start, counts) + position * np.repeat(ends - block_start, counts)
    return temperature, np.repeat(removed, counts), np.repeat(added, counts)
