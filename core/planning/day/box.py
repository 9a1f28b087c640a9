"""The box in a planned day: the air and the goods at each stop, the cold chain's verdict
naming the stop where it breaks, and how the refrigeration unit ran (its energy from the
battery and the grid against a thermostat's, and its schedule)."""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Callable, Sequence

import numpy as np

from core.arrays import FloatArray
from core.params import CargoBoxParams, VanParams
from core.physics.battery import JOULES_PER_KWH
from core.physics.cargo import BoxResult
from core.physics.cold_chain import check_cold_chain
from core.physics.simulate import SimulationResult
from core.planning.day.timeline import PLAN_DT_S
from core.planning.model import (
    ColdChainResult,
    RefrigerationResult,
    ScheduleInterval,
    Temperatures,
)

#: Length of a stretch of the refrigeration schedule in the answer [s].
SCHEDULE_STEP_S = 300.0


def temperatures(trace_c: FloatArray, b: int, c: int) -> Temperatures:
    """A box trace (at each step's end) at samples ``b`` and ``c``: sample i ends step i − 1;
    NaN (no goods aboard) is null."""

    def at(sample: int) -> float | None:
        value = float(trace_c[max(sample - 1, 0)]) if trace_c.size else math.nan
        return value if math.isfinite(value) else None

    return Temperatures(arrival=at(b), departure=at(c))


def cold_chain(
    box: CargoBoxParams, simulated: BoxResult, leaving: Sequence[tuple[int, str]]
) -> ColdChainResult | None:
    """The goods held to their band (None: no product); ``leaving`` each stop's departure
    sample and id, in order: the first left at or after the break is named."""
    band, product_c = box.band, simulated.product_c
    if band is None or product_c is None:
        return None
    check = check_cold_chain(band, product_c, PLAN_DT_S)
    stop = None
    if check.first_break_step is not None:
        sample = check.first_break_step + 1  # the step's end
        stop = next((name for leave, name in leaving if leave >= sample), None)
    return ColdChainResult.of(band, check, PLAN_DT_S, stop)


def refrigeration(
    van: VanParams, simulated: SimulationResult, moment: Callable[[int], dt.datetime]
) -> RefrigerationResult:
    """What the unit drew from the battery and the grid, against a thermostat's, and its
    schedule in stretches of :data:`SCHEDULE_STEP_S` (``moment``: a sample's time)."""
    box = simulated.box
    power = simulated.power_w["refrigeration"]
    on_battery = 1.0 - simulated.plugged
    thermostat = power if box.thermostat_power_w is None else box.thermostat_power_w
    setpoint = (
        np.full(power.shape, van.cargo_box.setpoint_c) if box.setpoint_c is None else box.setpoint_c
    )
    every = max(round(SCHEDULE_STEP_S / PLAN_DT_S), 1)
    schedule = [
        ScheduleInterval(
            start=moment(a),
            end=moment(min(a + every, power.size)),
            power_w=float(power[a : a + every].mean()),
            air_setpoint_c=float(setpoint[a : a + every].mean()),
        )
        for a in range(0, power.size, every)
    ]

    def kwh(watts: FloatArray, share: FloatArray) -> float:
        return float((watts * share).sum()) * PLAN_DT_S / JOULES_PER_KWH

    strategy = van.refrigeration
    battery_kwh = kwh(power, on_battery)
    precool_kwh = box.precool_grid_j / JOULES_PER_KWH
    thermostat_kwh = kwh(thermostat, on_battery)
    depot_price = strategy.depot_price_per_kwh

    def cost(battery: float, watts: FloatArray, precool: float) -> float | None:
        if depot_price is None:
            return None
        refill = depot_price / van.battery.charging_efficiency
        return (
            battery * refill + kwh(watts, simulated.plugged_price_per_kwh) + precool * depot_price
        )

    return RefrigerationResult(
        strategy=strategy.strategy,
        objective=strategy.objective,
        battery_kwh=battery_kwh,
        grid_kwh=kwh(power, simulated.plugged) + precool_kwh,
        thermostat_battery_kwh=thermostat_kwh,
        cost=cost(battery_kwh, power, precool_kwh),
        thermostat_cost=cost(thermostat_kwh, thermostat, 0.0),
        schedule=schedule,
    )
