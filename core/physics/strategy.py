"""The refrigeration unit's operating strategy: the air set-point over the whole day that
uses the least battery energy (or costs least) with the goods inside their band at every
moment — the paper's outlook (§5: "the optimal operating strategy of the whole power
management system") on its own box model with the goods as a node of their own
(:mod:`core.physics.cold_chain`).

A linear programme on a grid of :data:`GRID_S` (scipy's HiGHS). Per step ``k``: the heat the
unit removes ``q_k ∈ [0, Q_0,max]`` and the heater adds ``h_k ∈ [0, Q_h,max]`` (0 without
heater), the air's and the goods' temperatures at the step's end, and the slack ``s_k ≥ 0``
by which the goods leave their band (priced at :data:`SLACK_PENALTY`: a day the unit cannot
hold is answered, the slack saying where). The box's equations are
:func:`core.physics.cold_chain.two_nodes`' backward-Euler steps, exactly::

    (a + G_k + H_k)·ϑa_k − H_k·ϑp_k + q_k − h_k = a·ϑa_{k−1} + G_k·ϑeq_k
    (p_k + H_k)·ϑp_k − H_k·ϑa_k                 = p_k·ϑp_{k−1}

with ``a = C_a/Δt``, ``p_k = C_p,k/Δt``. The goods stay within their band less a margin while
aboard; the air within the band (an EN 12830 recorder logs it). The objective is
``Σ (q_k/COP_k + h_k/COP_h)·Δt·w_k`` with ``w_k`` 1 on the battery and :data:`GRID_WEIGHT`
while plugged in (the grid's energy is not the battery's, but not free either);
``COP_k`` the unit's at the step's outside temperature and the set-point (eq. 12 with the
'carnot' model, linear in the decisions). The air temperatures found are the set-point
schedule; the full simulation then follows it with the unit's thermostat and has the last
word.

References: Huang et al., *Applied Energy* 2016 (economic MPC of transport refrigeration);
Shafiei & Alleyne 2015 (cooling shifted to when the truck drives).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog
from scipy.sparse import coo_matrix

from core.arrays import FloatArray
from core.params import CargoBoxParams, ProductBand
from core.physics.battery import JOULES_PER_KWH

#: The programme's step [s].
GRID_S = 60.0
#: What a joule from the grid weighs against one from the battery when the least battery
#: energy is sought: a tenth — the battery's is the day's range, but the grid's is not free
#: (at a hundredth, 60 minutes of pre-cooling spent 1.5 kWh of the grid to spare 0.6 of the
#: battery on the poorly insulated paper van).
GRID_WEIGHT = 0.1
#: How far inside their band the goods are planned to stay [K]: the doors and arrivals vary.
MARGIN_K = 0.5
#: The price of the goods (and of the air) outside their band in the objective [kWh per
#: kelvin and minute]: far above any energy, so the band is kept wherever the unit can.
SLACK_PENALTY = 100.0
AIR_PENALTY = 1.0


@dataclass(frozen=True)
class BoxDay:
    """The day on the programme's grid, per step: its length [s], the box's conductance
    ``G`` [W/K] and equilibrium ``ϑ_eq`` [°C] (walls, door and sun), the goods aboard [kg], the
    unit's cooling COP [–] and what a joule drawn then weighs in the objective."""

    seconds: FloatArray
    conductance_w_k: FloatArray
    equilibrium_c: FloatArray
    payload_kg: FloatArray
    cop: FloatArray
    weight: FloatArray


@dataclass(frozen=True)
class Schedule:
    """The programme's answer per step: the air at the step's end (the set-point), the goods,
    the heat the unit removes and the heater adds [W], and the goods' and the air's kelvins
    outside their band."""

    air_c: FloatArray
    product_c: FloatArray
    removed_w: FloatArray
    added_w: FloatArray
    outside_k: FloatArray


#: The variables of one step, in order.
_Q, _H, _TA, _TP, _S, _U = range(6)
_VARS = 6


