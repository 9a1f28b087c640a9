"""Auxiliaries and cabin comfort (paper §2.3, Table 2), with the cab's thermal duty at stops."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray, interval_rates
from core.params import VehicleParams

#: Paper Table 2: ambient temperature [°C] and the electric power [W] that keeps the cab at
#: 20 °C (heating below 20 °C, air conditioning above).
HVAC_TABLE_TEMPERATURE_C = np.array([-20.0, -10.0, 0.0, 10.0, 20.0, 30.0])
HVAC_TABLE_POWER_W = np.array([4200.0, 3200.0, 2300.0, 900.0, 0.0, 600.0])
#: The cab's comfort temperature [°C] (paper §2.3).
CAB_SETPOINT_C = 20.0
#: Share of the cab HVAC's power while parked, by ``cab_hvac_at_stops``.
_PARKED_SHARE = {"on": 1.0, "off": 0.0}


def cabin_hvac_power_w(vehicle: VehicleParams, ambient_c: ArrayLike) -> FloatArray:
    """Electric power of the cab's heater / air conditioning holding 20 °C [W] (Table 2).

    Linear interpolation between the table's points, held flat outside -20…30 °C.

    Parameters
    ----------
    ambient_c
        Ambient temperature [°C].
    """
    power = np.interp(
        np.asarray(ambient_c, dtype=float), HVAC_TABLE_TEMPERATURE_C, HVAC_TABLE_POWER_W
    )
    return power if vehicle.cabin_hvac_enabled else np.zeros_like(power)


def auxiliaries_power_w(vehicle: VehicleParams, n_steps: int) -> FloatArray:
    """Constant auxiliary power (radio, lights, controls) for ``n_steps`` steps [W] (§2.3)."""
    return np.full(n_steps, vehicle.auxiliaries_power_w)


def parked_share(vehicle: VehicleParams) -> float:
    """Share of the Table 2 power the cab HVAC draws while parked [–]."""
    return _PARKED_SHARE.get(vehicle.cab_hvac_at_stops, vehicle.cab_reduced_share)


def _drift(vehicle: VehicleParams, ambient_c: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Deficit a parked cab settles at [J] and its rate of approach [1/s].

    A lumped cab loses heat to the outside with the conductance the Table 2 power implies,
    ``G = P(ϑ_amb)/|20 °C − ϑ_amb|``, and has the recovery energy ``C`` per kelvin. Parked with
    the HVAC at share ``s`` of ``P``, its deficit [K] relaxes towards ``(1 − s)·|20 − ϑ_amb|``
    with the time constant ``C/G`` (first-order response); bringing it back costs ``C`` per
    kelvin.
    """
    gap_k = np.abs(CAB_SETPOINT_C - ambient_c)
    power = cabin_hvac_power_w(vehicle, ambient_c)
    capacity = vehicle.cab_recovery_energy_j_k
    safe_gap = np.where(gap_k > 0.1, gap_k, 1.0)
    rate = np.where(gap_k > 0.1, power / safe_gap / capacity, 0.0)
    return capacity * (1.0 - parked_share(vehicle)) * gap_k * (power > 0), rate


def cab_power_w(
    vehicle: VehicleParams,
    ambient_c: FloatArray,
    dt_s: float,
    parked: Sequence[tuple[float, float]] = (),
    initial_deficit_j: float = 0.0,
    hvac_w: FloatArray | None = None,
) -> FloatArray:
    """Electric power of the cab HVAC over each step [W] (Table 2 and the thermal duty).

    While driving the HVAC holds 20 °C at the Table 2 power. While parked it draws the parked
    share of it (``cab_hvac_at_stops``) and the cab drifts (:func:`_drift`); once the van
    drives on, the HVAC recovers the deficit with the power it has left below
    ``cab_hvac_max_power_w``, as it does at departure for a cab that was not pre-conditioned
    (``initial_deficit_j``). A recovery cut short by the next stop carries its rest into that
    stop's drift. One pass over the stops; the per-second power is then one vectorised sum.

    Parameters
    ----------
    ambient_c
        Outside temperature of each step [°C]; step ``k`` spans ``[k·dt, (k+1)·dt)``.
    parked
        ``(start_s, duration_s)`` of each stop, in time order.
    initial_deficit_j
        Energy to bring the cab to 20 °C at the start [J].
    hvac_w
        The Table 2 power of each step [W] when already known (:func:`cabin_hvac_power_w`).
    """
    base = cabin_hvac_power_w(vehicle, ambient_c) if hvac_w is None else hvac_w
    share = parked_share(vehicle)
    nothing_parked = not parked or share == 1.0
    if (
        not vehicle.cabin_hvac_enabled
        or base.size == 0
        or (nothing_parked and initial_deficit_j == 0)
    ):
        return base
    n = base.size
    # At full power while parked the HVAC holds the cab as it does on the road: no stops count.
    stops = [] if share == 1.0 else parked
    starts = np.array([p[0] for p in stops], dtype=float)
    durations = np.array([p[1] for p in stops], dtype=float)
    ends = starts + durations
    power = base * (1.0 - (1.0 - share) * interval_rates(starts, ends, n, dt_s))
    at_end = np.clip((ends / dt_s).astype(int), 0, n - 1)
    spare = np.maximum(
        vehicle.cab_hvac_max_power_w - base[at_end], 0.1 * vehicle.cab_hvac_max_power_w
    )
    settled, rate = _drift(vehicle, ambient_c[at_end])
    keep = np.exp(-rate * durations)
    boost_start, boost_end, boost_rate = [], [], []
    deficit_j = initial_deficit_j
    clock_s = 0.0
    rate_w = max(vehicle.cab_hvac_max_power_w - float(base[0]), 0.1 * vehicle.cab_hvac_max_power_w)
    for start_s, end_s, settled_j, kept, spare_w in zip(
        starts.tolist(), ends.tolist(), settled.tolist(), keep.tolist(), spare.tolist(), strict=True
    ):
        delivered_j = min(deficit_j, max(start_s - clock_s, 0.0) * rate_w)
        boost_start.append(clock_s)
        boost_end.append(clock_s + delivered_j / rate_w)
        boost_rate.append(rate_w)
        deficit_j = settled_j + (deficit_j - delivered_j - settled_j) * kept
        clock_s, rate_w = end_s, spare_w
    boost_start.append(clock_s)
    boost_end.append(clock_s + deficit_j / rate_w)
    boost_rate.append(rate_w)
    return power + interval_rates(boost_start, boost_end, n, dt_s, boost_rate, overlap="add")
