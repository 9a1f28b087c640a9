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
constant is minutes even with the door open), in Numba. The set-point is ``setpoint_c``, or
with the optimal strategy the schedule :mod:`core.physics.strategy` plans for the day.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numba import njit

from core.arrays import Blocks, FloatArray
from core.params import CargoBoxParams, ProductBand, RefrigerationStrategy
from core.physics.cargo import (
    BoxResult,
    air_heat_capacity_j_k,
    door_conductances_w_k,
    refrigeration_cop,
    wall_heat_w,
)
from core.physics.strategy import GRID_S, GRID_WEIGHT, BoxDay, optimal_schedule

#: Step of the two-node integration [s].
BOX_STEP_S = 10.0
#: Most steps of the strategy's programme: a day of minutes; a longer trace (days on the
#: road) is planned on a coarser grid, so its solve stays within a second or so.
MAX_GRID_STEPS = 1440


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
    setpoint_c: FloatArray | tuple[FloatArray, FloatArray],
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
        The air set-point of each step [°C]: the unit cools above it and heats below it; or
        two, the unit cooling above the first and heating below the second.
    start_c
        The air's and the goods' temperatures at the start [°C].
    """
    n = conductance_w_k.size
    blocks = Blocks(n, round(BOX_STEP_S / dt_s))
    edges, counts, mean = blocks.edges, blocks.counts, blocks.mean

    steady = box.mode == "steady"
    cool_w = math.inf if steady else box.refrigeration_capacity_w
    heat_w = (math.inf if steady else box.heating_capacity_w) if box.heater_enabled else 0.0
    switching = (
        (box.differential_k, box.min_on_minutes * 60.0, box.min_off_minutes * 60.0)
        if box.control == "on-off"
        else (0.0, 0.0, 0.0)
    )
    mass = mean(payload_kg)
    cool_to, heat_to = setpoint_c if isinstance(setpoint_c, tuple) else (setpoint_c, setpoint_c)
    air, product, removed, added = _integrate(
        mean(conductance_w_k),
        mean(equilibrium_c),
        (mean(cool_to), mean(heat_to)),
        (air_capacity_j_k, mass * box.cargo_specific_heat_j_kgk),
        mass * box.product_conductance_w_kgk,
        counts * dt_s,
        (cool_w, heat_w),
        switching,
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
    setpoint: tuple[FloatArray, FloatArray],
    capacity: tuple[float, FloatArray],
    h: FloatArray,
    seconds: FloatArray,
    unit: tuple[float, float],
    switching: tuple[float, float, float],
    start: tuple[float, float],
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Backward Euler over the blocks: the goods' equation solved for ``ϑ_p`` leaves the air's
    ``K·ϑ_a' = R − Q̇_0`` with ``K = C_a/Δt + G + k``, ``R = C_a/Δt·ϑ_a + G·ϑ_eq + k·ϑ_p`` and
    ``k = (C_p/Δt)·H/(C_p/Δt + H)``; the unit's ``Q̇_0 = R − K·ϑ_set`` within its limits
    (``setpoint``: the air it cools down to, and the air it heats up to). An on-off unit
    (``switching``: its differential [K] above 0, its shortest run and pause [s]) removes its
    full capacity or nothing: on once the air is above the set-point by half the differential,
    off once below it by half, each run and pause lasting their shortest at least."""
    cool_to, heat_to = setpoint
    c_air, c_product = capacity
    cool_w, heat_w = unit
    differential, min_on, min_off = switching
    n = g.size
    air, product = np.empty(n), np.empty(n)
    removed, added = np.zeros(n), np.zeros(n)
    ta, tp = start
    on, since = False, min_off  # a unit at rest long enough to start
    for i in range(n):
        a = c_air / seconds[i]
        p = c_product[i] / seconds[i]
        both = p + h[i]
        k = p * h[i] / both if both > 0 else 0.0
        big_k = a + g[i] + k
        r = a * ta + g[i] * eq[i] + k * tp
        if differential > 0:
            switch = (
                ta > cool_to[i] + 0.5 * differential
                if not on
                else ta < cool_to[i] - 0.5 * differential
            )
            if switch and since >= (min_on if on else min_off):
                on, since = not on, 0.0
            since += seconds[i]
            q = cool_w if on else 0.0
        else:
            q = min(r - big_k * cool_to[i], cool_w)
        if q <= 0:  # the air would end below the cooling set-point: heat only up to the other
            # (an on-off unit's: below its own differential)
            q = max(min(r - big_k * (heat_to[i] - 0.5 * differential), 0.0), -heat_w)
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
class Run:
    """How the unit runs: its strategy, the share of each step the van is plugged in (its
    consumers on the grid) and that share times the price there [per kWh], whether it leaves
    the depot (the optimal strategy may pre-cool there), and the battery's charging
    efficiency (what refilling a kWh costs)."""

    strategy: RefrigerationStrategy
    plugged: FloatArray
    from_depot: bool = True
    priced: FloatArray | None = None
    charging_efficiency: float = 1.0

    def weights(self) -> tuple[FloatArray, float]:
        """What a joule drawn in each step weighs in the strategy's objective, against one
        from the battery, and one drawn at the depot before departure: the grid's at
        :data:`core.physics.strategy.GRID_WEIGHT` ('energy'), or at its price over the
        battery's — the depot's over the charging efficiency ('cost')."""
        on_battery = 1.0 - self.plugged
        strategy = self.strategy
        if strategy.objective == "energy":
            return on_battery + GRID_WEIGHT * self.plugged, GRID_WEIGHT
        assert strategy.depot_price_per_kwh  # RefrigerationStrategy.priced
        battery_price = strategy.depot_price_per_kwh / self.charging_efficiency
        priced = np.zeros_like(self.plugged) if self.priced is None else self.priced
        return on_battery + priced / battery_price, self.charging_efficiency


