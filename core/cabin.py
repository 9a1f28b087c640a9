"""Auxiliaries and cabin comfort (paper §2.3, Table 2)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray
from core.params import VehicleParams

#: Paper Table 2: ambient temperature [°C] and the electric power [W] that keeps the cab at
#: 20 °C (heating below 20 °C, air conditioning above).
HVAC_TABLE_TEMPERATURE_C = np.array([-20.0, -10.0, 0.0, 10.0, 20.0, 30.0])
HVAC_TABLE_POWER_W = np.array([4200.0, 3200.0, 2300.0, 900.0, 0.0, 600.0])


def cabin_hvac_power_w(vehicle: VehicleParams, ambient_c: ArrayLike) -> FloatArray:
    """Electric power of the cab's heater / air conditioning [W] (paper Table 2).

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
