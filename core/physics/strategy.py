"""The refrigeration unit's operating strategy: the air set-point over the whole day that
uses the least battery energy (or costs least) with the goods inside their band at every
moment — the paper's outlook (§5: "the optimal operating strategy of the whole power
management system") on its own box model with the goods as a node of their own
(:mod:`core.physics.cold_chain`).

A linear programme on a grid of :data:`GRID_S` (scipy's HiGHS). Per step ``k``: the heat the
unit removes ``q_k ∈ [0, Q_0,max(ϑa_k)]`` (its capacity at the air's temperature and the
outside's, linear in the air: :func:`core.physics.cargo.capacity_line_w`) and the heater
adds ``h_k ∈ [0, Q_h,max]`` (0 without heater), the air's and the goods' temperatures at
the step's end, and the slack ``s_k ≥ 0`` by which the goods leave their band (priced at
:data:`SLACK_PENALTY`: a day the unit cannot hold is answered, the slack saying where).
The box's equations are :func:`core.physics.cold_chain.two_nodes`' backward-Euler steps,
exactly::

    (a + G_k + H_k)·ϑa_k − H_k·ϑp_k + q_k − h_k = a·ϑa_{k−1} + G_k·ϑeq_k
    (p_k + H_k)·ϑp_k − H_k·ϑa_k                 = p_k·ϑp_{k−1}

with ``a = C_a/Δt``, ``p_k = C_p,k/Δt`` (the fans' heat on the right of the air's, as if
the unit ran throughout; its part-load losses are left to the simulation, which follows the
schedule and counts them). The goods stay within their band less a margin while
aboard; the air within the band (an EN 12830 recorder logs it) but while a door is open. The
objective is
``Σ (q_k/COP_k + h_k/COP_h)·Δt·w_k`` with ``w_k`` 1 on the battery and, while plugged in,
:data:`GRID_WEIGHT` (objective 'energy': the grid's energy is not the battery's, but not free
either) or the charger's price over the battery's — the depot's over the charging efficiency
(objective 'cost': :meth:`core.physics.cold_chain.Run.weights`);
``COP_k`` the unit's at the step's outside temperature and the set-point (eq. 12 with the
'carnot' model, linear in the decisions). The goods' band is the rule (89/108/EEC, ATP); the
air's is relaxed while a door is open, as the rules allow: fighting an open door the unit
cannot win against only blows cold air out. The air temperatures found are the set-point
schedule; the full simulation then follows it with the unit's thermostat and has the last
word. An on-off unit's duty is planned as its mean over each step (the relaxation: the
mixed-integer programme with its runs and pauses took 26 s for a day, against 0.1 s), the
air kept half its differential inside the band; its thermostat switches around the plan.

References: Huang et al., *Applied Energy* 2016 (economic MPC of transport refrigeration);
Shafiei & Alleyne 2015 (cooling shifted to when the truck drives).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, milp
from scipy.sparse import coo_matrix

from core.arrays import FloatArray
from core.params import CargoBoxParams, ProductBand
from core.physics.battery import JOULES_PER_KWH
from core.physics.cargo import capacity_line_w

#: The programme's step [s].
GRID_S = 60.0
#: What a joule from the grid weighs against one from the battery when the least battery
#: energy is sought: a tenth — the battery's is the day's range, but the grid's is not free
#: (at a hundredth, 60 minutes of pre-cooling spent 1.5 kWh of the grid to spare 0.6 of the
#: battery on the poorly insulated paper van).
GRID_WEIGHT = 0.1
#: How far inside their band the goods are planned to stay [K]: the doors and arrivals vary.
MARGIN_K = 0.5
#: ... and at least this share of the band's width: a wide band's goods (frozen: 12 K) drift
#: further on a day as driven than a narrow one's.
MARGIN_SHARE = 0.1


def margin_k(band: ProductBand) -> float:
    """How far inside ``band`` the goods are planned [K]: :data:`MARGIN_K`, or
    :data:`MARGIN_SHARE` of its width if more."""
    return max(MARGIN_K, MARGIN_SHARE * (band.max_c - band.min_c))


#: The price of the goods (and of the air) outside their band in the objective [kWh per
#: kelvin and minute]: far above any energy, so the band is kept wherever the unit can.
SLACK_PENALTY = 100.0
AIR_PENALTY = 1.0


@dataclass(frozen=True)
class BoxDay:
    """The day on the programme's grid, per step: its length [s], the box's conductance
    ``G`` [W/K] and equilibrium ``ϑ_eq`` [°C] (walls, door and sun), the goods aboard [kg], the
    unit's cooling COP [–], what a joule drawn then weighs in the objective, the outside air
    [°C] (the unit's capacity) and the open door's conductance [W/K] (the air may leave its
    band where it is above 0; None: never)."""

    seconds: FloatArray
    conductance_w_k: FloatArray
    equilibrium_c: FloatArray
    payload_kg: FloatArray
    cop: FloatArray
    weight: FloatArray
    ambient_c: FloatArray
    door_open: FloatArray | None = None


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
    held_steps: int = 0,
) -> Schedule:
    """The unit's removed and added heat per step of ``day`` at the least weighted energy,
    the goods within ``band`` less :func:`margin_k` while aboard and the air within the band,
    from the air and the goods at ``start_c`` (module docstring); through the first
    ``held_steps`` (at the depot) no warmer than at the start: pre-cooling only cools. For an
    on-off unit the programme plans its duty (the heat it removes is its mean over the
    step) with the air half the differential inside the band: its thermostat swings that far
    around the set-point."""
    n = day.seconds.size
    rows, cols, vals, rhs = _equalities(box, air_capacity_j_k, day, start_c)
    a_eq = coo_matrix((vals, (rows, cols)), shape=(2 * n, _VARS * n)).tocsr()
    swing = 0.5 * box.differential_k if box.control == "on-off" else 0.0
    cost = np.zeros((n, _VARS))
    per_kwh = day.seconds * day.weight / JOULES_PER_KWH
    cost[:, _Q] = per_kwh / day.cop
    cost[:, _H] = per_kwh / box.heating_cop
    cost[:, _S] = SLACK_PENALTY * day.seconds / 60.0
    cost[:, _U] = AIR_PENALTY * day.seconds / 60.0
    steady = box.mode == "steady"
    heat = (np.inf if steady else box.heating_capacity_w) if box.heater_enabled else 0.0
    solved = milp(
        cost.ravel(),
        bounds=Bounds(
            np.tile([0.0, 0.0, -np.inf, -np.inf, 0.0, 0.0], n),
            np.tile([np.inf, heat] + [np.inf] * 4, n),
        ),
        constraints=[
            LinearConstraint(a_eq, rhs, rhs),
            _band_rows(band, day, swing, (held_steps, start_c)),
            _capacity_rows(box, day),
        ],
    )
    if solved.x is None:
        raise ArithmeticError(f"the refrigeration programme found no schedule: {solved.message}")
    x = solved.x.reshape(n, _VARS)
    return Schedule(
        air_c=x[:, _TA],
        product_c=np.where(day.payload_kg > 0, x[:, _TP], np.nan),
        removed_w=np.maximum(x[:, _Q], 0.0),
        added_w=np.maximum(x[:, _H], 0.0),
        outside_k=x[:, _S],
    )


def _capacity_rows(box: CargoBoxParams, day: BoxDay) -> LinearConstraint:
    """The unit's cooling capacity at the air's temperature in each step,
    ``q_k − slope·ϑa_k ≤ Q_0(0 °C)`` (:func:`core.physics.cargo.capacity_line_w`; its floor
    left out, as the programme keeps the air in the band); none in the steady mode."""
    n = day.seconds.size
    at_zero, slope = capacity_line_w(box, day.ambient_c)
    if box.mode == "steady":
        at_zero, slope = np.full(n, np.inf), 0.0
    k = np.arange(n)
    rows = np.concatenate([k, k])
    cols = np.concatenate([_VARS * k + _Q, _VARS * k + _TA])
    vals = np.concatenate([np.ones(n), np.full(n, -slope)])
    matrix = coo_matrix((vals, (rows, cols)), shape=(n, _VARS * n)).tocsr()
    return LinearConstraint(matrix, -np.inf, at_zero)


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
    # the fans' heat as if the unit ran throughout: the simulation counts it only while it does
    rhs[air] = g * day.equilibrium_c + box.standby_power_w
    if n:
        rhs[0] += a[0] * start_c[0]
        rhs[1] = keep[0] * start_c[1]
    return rows, cols, vals, rhs


def _band_rows(
    band: ProductBand, day: BoxDay, swing_k: float, held: tuple[int, tuple[float, float]]
) -> LinearConstraint:
    """The goods within the band less the margin while aboard, the air within the band less
    ``swing_k`` (at most to its middle), and through the first steps ``held`` no warmer than
    at the start (the air, the goods) [°C]: each less its slack."""
    n = day.seconds.size
    aboard = np.flatnonzero(day.payload_kg > 0)
    everywhere = np.arange(n)
    # the goods' band is the rule; the air may leave its band while a door is open
    shut = everywhere if day.door_open is None else np.flatnonzero(day.door_open <= 0)
    held_steps, start_c = held
    margin = margin_k(band)
    goods_high = np.full(n, max(band.max_c - margin, band.middle_c))
    goods_high[:held_steps] = np.minimum(goods_high[:held_steps], start_c[1])
    air_high = np.full(n, max(band.max_c - swing_k, band.middle_c))
    air_high[:held_steps] = np.minimum(air_high[:held_steps], start_c[0])
    low = min(band.min_c + margin, band.middle_c)
    limits = [  # variable, its slack, the steps, the sign, the bound in each step
        (_TP, _S, aboard, 1.0, goods_high),
        (_TP, _S, aboard, -1.0, np.full(n, -low)),
        (_TA, _U, shut, 1.0, air_high),
        (_TA, _U, everywhere, -1.0, np.full(n, -min(band.min_c + swing_k, band.middle_c))),
    ]
    row = np.arange(sum(s.size for _, _, s, _, _ in limits))
    rows = np.concatenate([row, row])
    cols = np.concatenate(
        [_VARS * s + v for v, _, s, _, _ in limits] + [_VARS * s + u for _, u, s, _, _ in limits]
    )
    vals = np.concatenate(
        [np.full(s.size, sign) for _, _, s, sign, _ in limits] + [-np.ones(row.size)]
    )
    bounds = np.concatenate([bound[s] for _, _, s, _, bound in limits])
    matrix = coo_matrix((vals, (rows, cols)), shape=(row.size, _VARS * n)).tocsr()
    return LinearConstraint(matrix, -np.inf, bounds)