#: The box's surroundings over a trace, per step: the ambient [°C], the sun on the box [W] and
#: the door's open share [–].
Outside = tuple[FloatArray, FloatArray, FloatArray]


@dataclass(frozen=True)
class Setpoints:
    """What the unit follows through a trace, per step: the air it cools down to and the air
    it heats up to [°C]; with the air and the goods at departure [°C] after pre-cooling at the
    depot, and what that drew from the grid [J]."""

    cool_to_c: FloatArray
    heat_to_c: FloatArray
    departure_c: tuple[float, float]
    precool_grid_j: float = 0.0


def box_with_goods(
    box: CargoBoxParams,
    outside: Outside,
    payload_kg: FloatArray,
    dt_s: float,
    start_c: tuple[float, float],
    run: Run,
) -> BoxResult:
    """The box of two nodes over steps of ``dt_s``: ``outside`` the ambient [°C], the sun [W]
    and the door's open share of each step; the goods aboard [kg]; ``start_c`` the air's and
    the goods' temperatures at the start [°C]; the unit a thermostat on the set-point, or on
    the optimal strategy's schedule (pre-cooled at the depot from the grid)."""
    thermostat = Setpoints(*(np.full(payload_kg.shape, box.setpoint_c),) * 2, start_c)
    kept = follow(box, outside, payload_kg, dt_s, thermostat)
    if run.strategy.strategy == "thermostat":
        return kept
    planned = plan_setpoints(box, outside, payload_kg, dt_s, start_c, run)
    return replace(
        follow(box, outside, payload_kg, dt_s, planned),
        setpoint_c=planned.cool_to_c,
        thermostat_power_w=kept.power_w,
        precool_grid_j=planned.precool_grid_j,
    )


