"""Battery state of charge and the feasibility verdict."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray
from core.params import BatteryParams

JOULES_PER_KWH = 3.6e6

# Temperature derating from AAA's "Electric Vehicle Range Testing" (American Automobile
# Association with the Automotive Club of Southern California, February 2019): five EVs on a
# dynamometer, HVAC off, against 75 °F (23.9 °C). At 20 °F (−6.7 °C) the range fell 12 % and
# the economy 9 % (energy per km × 1/0.91); at 95 °F (35 °C) 4 % and 5 %. Range over economy
# gives the usable energy (0.88/0.91 = 0.967 in the cold; 0.96/0.95 > 1 in the heat, taken as
# 1). Continued linearly to −20 °C, held flat outside −20…35 °C.
DERATING_TEMPERATURE_C = np.array([-20.0, -6.7, 23.9, 35.0])
DERATING_ENERGY_FACTOR = np.array([1.1419, 1 / 0.91, 1.0, 1 / 0.95])
DERATING_CAPACITY_FACTOR = np.array([0.9527, 0.88 / 0.91, 1.0, 1.0])


def energy_factor(battery: BatteryParams, temperature_c: ArrayLike) -> FloatArray:
    """Battery energy per energy the consumers use at a battery temperature [–] (≥ 1).

    Internal losses and the cold drive train of AAA (2019); 1 without ``temperature_derating``.
    """
    t = np.asarray(temperature_c, dtype=float)
    if not battery.temperature_derating:
        return np.ones_like(t)
    return np.interp(t, DERATING_TEMPERATURE_C, DERATING_ENERGY_FACTOR)


def capacity_factor(battery: BatteryParams, temperature_c: float) -> float:
    """Usable share of the nominal usable capacity at a battery temperature [–] (≤ 1)."""
    if not battery.temperature_derating:
        return 1.0
    return float(np.interp(temperature_c, DERATING_TEMPERATURE_C, DERATING_CAPACITY_FACTOR))


def battery_energy_j(
    battery: BatteryParams, consumer_energy_j: ArrayLike, temperature_c: ArrayLike
) -> FloatArray:
    """Energy leaving the battery in each step [J] for the consumers' net energy [J]: more per
    discharged joule in the cold, less stored per regenerated joule."""
    energy = np.asarray(consumer_energy_j, dtype=float)
    factor = energy_factor(battery, temperature_c)
    return np.where(energy > 0, energy * factor, energy / factor)


@dataclass(frozen=True)
class BatteryVerdict:
    """Whether the battery holds out with its reserve.

    Every figure comes from one state-of-charge series, never clipped: below 0 it is the
    energy the battery does not hold, as a share of its usable capacity (the van would stop
    there). So ``feasible`` ⇔ ``min_soc ≥ reserve_soc`` ⇔ ``margin_kwh ≥ 0``, whatever the
    reserve (an empty battery is never feasible, even with ``min_soc = 0``).

    Attributes
    ----------
    feasible
        True when the state of charge never falls below ``min_soc``.
    min_soc, final_soc
        Lowest and last state of charge [–]; negative when the battery would run empty.
    margin_kwh
        Energy left above the reserve at the lowest point [kWh]:
        ``(min_soc − reserve_soc) · usable_capacity_kwh``; negative when infeasible (the
        shortfall, even beyond an empty battery).
    required_capacity_kwh
        Smallest nominal usable capacity that keeps the same trace above the reserve [kWh].
    usable_capacity_kwh
        Usable capacity on the day, after temperature derating [kWh].
    recharge_kwh
        Energy from the grid to bring the battery back to its initial state of charge [kWh].
    first_infeasible_index
        First sample whose state of charge is below the reserve, or None.
    reserve_soc
        The reserve it was held to: the battery's ``min_soc`` [–].
    """

    feasible: bool
    min_soc: float
    final_soc: float
    margin_kwh: float
    required_capacity_kwh: float
    usable_capacity_kwh: float
    recharge_kwh: float
    first_infeasible_index: int | None
    reserve_soc: float


#: How far below the reserve a state of charge may round and still hold it [–]: float noise.
SOC_TOLERANCE = 1e-12


def discharge(
    battery: BatteryParams, step_energy_j: ArrayLike, usable_share: float = 1.0
) -> tuple[FloatArray, BatteryVerdict]:
    """State of charge at every sample [–] and the verdict, from the battery energy of each
    step [J].

    ``soc_k = min(1, soc_{k−1} − E_k / C)``: regeneration charges the battery but not beyond
    full; nothing stops it at empty (a negative state of charge is energy the battery lacks).
    ``C`` is the usable capacity times ``usable_share`` (:func:`capacity_factor`). The state
    of charge has ``n + 1`` values for ``n`` steps, the first being ``initial_soc``.

    The required capacity is the deepest discharge below any earlier peak (regeneration cannot
    lift a full battery) divided by the usable window ``initial_soc − min_soc`` and by the
    day's usable share. It is exact when the van leaves full and errs on the large side
    otherwise. Both walks are reflected running sums (:func:`core.arrays.reflected_cumsum`)
    of one cumulative sum, computed once.
    """
    capacity_kwh = battery.usable_capacity_kwh * usable_share
    used_kwh = np.cumsum(np.asarray(step_energy_j, dtype=float)) / JOULES_PER_KWH
    lowest_used = np.minimum.accumulate(used_kwh) if used_kwh.size else used_kwh
    headroom_kwh = (1.0 - battery.initial_soc) * capacity_kwh
    depth_kwh = used_kwh - np.minimum(lowest_used, -headroom_kwh)
    soc = np.concatenate(([battery.initial_soc], 1.0 - depth_kwh / capacity_kwh))
    drawdown_kwh = used_kwh - np.minimum(lowest_used, 0.0)
    peak_draw_kwh = float(drawdown_kwh.max()) if drawdown_kwh.size else 0.0
    below = np.flatnonzero(soc < battery.min_soc - SOC_TOLERANCE)
    lowest = float(soc.min())
    return soc, BatteryVerdict(
        feasible=below.size == 0,
        min_soc=lowest,
        final_soc=float(soc[-1]),
        margin_kwh=(lowest - battery.min_soc) * capacity_kwh,
        required_capacity_kwh=peak_draw_kwh
        / (battery.initial_soc - battery.min_soc)
        / usable_share,
        usable_capacity_kwh=capacity_kwh,
        recharge_kwh=max(battery.initial_soc - float(soc[-1]), 0.0)
        * capacity_kwh
        / battery.charging_efficiency,
        first_infeasible_index=int(below[0]) if below.size else None,
        reserve_soc=battery.min_soc,
    )
