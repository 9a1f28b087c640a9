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
from core.physics.cold_chain import box_check, goods_history
from core.physics.simulate import SimulationResult
from core.planning.model import (
    PLAN_DT_S,
    Baseline,
    ColdChainResult,
    DeliveredGoods,
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
    check = box_check(band, simulated, PLAN_DT_S)
    stop = None
    if check.first_break_step is not None:
        sample = check.first_break_step + 1  # the step's end (before departure: the start)
        stop = next((name for leave, name in leaving if leave >= sample), None)
    return ColdChainResult.of(band, check, stop)


def deliveries(
    box: CargoBoxParams, simulated: BoxResult, handed_over: Sequence[int]
) -> list[DeliveredGoods] | None:
    """The goods handed over at each of the samples ``handed_over`` (a stop's departure): their
    warmest and their minutes above the band from their loading on, and whether the chain
    had broken by then (None: no product)."""
    band, trace = box.band, simulated.product_c
    if band is None or trace is None:
        return None
    check = box_check(band, simulated, PLAN_DT_S)
    product_c, seconds, before = goods_history(trace, PLAN_DT_S, simulated.goods_before)
    warmest = np.fmax.accumulate(product_c)
    above = np.cumsum(np.where(product_c > band.max_c + 1e-9, seconds, 0.0)) / 60.0
    broke = math.inf if check.first_break_step is None else check.first_break_step
    out = []
    for sample in handed_over:
        last = before + max(sample, 1) - 1  # sample i ends step i − 1
        out.append(
            DeliveredGoods(
                product_max_c=float(warmest[last]) if math.isfinite(warmest[last]) else None,
                minutes_above_band=float(above[last]),
                verdict="breaks" if broke <= sample - 1 else "holds",
            )
        )
    return out


def refrigeration(
    van: VanParams, simulated: SimulationResult, moment: Callable[[int], dt.datetime]
) -> RefrigerationResult:
    """What the unit drew from the battery and the grid, against a thermostat's, and its
    schedule in stretches of :data:`SCHEDULE_STEP_S` (``moment``: a sample's time)."""
    box = simulated.box
    power = simulated.power_w["refrigeration"]
    on_battery = 1.0 - simulated.plugged
    thermostat = power if box.thermostat is None else box.thermostat.power_w
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
        followed=box.followed,
        baselines=[] if box.best_constant is None else baselines(van, simulated, kwh, cost),
    )


def baselines(
    van: VanParams,
    simulated: SimulationResult,
    kwh: Callable[[FloatArray, FloatArray], float],
    cost: Callable[[float, FloatArray, float], float | None],
) -> list[Baseline]:
    """The configured thermostat's day and the best constant set-point's beside the unit's
    (``kwh``: energy of a power over a share of each step; ``cost``: of the battery's energy,
    a power on the grid and pre-cooling)."""
    box, band = simulated.box, van.cargo_box.band
    assert box.best_constant is not None and band is not None  # a box with a product
    power = simulated.power_w["refrigeration"]
    on_battery = 1.0 - simulated.plugged
    battery = kwh(power, on_battery)
    total = battery + kwh(power, simulated.plugged) + box.precool_grid_j / JOULES_PER_KWH
    constant = box.best_constant()
    out = []
    for name, setpoint_c, result in (
        ("thermostat", van.cargo_box.setpoint_c, box.thermostat or box),
        ("best-constant", constant.setpoint_c, constant.box),
    ):
        watts = result.power_w
        its_battery, its_grid = kwh(watts, on_battery), kwh(watts, simulated.plugged)
        assert result.product_c is not None  # a box with a product
        holds = box.unheld is None and box_check(band, result, PLAN_DT_S).holds
        out.append(
            Baseline(
                name=name,
                setpoint_c=setpoint_c,
                battery_kwh=its_battery,
                grid_kwh=its_grid,
                cost=cost(its_battery, watts, 0.0),
                cold_chain="holds" if holds else "breaks",
                battery_saved=_saved(battery, its_battery),
                total_saved=_saved(total, its_battery + its_grid),
            )
        )
    return out


def _saved(used: float, baseline: float) -> float:
    """The share of ``baseline`` that ``used`` does without [–]."""
    return 1.0 - used / baseline if baseline > 0 else 0.0