def _flows(box: CargoBoxParams, outside: Outside) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The door's conductance, the box's in all [W/K] and its equilibrium [°C] (eqs 10, 11,
    17) in each step."""
    ambient_c, solar_w, door_open = outside
    door_w_k = door_conductances_w_k(box, ambient_c, door_open)
    conductance = box.wall_heat_transfer_w_m2k * box.heat_transfer_area_m2 + door_w_k
    return door_w_k, conductance, ambient_c + solar_w / conductance


def follow(
    box: CargoBoxParams,
    outside: Outside,
    payload_kg: FloatArray,
    dt_s: float,
    setpoints: Setpoints,
) -> BoxResult:
    """The box with its unit following ``setpoints`` from their departure temperatures (the
    arguments as :func:`box_with_goods`')."""
    door_w_k, conductance, equilibrium = _flows(box, outside)
    nodes = two_nodes(
        box,
        air_heat_capacity_j_k(box),
        conductance,
        equilibrium,
        payload_kg,
        (setpoints.cool_to_c, setpoints.heat_to_c),
        dt_s,
        setpoints.departure_c,
    )
    return _result(box, outside[0], outside[1], door_w_k, nodes, dt_s)


def _result(
    box: CargoBoxParams,
    ambient_c: FloatArray,
    solar_w: FloatArray,
    door_w_k: FloatArray,
    nodes: TwoNodes,
    dt_s: float,
) -> BoxResult:
    """The unit's power (eq. 12: the heat removed over the COP at the air's temperature, the
    heater's, the standby draw) and the heat flows at the air's temperature."""
    air = nodes.air_c
    cop = refrigeration_cop(box, ambient_c, air)
    power = nodes.removed_w / cop + nodes.added_w / box.heating_cop + box.standby_power_w
    return BoxResult(
        power_w=power,
        wall_heat_w=wall_heat_w(box, ambient_c, air),
        solar_heat_w=solar_w,
        door_heat_w=door_w_k * (ambient_c - air),
        temperature_c=air,
        max_temperature_c=float(air.max()) if air.size else box.setpoint_c,
        minutes_above_limit=float((air > box.product_limit_c).sum() * dt_s / 60.0),
        product_c=nodes.product_c,
    )


def grid_step_s(span_s: float) -> float:
    """The programme's step for a trace of ``span_s`` [s]: a minute
    (:data:`core.physics.strategy.GRID_S`), coarser beyond a day — at most
    :data:`MAX_GRID_STEPS` steps, so a trace of days on the road is planned in about the
    time of one day."""
    return max(GRID_S, span_s / MAX_GRID_STEPS)


def plan_setpoints(
    box: CargoBoxParams,
    outside: Outside,
    payload_kg: FloatArray,
    dt_s: float,
    start_c: tuple[float, float],
    run: Run,
    grid_s: float | None = None,
) -> Setpoints:
    """The optimal strategy's set-points for the day ahead (the arguments as
    :func:`box_with_goods`'): the day on the programme's grid of ``grid_s`` [s] (its steps'
    means; by default :func:`grid_step_s`), after the minutes at the depot it may pre-cool
    in. From a start under way (``run.from_depot`` false) it is the receding horizon's
    re-plan: the rest of the day from the box's state."""
    ambient = outside[0]
    _, conductance, equilibrium = _flows(box, outside)
    weights, at_depot = run.weights()
    n = ambient.size
    per_block = max(round((grid_s or grid_step_s(n * dt_s)) / dt_s), 1)
    step_s = per_block * dt_s
    blocks = Blocks(n, per_block)
    counts, mean = blocks.counts, blocks.mean
    grid_outside = mean(ambient)
    days = [
        BoxDay(
            seconds=counts * dt_s,
            conductance_w_k=mean(conductance),
            equilibrium_c=mean(equilibrium),
            payload_kg=mean(payload_kg),
            cop=np.broadcast_to(
                refrigeration_cop(box, grid_outside, box.setpoint_c), grid_outside.shape
            ),
            weight=mean(weights),
        )
    ]
    m = math.ceil(run.strategy.precool_minutes * 60.0 / step_s) if run.from_depot and n else 0
    if m:  # at the depot, door shut, out of the sun, on the grid
        wall = box.wall_heat_transfer_w_m2k * box.heat_transfer_area_m2
        days.insert(
            0,
            _constant_day(
                m, (step_s, at_depot), wall, (float(ambient[0]), float(payload_kg[0])), box
            ),
        )
    day = BoxDay(
        *(np.concatenate([getattr(d, f) for d in days]) for f in BoxDay.__dataclass_fields__)
    )
    assert box.band is not None  # the strategy needs a product (VanParams)
    air_capacity = air_heat_capacity_j_k(box)
    schedule = optimal_schedule(box, box.band, air_capacity, day, start_c, m)
    departure = start_c
    if m:
        goods = float(schedule.product_c[m - 1])
        departure = (float(schedule.air_c[m - 1]), goods if math.isfinite(goods) else start_c[1])
    electric = (schedule.removed_w / day.cop + schedule.added_w / box.heating_cop) * day.seconds
    # the air the programme keeps, from one minute's end to the next (a step up would have the
    # heater chase it); the heater holds the floor, and the air where the programme heats
    air = schedule.air_c[m:]
    ends_s = np.cumsum(counts) * dt_s
    cool_to = np.interp(
        np.arange(1, n + 1) * dt_s, np.append(0.0, ends_s), np.append(departure[0], air)
    )
    heat_to = np.repeat(np.where(schedule.added_w[m:] > 0, air, box.band.min_c), counts)
    precool_j = _precool_j(
        box,
        BoxDay(*(getattr(day, f)[:m] for f in BoxDay.__dataclass_fields__)),
        electric[:m],
        start_c,
    )
    return Setpoints(cool_to, heat_to, departure, precool_j)


def _precool_j(
    box: CargoBoxParams, window: BoxDay, electric_j: FloatArray, start_c: tuple[float, float]
) -> float:
    """Pre-cooling: what the programme drew in the depot's ``window`` (``electric_j`` [J] per
    step) beyond holding the box as it starts — what the thermostat's day assumes of those
    minutes; at least nothing."""
    if not window.seconds.size:
        return 0.0
    held = two_nodes(
        box,
        air_heat_capacity_j_k(box),
        window.conductance_w_k,
        window.equilibrium_c,
        window.payload_kg,
        np.full(window.seconds.size, start_c[0]),
        float(window.seconds[0]),
        start_c,
    )
    holding = (held.removed_w / window.cop + held.added_w / box.heating_cop) * window.seconds
    return max(float(electric_j.sum() - holding.sum()), 0.0)


def _constant_day(
    m: int,
    step: tuple[float, float],
    conductance: float,
    at: tuple[float, float],
    box: CargoBoxParams,
) -> BoxDay:
    """``m`` steps at the depot (``step``: their length [s] and what a joule weighs there):
    the walls alone, the outside air (``at``: its temperature [°C] and the goods aboard
    [kg]), on the grid."""
    grid_s, weight = step
    ambient_c, payload_kg = at
    return BoxDay(
        seconds=np.full(m, grid_s),
        conductance_w_k=np.full(m, conductance),
        equilibrium_c=np.full(m, ambient_c),
        payload_kg=np.full(m, payload_kg),
        cop=np.full(m, float(refrigeration_cop(box, ambient_c, box.setpoint_c))),
        weight=np.full(m, weight),
    )


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
