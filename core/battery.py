"""Battery state of charge and the feasibility verdict."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray, reflected_cumsum
from core.params import BatteryParams

JOULES_PER_KWH = 3.6e6


@dataclass(frozen=True)
class BatteryVerdict:
    """Whether the battery holds out with its reserve.

    Attributes
    ----------
    feasible
        True when the state of charge never falls below ``min_soc``.
    min_soc, final_soc
        Lowest and last state of charge [–].
    margin_kwh
        Energy left above the reserve at the lowest point [kWh]; negative when infeasible.
    required_capacity_kwh
        Smallest usable capacity that keeps the same trace above the reserve [kWh].
    first_infeasible_index
        First sample whose state of charge is below the reserve, or None.
    """

    feasible: bool
    min_soc: float
    final_soc: float
    margin_kwh: float
    required_capacity_kwh: float
    first_infeasible_index: int | None


def state_of_charge(battery: BatteryParams, step_energy_j: ArrayLike) -> FloatArray:
    """State of charge at every sample [–], from the electric energy of each step [J].

    ``soc_k = min(1, soc_{k−1} − E_k / C)``: regeneration charges the battery but not beyond
    full. Returns ``n + 1`` values for ``n`` steps, the first being ``initial_soc``.
    """
    capacity_j = battery.usable_capacity_kwh * JOULES_PER_KWH
    depth = reflected_cumsum(
        np.asarray(step_energy_j, dtype=float) / capacity_j, initial=1.0 - battery.initial_soc
    )
    return np.concatenate(([battery.initial_soc], 1.0 - depth))


def verdict(battery: BatteryParams, soc: FloatArray, step_energy_j: ArrayLike) -> BatteryVerdict:
    """Feasibility, margin, required capacity and first failure of a state-of-charge trace.

    The required capacity is the deepest discharge below any earlier peak (regeneration cannot
    lift a full battery) divided by the usable window ``initial_soc − min_soc``. It is exact
    when the van leaves full and errs on the large side otherwise.
    """
    capacity_kwh = battery.usable_capacity_kwh
    drawdown_kwh = reflected_cumsum(np.asarray(step_energy_j, dtype=float) / JOULES_PER_KWH)
    peak_draw_kwh = float(drawdown_kwh.max()) if drawdown_kwh.size else 0.0
    below = np.flatnonzero(soc < battery.min_soc - 1e-12)
    lowest = float(soc.min())
    return BatteryVerdict(
        feasible=below.size == 0,
        min_soc=lowest,
        final_soc=float(soc[-1]),
        margin_kwh=(lowest - battery.min_soc) * capacity_kwh,
        required_capacity_kwh=peak_draw_kwh / (battery.initial_soc - battery.min_soc),
        first_infeasible_index=int(below[0]) if below.size else None,
    )