def optimal_schedule(
    box: CargoBoxParams,
    band: ProductBand,
    air_capacity_j_k: float,
    day: BoxDay,
    start_c: tuple[float, float],
) -> Schedule:
    """The unit's removed and added heat per step of ``day`` at the least weighted energy,
    the goods within ``band`` less :data:`MARGIN_K` while aboard and the air within the band,
    from the air and the goods at ``start_c`` (module docstring)."""
    n = day.seconds.size
    rows, cols, vals, rhs = _equalities(box, air_capacity_j_k, day, start_c)
    a_eq = coo_matrix((vals, (rows, cols)), shape=(2 * n, _VARS * n)).tocsr()
    a_ub, b_ub = _band_rows(band, day)
    cost = np.zeros((n, _VARS))
    per_kwh = day.seconds * day.weight / JOULES_PER_KWH
    cost[:, _Q] = per_kwh / day.cop
    cost[:, _H] = per_kwh / box.heating_cop
    cost[:, _S] = SLACK_PENALTY * day.seconds / 60.0
    cost[:, _U] = AIR_PENALTY * day.seconds / 60.0
    steady = box.mode == "steady"
    cool = None if steady else box.refrigeration_capacity_w
    heat = (None if steady else box.heating_capacity_w) if box.heater_enabled else 0.0
    bounds = [(0, cool), (0, heat), (None, None), (None, None), (0, None), (0, None)] * n
    solved = linprog(
        cost.ravel(), A_ub=a_ub, b_ub=b_ub, A_eq=a_eq, b_eq=rhs, bounds=bounds, method="highs"
    )
    if solved.status != 0:
        raise ArithmeticError(f"the refrigeration programme found no schedule: {solved.message}")
    x = solved.x.reshape(n, _VARS)
    return Schedule(
        air_c=x[:, _TA],
        product_c=np.where(day.payload_kg > 0, x[:, _TP], np.nan),
        removed_w=np.maximum(x[:, _Q], 0.0),
        added_w=np.maximum(x[:, _H], 0.0),
        outside_k=x[:, _S],
    )


def _equalities(
    box: CargoBoxParams, air_capacity_j_k: float, day: BoxDay, start_c: tuple[float, float]
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The box's two equations per step (module docstring) as sparse rows: the air's in row
    ``2k``, the goods' in ``2k + 1``."""
    n = day.seconds.size
    a = air_capacity_j_k / day.seconds
    p = day.payload_kg * box.cargo_specific_heat_j_kgk / day.seconds
    h = day.payload_kg * box.product_conductance_w_kgk
    g = day.conductance_w_k
    both = p + h
    empty = both <= 0
    keep = np.where(empty, 1.0, p)  # no goods: the node keeps its last value
    k = np.arange(n)
    air, goods = 2 * k, 2 * k + 1
    at = _VARS * k
    rest = k[1:]
    rows = np.concatenate([air, air, air, air, goods, goods, air[rest], goods[rest]])
    cols = np.concatenate(
        [at + _TA, at + _TP, at + _Q, at + _H, at + _TP, at + _TA, at[:-1] + _TA, at[:-1] + _TP]
    )
    ones = np.ones(n)
    vals = np.concatenate(
        [a + g + h, -h, ones, -ones, np.where(empty, 1.0, both), -h, -a[rest], -keep[rest]]
    )
    rhs = np.zeros(2 * n)
    rhs[air] = g * day.equilibrium_c
    if n:
        rhs[0] += a[0] * start_c[0]
        rhs[1] = keep[0] * start_c[1]
    return rows, cols, vals, rhs


def _band_rows(band: ProductBand, day: BoxDay) -> tuple[object, FloatArray]:
    """The goods within the band less the margin while aboard, the air within the band: each
    less its slack."""
    n = day.seconds.size
    aboard = np.flatnonzero(day.payload_kg > 0)
    high = max(band.max_c - MARGIN_K, band.middle_c)
    low = min(band.min_c + MARGIN_K, band.middle_c)
    limits = [  # variable, its slack, the steps, the sign, the bound
        (_TP, _S, aboard, 1.0, high),
        (_TP, _S, aboard, -1.0, -low),
        (_TA, _U, np.arange(n), 1.0, band.max_c),
        (_TA, _U, np.arange(n), -1.0, -band.min_c),
    ]
    steps = [s for _, _, s, _, _ in limits]
    row = np.arange(sum(s.size for s in steps))
    rows = np.concatenate([row, row])
    cols = np.concatenate(
        [_VARS * s + v for v, _, s, _, _ in limits] + [_VARS * s + u for _, u, s, _, _ in limits]
    )
    vals = np.concatenate(
        [np.full(s.size, sign) for _, _, s, sign, _ in limits] + [-np.ones(row.size)]
    )
    bounds = np.concatenate([np.full(s.size, bound) for _, _, s, _, bound in limits])
    matrix = coo_matrix((vals, (rows, cols)), shape=(row.size, _VARS * n)).tocsr()
    return matrix, bounds
