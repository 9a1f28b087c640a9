"""The integers the routing solvers see, in one place: seconds for time, grams for payload and
tenths of a watt-hour for energy. The planner rounds explicitly — up where a quantity is taken
(a stop's demand, an arc's energy), down where it is a limit (a van's payload, its battery) —
so a solution the solver accepts never exceeds what the rounded figures allow.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: Energy of one solver unit [J]: a tenth of a watt-hour.
ENERGY_UNIT_J = 360.0
#: Payload of one solver unit [kg]: a gram.
PAYLOAD_UNIT_KG = 0.001


def energy_units_up(energy_j: ArrayLike) -> NDArray[np.int64]:
    """Energy taken, in solver units, rounded up."""
    return np.ceil(np.asarray(energy_j, dtype=float) / ENERGY_UNIT_J).astype(np.int64)


def energy_units_down(energy_j: float) -> int:
    """An energy limit in solver units, rounded down."""
    return math.floor(energy_j / ENERGY_UNIT_J)


def payload_units_up(mass_kg: ArrayLike) -> NDArray[np.int64]:
    """Payload taken, in solver units, rounded up."""
    return np.ceil(np.asarray(mass_kg, dtype=float) / PAYLOAD_UNIT_KG - 1e-9).astype(np.int64)


def payload_units_down(mass_kg: float) -> int:
    """A payload limit in solver units, rounded down."""
    return math.floor(mass_kg / PAYLOAD_UNIT_KG + 1e-9)
