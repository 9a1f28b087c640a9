"""The goods' own temperature beside the box air's, the refrigeration unit following an air
set-point, and whether the cold chain holds.

The paper's box (§3, eqs 9–12) is one node: the air, the structure and the cargo at one
temperature. The rules constrain the goods, and an EN 12830 recorder logs the air; the goods
follow the air slowly (hours), the air follows an open door in minutes. Two nodes:

* the air and the box structure that follows it, ``C_a = ρ·V·c_p,air + C_struct``::

      C_a·dϑ_a/dt = G·(ϑ_eq − ϑ_a) + H·(ϑ_p − ϑ_a) − Q̇_0

  with ``G = α·A + G_door`` and ``ϑ_eq = ϑ_amb + Q̇_sol/G`` (eqs 10, 11, 17 and the
  Gosney–Olama door, :mod:`core.physics.cargo`), ``Q̇_0`` the heat the unit removes (negative:
  the heater adds);
* the goods aboard, ``C_p = m·c_p`` (eq. 9's cargo term) and ``H = m·h`` (h:
  ``product_conductance_w_kgk``)::

      C_p·dϑ_p/dt = H·(ϑ_a − ϑ_p)

  Goods delivered leave with their heat: the mass falls, the temperature stays.

The unit is an ideal thermostat on the air: each step it removes (or, with the heater, adds)
what brings the air to its set-point at the step's end, within its capacity (unlimited in the
paper's steady mode). Solved by backward Euler over steps of :data:`BOX_STEP_S` (the air's time
constant is minutes even with the door open), in Numba.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from core.arrays import FloatArray
from core.params import CargoBoxParams, ProductBand

#: Step of the two-node integration [s].
BOX_STEP_S = 10.0


@dataclass(frozen=True)
class TwoNodes:
    """The air and the goods over a trace, per step.

    Attributes
    ----------
    air_c
        Box air at the end of each step [°C].
    product_c
        The goods at the end of each step [°C]; NaN while none are aboard.
    removed_w, added_w
        Heat the unit removes, and the heater adds, in each step [W].
    """

    air_c: FloatArray
    product_c: FloatArray
    removed_w: FloatArray
    added_w: FloatArray


def two_nodes(
    box: CargoBoxParams,
    air_capacity_j_k: float,
    conductance_w_k: FloatArray,
    equilibrium_c: FloatArray,
    payload_kg: FloatArray,
    setpoint_c: FloatArray,
    dt_s: float,
    start_c: tuple[float, float],
) -> TwoNodes:
    """The air and the goods over steps of ``dt_s`` (blocks of :data:`BOX_STEP_S`).

    Parameters
    ----------
    box
        The box, its unit (cooling and heating capacities; the paper's steady mode: unlimited)
        and its goods (specific heat, conductance per kg).
    air_capacity_j_k
        ``C_a`` [J/K].
    conductance_w_k, equilibrium_c
        ``G`` [W/K] and ``ϑ_eq`` [°C] of each step.
    payload_kg
        The goods aboard in each step [kg].
    setpoint_c
        The air set-point of each step [°C].
    start_c
        The air's and the goods' temperatures at the start [°C].
    """
    n = conductance_w_k.size
    per_block = max(round(BOX_STEP_S / dt_s), 1)
    edges = np.arange(0, n, per_block)
    counts = np.diff(np.append(edges, n))

    def mean(values: FloatArray) -> FloatArray:
        return np.add.reduceat(values, edges) / counts if n else np.zeros(0)

    steady = box.mode == "steady"
    cool_w = math.inf if steady else box.refrigeration_capacity_w
    heat_w = (math.inf if steady else box.heating_capacity_w) if box.heater_enabled else 0.0
    mass = mean(payload_kg)
    air, product, removed, added = _integrate(
        mean(conductance_w_k),
        mean(equilibrium_c),
        mean(setpoint_c),
        (air_capacity_j_k, mass * box.cargo_specific_heat_j_kgk),
        mass * box.product_conductance_w_kgk,
        counts * dt_s,
        (cool_w, heat_w),
        start_c,
    )
    product[mass <= 0] = np.nan
    air_start = np.concatenate(([start_c[0]], air[:-1]))
    # within a block the air moves linearly from its start to its end; the goods are read at
    # the block's end
    position = (np.arange(n) - np.repeat(edges, counts) + 1) / np.repeat(counts, counts)
    return TwoNodes(
        air_c=np.repeat(air_start, counts) + position * np.repeat(air - air_start, counts),
        product_c=np.repeat(product, counts),
        removed_w=np.repeat(removed, counts),
        added_w=np.repeat(added, counts),
    )


@njit(cache=True)
def _integrate(
    g: FloatArray,
    eq: FloatArray,
    setpoint: FloatArray,
    capacity: tuple[float, FloatArray],
    h: FloatArray,
    seconds: FloatArray,
    unit: tuple[float, float],
    start: tuple[float, float],
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Backward Euler over the blocks: the goods' equation solved for ``ϑ_p`` leaves the air's
    ``K·ϑ_a' = R − Q̇_0`` with ``K = C_a/Δt + G + k``, ``R = C_a/Δt·ϑ_a + G·ϑ_eq + k·ϑ_p`` and
    ``k = (C_p/Δt)·H/(C_p/Δt + H)``; the unit's ``Q̇_0 = R − K·ϑ_set`` within its limits."""
    c_air, c_product = capacity
    cool_w, heat_w = unit
    n = g.size
    air, product = np.empty(n), np.empty(n)
    removed, added = np.zeros(n), np.zeros(n)
    ta, tp = start
    for i in range(n):
        a = c_air / seconds[i]
        p = c_product[i] / seconds[i]
        both = p + h[i]
        k = p * h[i] / both if both > 0 else 0.0
        big_k = a + g[i] + k
        r = a * ta + g[i] * eq[i] + k * tp
        q = min(max(r - big_k * setpoint[i], -heat_w), cool_w)
        ta = (r - q) / big_k
        if both > 0:
            tp = (p * tp + h[i] * ta) / both
        air[i], product[i] = ta, tp
        if q > 0:
            removed[i] = q
        else:
            added[i] = -q
    return air, product, removed, added


@dataclass(frozen=True)
class ColdChainCheck:
    """Whether the goods stayed inside their band while aboard.

    Attributes
    ----------
    holds
        Never outside ``[min_c, max_c + excursion_c]``.
    product_min_c, product_max_c
        The coldest and warmest the goods were [°C] (None: no goods aboard).
    minutes_outside_band
        Time outside ``[min_c, max_c]`` [min].
    first_break_step
        The first step outside ``[min_c, max_c + excursion_c]`` (None: it holds).
    reason
        Why it breaks, in words (None: it holds).
    """

    holds: bool
    product_min_c: float | None
    product_max_c: float | None
    minutes_outside_band: float
    first_break_step: int | None
    reason: str | None


def check_cold_chain(band: ProductBand, product_c: FloatArray, dt_s: float) -> ColdChainCheck:
    """The goods' temperatures ``product_c`` per step of ``dt_s`` (NaN: none aboard) held to
    ``band``."""
    aboard = np.isfinite(product_c)
    if not aboard.any():
        return ColdChainCheck(True, None, None, 0.0, None, None)
    values = product_c[aboard]
    outside = aboard & ((product_c < band.min_c) | (product_c > band.max_c))
    ceiling = band.max_c + band.excursion_c
    warm = aboard & (product_c > ceiling + 1e-9)
    cold = aboard & (product_c < band.min_c - 1e-9)
    broken = np.flatnonzero(warm | cold)
    reason = None
    if broken.size:
        at = float(product_c[broken[0]])
        reason = (
            f"the goods reached {at:.1f} °C, above their band's {ceiling:g} °C"
            if warm[broken[0]]
            else f"the goods fell to {at:.1f} °C, below their band's floor of {band.min_c:g} °C"
        )
    return ColdChainCheck(
        holds=not broken.size,
        product_min_c=float(values.min()),
        product_max_c=float(values.max()),
        minutes_outside_band=float(outside.sum() * dt_s / 60.0),
        first_break_step=int(broken[0]) if broken.size else None,
        reason=reason,
    )
