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

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numba import njit

from core.arrays import Blocks, FloatArray
from core.params import CargoBoxParams, ProductBand, RefrigerationStrategy
from core.physics.cargo import (
    MIN_CAPACITY_SHARE,
    BoxResult,
    Followed,
    air_heat_capacity_j_k,
    capacity_line_w,
    cooling_capacity_w,
    door_conductances_w_k,
    refrigeration_cop,
    unit_power_w,
    wall_heat_w,
)
from core.physics.strategy import GRID_S, GRID_WEIGHT, BoxDay, margin_k, optimal_schedule

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
    paid_w
        Heat the compressor is paid for in each step [W]: an 'on-off' unit's capacity while it
        runs, however much of it its start-up ramp delivers; else ``removed_w``.
    """

    air_c: FloatArray
    product_c: FloatArray
    removed_w: FloatArray
    added_w: FloatArray
    paid_w: FloatArray


def two_nodes(
    box: CargoBoxParams,
    flows: tuple[FloatArray, FloatArray, FloatArray],
    payload_kg: FloatArray,
    setpoints: Setpoints,
    dt_s: float,
) -> TwoNodes:
    """The air and the goods over steps of ``dt_s`` (blocks of :data:`BOX_STEP_S`).

    Parameters
    ----------
    box
        The box, its unit (cooling and heating capacities; the paper's steady mode: unlimited)
        and its goods (specific heat, conductance per kg); the air's heat capacity ``C_a``
        [J/K] from it (:func:`air_heat_capacity_j_k`).
    flows
        ``G`` [W/K], ``ϑ_eq`` and the outside air (the unit's capacity) [°C] of each step.
    payload_kg
        The goods aboard in each step [kg].
    setpoints
        The air of each step the unit cools down to and heats up to [°C], and the air's and
        the goods' temperatures at the start [°C] (``departure_c``).
    dt_s
        The step [s].
    """
    conductance_w_k, equilibrium_c, ambient_c = flows
    start_c = setpoints.departure_c
    n = conductance_w_k.size
    blocks = Blocks(n, round(BOX_STEP_S / dt_s))
    edges, counts, mean = blocks.edges, blocks.counts, blocks.mean
    mass = mean(payload_kg)
    air, product, removed, added, paid = _on_blocks(
        box,
        (air_heat_capacity_j_k(box), mass),
        (mean(conductance_w_k), mean(equilibrium_c), mean(ambient_c)),
        (mean(setpoints.cool_to_c), mean(setpoints.heat_to_c)),
        counts * dt_s,
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
        paid_w=np.repeat(paid, counts),
    )


def _on_blocks(
    box: CargoBoxParams,
    capacity: tuple[float, FloatArray],
    flows: tuple[FloatArray, FloatArray, FloatArray],
    setpoint_c: tuple[FloatArray, FloatArray],
    seconds: FloatArray,
    start_c: tuple[float, float],
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """:func:`_integrate` over blocks of ``seconds`` with the box's unit: ``capacity`` the
    air's [J/K] and the goods aboard [kg], ``flows`` the conductance [W/K], the equilibrium
    and the outside air [°C], ``setpoint_c`` what it cools down to and heats up to."""
    steady = box.mode == "steady"
    conductance, equilibrium, ambient = flows
    # the paper's steady unit removes every load
    at_zero, slope = capacity_line_w(box, ambient)
    if steady:
        at_zero, slope = np.full(ambient.size, math.inf), 0.0
    heat_w = (math.inf if steady else box.heating_capacity_w) if box.heater_enabled else 0.0
    switching = (
        (box.differential_k, box.min_on_minutes * 60.0, box.min_off_minutes * 60.0)
        if box.control == "on-off"
        else (0.0, 0.0, 0.0)
    )
    # an on-off unit's start-up ramp (its cycling losses, AHRI's cyclic test: 6 min on, 24 off)
    ramp_s = box.cycling_degradation * 0.8 * 360.0 if box.control == "on-off" else 0.0
    air_j_k, mass = capacity
    return _integrate(
        conductance,
        equilibrium,
        setpoint_c,
        (air_j_k, mass * box.cargo_specific_heat_j_kgk),
        mass * box.product_conductance_w_kgk,
        seconds,
        (at_zero, slope, MIN_CAPACITY_SHARE * box.refrigeration_capacity_w),
        (heat_w, box.standby_power_w),
        (*switching, ramp_s),
        start_c,
    )


@njit(cache=True)
def _integrate(
    g: FloatArray,
    eq: FloatArray,
    setpoint: tuple[FloatArray, FloatArray],
    capacity: tuple[float, FloatArray],
    h: FloatArray,
    seconds: FloatArray,
    cooling: tuple[FloatArray, float, float],
    unit: tuple[float, float],
    switching: tuple[float, float, float, float],
    start: tuple[float, float],
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Backward Euler over the blocks: the goods' equation solved for ``ϑ_p`` leaves the air's
    ``K·ϑ_a' = R − Q̇_0`` with ``K = C_a/Δt + G + k``, ``R = C_a/Δt·ϑ_a + G·ϑ_eq + k·ϑ_p`` and
    ``k = (C_p/Δt)·H/(C_p/Δt + H)``; the unit's ``Q̇_0 = R − K·ϑ_set`` within its limits
    (``setpoint``: the air it cools down to, and the air it heats up to). ``cooling``: the
    capacity at 0 °C in each block [W], its slope with the air [W/K] and its least [W], taken
    at the block's start; ``unit``: the heater's capacity and the fans' draw [W], heat in the
    air while the unit runs. An on-off unit (``switching``: its differential [K] above 0, its
    shortest run and pause [s], its start-up ramp's time constant [s]) runs at its full
    capacity or not at all — delivering ``1 − e^(−t/τ)`` of it ``t`` after each start, paid
    in full: on once the air is above the set-point by half the differential, off once below
    it by half, each run and pause lasting their shortest at least. Returns the air, the
    goods [°C], the heat removed, added and paid for (:class:`TwoNodes`) [W]."""
    cool_to, heat_to = setpoint
    c_air, c_product = capacity
    at_zero, slope, least = cooling
    heat_w, fan_w = unit
    differential, min_on, min_off, ramp = switching
    n = g.size
    air, product = np.empty(n), np.empty(n)
    removed, added, paid = np.zeros(n), np.zeros(n), np.zeros(n)
    ta, tp = start
    on, since = False, min_off  # a unit at rest long enough to start
    for i in range(n):
        a = c_air / seconds[i]
        p = c_product[i] / seconds[i]
        both = p + h[i]
        k = p * h[i] / both if both > 0 else 0.0
        big_k = a + g[i] + k
        r = a * ta + g[i] * eq[i] + k * tp
        cool_w = max(at_zero[i] + slope * ta, least)
        if differential > 0:
            switch = (
                ta > cool_to[i] + 0.5 * differential
                if not on
                else ta < cool_to[i] - 0.5 * differential
            )
            if switch and since >= (min_on if on else min_off):
                on, since = not on, 0.0
            share = 1.0
            if on and ramp > 0:  # the mean of the ramp over the block
                fade = math.exp(-since / ramp) - math.exp(-(since + seconds[i]) / ramp)
                share -= ramp / seconds[i] * fade
            since += seconds[i]
            q = cool_w * share if on else 0.0
            pay = cool_w if on else 0.0
        else:  # it runs while the air would end above the set-point without it
            need = r - big_k * cool_to[i]
            q = min(need + fan_w, cool_w) if need > 0 else 0.0
            pay = q
        if q > 0:
            r += fan_w
        else:  # the air would end below the cooling set-point: heat only up to the other
            # (an on-off unit's: below its own differential), the fans' heat helping
            floor = heat_to[i] - 0.5 * differential
            pay = q = 0.0
            if heat_w > 0 and r + fan_w - big_k * floor < 0:
                r += fan_w
                q = max(r - big_k * floor, -heat_w)
        ta = (r - q) / big_k
        if both > 0:
            tp = (p * tp + h[i] * ta) / both
        air[i], product[i] = ta, tp
        if q > 0:
            removed[i] = q
            paid[i] = pay
        else:
            added[i] = -q
    return air, product, removed, added, paid


@dataclass(frozen=True)
class Run:
    """How the unit runs: its strategy, the share of each step the van is plugged in (its
    consumers on the grid) and that share times the price there [per kWh], whether it leaves
    the depot (the optimal strategy may pre-cool there), the battery's charging efficiency
    (what refilling a kWh costs), and a schedule to follow instead of the strategy (the air
    set-point of each step [°C], NaN: the thermostat's; a plan's, replayed)."""

    strategy: RefrigerationStrategy
    plugged: FloatArray
    from_depot: bool = True
    priced: FloatArray | None = None
    charging_efficiency: float = 1.0
    setpoint_c: FloatArray | None = None

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
    depot, what that drew from the grid [J], and the air and the goods through it (each
    step's end [°C] and length [s])."""

    cool_to_c: FloatArray
    heat_to_c: FloatArray
    departure_c: tuple[float, float]
    precool_grid_j: float = 0.0
    depot_product_c: FloatArray = field(default_factory=lambda: np.zeros(0))
    depot_seconds_s: FloatArray = field(default_factory=lambda: np.zeros(0))
    depot_air_c: FloatArray = field(default_factory=lambda: np.zeros(0))


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
    the optimal strategy's schedule (pre-cooled at the depot from the grid) — unless the best
    constant set-point (:func:`best_constant`) keeps the goods at least as well for less by the
    strategy's objective: then on that."""
    day = DayInputs(outside, payload_kg, dt_s, start_c, run)
    thermostat = _constant(box.setpoint_c, payload_kg, start_c)
    kept = follow(box, outside, payload_kg, dt_s, thermostat)
    # the goods as loaded (none: the van leaves empty): a moment of no length
    aboard = bool(payload_kg.size and payload_kg[0] > 0)
    loaded = np.array([start_c[1] if aboard else np.nan])
    unheld = _unheld(box, outside)
    notes = (
        *_loading_notes(box, start_c[1] if aboard else None),
        *([] if unheld is None else [unheld[1]]),
    )
    # a steady box is held by assumption: only the rating says the unit cannot
    held = unheld if box.mode == "steady" else None
    narrow = _too_narrow(box) if run.strategy.strategy == "optimal" else ()
    constant: Callable[[], ConstantRun] = functools.cache(
        functools.partial(best_constant, box, day)
    )
    followed: Followed
    if run.setpoint_c is not None:  # a schedule to replay: followed
        setpoints = _replayed(box, run.setpoint_c, start_c)
        result, followed = follow(box, outside, payload_kg, dt_s, setpoints), "schedule"
    elif run.strategy.strategy == "thermostat" or narrow:
        setpoints, result, followed = thermostat, kept, "thermostat"
    else:
        unit = plan_unit(box, day)
        setpoints, result, followed = unit.setpoints, unit.box, unit.followed
        constant = unit.baseline
    planned = followed != "thermostat"
    return replace(
        result,
        setpoint_c=setpoints.cool_to_c if planned else None,
        thermostat=kept if planned else None,
        precool_grid_j=setpoints.precool_grid_j,
        product_before_c=np.concatenate((loaded, setpoints.depot_product_c)),
        seconds_before_s=np.concatenate(([0.0], setpoints.depot_seconds_s)),
        followed=followed,
        best_constant=constant,
        unheld=held,
        notes=(*notes, *narrow),
    )


def _replayed(
    box: CargoBoxParams, setpoint_c: FloatArray, start_c: tuple[float, float]
) -> Setpoints:
    """A schedule to replay (the air set-point of each step, NaN: the thermostat's) as what
    the unit follows: it cools down to it, the heater holding the band's floor."""
    assert box.band is not None  # a box with a product
    given = ~np.isnan(setpoint_c)
    cool_to = np.where(given, setpoint_c, box.setpoint_c)
    heat_to = np.where(given, np.minimum(cool_to, box.band.min_c), box.setpoint_c)
    return Setpoints(cool_to, heat_to, start_c)


@dataclass(frozen=True)
class UnitPlan:
    """What the optimal strategy has the unit follow through a day: the set-points, the box
    following them, whether they are the programme's schedule or the best constant
    set-point, and that set-point's day."""

    setpoints: Setpoints
    box: BoxResult
    followed: Literal["schedule", "best-constant"]
    constant: ConstantRun

    def baseline(self) -> ConstantRun:
        """The best constant set-point's day, the plan weighed against."""
        return self.constant


def plan_unit(box: CargoBoxParams, day: DayInputs) -> UnitPlan:
    """The optimal strategy on ``day``: the programme's schedule (:func:`plan_setpoints`) —
    with the pre-cooling at the depot, or without it where the full physics finds that
    cheaper (the programme prices the fans while the unit runs and its cycling below its
    least speed linearly, and an hour at the depot can leave the unit idling through the day
    where those losses are) — or the best constant set-point (:func:`best_constant`) where the
    schedule would leave the goods out longer, cost more by the objective or, by the energy
    objective, draw more from the battery. A re-plan under way runs this from the box's
    state."""
    args = (day.outside, day.payload_kg, day.dt_s)
    planned = plan_setpoints(box, *args, day.start_c, day.run)
    scheduled = follow(box, *args, planned)
    strategy = day.run.strategy
    if day.run.from_depot and strategy.precool_minutes > 0:
        at_once = replace(day.run, strategy=strategy.model_copy(update={"precool_minutes": 0.0}))
        unplanned = plan_setpoints(box, *args, day.start_c, at_once)
        leaving = follow(box, *args, unplanned)
        if _costlier(box, day, (scheduled, planned.precool_grid_j), (leaving, 0.0)):
            planned, scheduled = unplanned, leaving
    constant = best_constant(box, day)
    if _costlier(box, day, (scheduled, planned.precool_grid_j), (constant.box, 0.0)):
        setpoints = _constant(constant.setpoint_c, day.payload_kg, constant.start_c)
        return UnitPlan(setpoints, constant.box, "best-constant", constant)
    return UnitPlan(planned, scheduled, "schedule", constant)


def _loading_notes(box: CargoBoxParams, loaded_c: float | None) -> tuple[str, ...]:
    """A warning for goods loaded outside their band (None: no goods aboard)."""
    band = box.band
    assert band is not None  # a box with a product
    if loaded_c is None or band.min_c <= loaded_c <= band.max_c:
        return ()
    side = (
        f"below their band's floor of {band.min_c:g} °C (chilled goods may have frozen)"
        if loaded_c < band.min_c
        else f"above their band's {band.max_c:g} °C"
    )
    return (
        f"the goods are loaded at {loaded_c:g} °C, {side}: the cold chain is broken from "
        "loading (cargo_box.load_temperature_c)",
    )


def _unheld(box: CargoBoxParams, outside: Outside) -> tuple[int, str] | None:
    """The first step in which the walls, the sun and the unit's fans alone bring more heat
    than the unit removes with the air at the band's ceiling (its capacity there,
    :func:`core.physics.cargo.cooling_capacity_w`), and a warning saying so; None: none."""
    band = box.band
    assert band is not None  # a box with a product
    load_w = wall_heat_w(box, outside[0], band.max_c) + outside[1] + box.standby_power_w
    capacity_w = np.broadcast_to(cooling_capacity_w(box, outside[0], band.max_c), np.shape(load_w))
    over = np.flatnonzero(load_w > capacity_w)
    if not over.size:
        return None
    at = int(over[0])
    worst = int(np.argmax(load_w - capacity_w))
    return (
        at,
        f"the unit's {float(capacity_w[worst]) / 1000:.1f} kW (at {band.max_c:g} °C in the box "
        f"and {float(outside[0][worst]):.0f} °C outside) cannot hold the goods' band: the "
        f"walls, the sun and its fans alone bring {float(load_w[worst]) / 1000:.1f} kW",
    )


def _too_narrow(box: CargoBoxParams) -> tuple[str, ...]:
    """A warning when the product's band is too narrow for the optimal strategy to plan in:
    narrower than its margins on both sides and an on-off unit's differential."""
    band = box.band
    assert band is not None  # a box with a product
    swing = box.differential_k if box.control == "on-off" else 0.0
    least = 2.0 * margin_k(band) + swing
    if band.max_c - band.min_c >= least:
        return ()
    return (
        f"the product's band ({band.max_c - band.min_c:g} K) is narrower than the optimal "
        f"strategy plans in ({least:g} K: its margins and the unit's differential): the unit "
        f"follows the thermostat at {box.setpoint_c:g} °C",
    )


@dataclass(frozen=True)
class DayInputs:
    """What a box's day is simulated from (:func:`box_with_goods`' arguments)."""

    outside: Outside
    payload_kg: FloatArray
    dt_s: float
    start_c: tuple[float, float]
    run: Run


def _constant(setpoint_c: float, payload_kg: FloatArray, start_c: tuple[float, float]) -> Setpoints:
    """A thermostat's set-points: ``setpoint_c`` all day, from ``start_c``."""
    return Setpoints(*(np.full(payload_kg.shape, setpoint_c),) * 2, start_c)


def _costlier(
    box: CargoBoxParams,
    day: DayInputs,
    planned: tuple[BoxResult, float],
    constant: tuple[BoxResult, float],
) -> bool:
    """Whether the box ``planned`` (with what its pre-cooling drew from the grid [J]) leaves
    the goods outside their band longer than the ``constant`` one, or costs more by the
    strategy's objective — or, by the energy objective, takes more from the battery."""
    weights, at_depot = day.run.weights()
    on_battery = 1.0 - day.run.plugged

    def measure(result: BoxResult, precool_j: float) -> tuple[float, float, float]:
        power = result.power_w * day.dt_s
        return (
            _kelvin_minutes(box, result.product_c, day.dt_s),
            float((power * weights).sum()) + at_depot * precool_j,
            float((power * on_battery).sum()),
        )

    plan, steady = measure(*planned), measure(*constant)
    if plan[0] > steady[0] + KELVIN_MINUTE_TOLERANCE:
        return True
    if plan[0] < steady[0] - KELVIN_MINUTE_TOLERANCE:
        return False
    energy = day.run.strategy.objective == "energy"
    return plan[1] > steady[1] or (energy and plan[2] > steady[2])


#: Goods this little outside their band count as in it [K·min]: the integration's rounding.
KELVIN_MINUTE_TOLERANCE = 1e-3


def _kelvin_minutes(box: CargoBoxParams, product_c: FloatArray | None, dt_s: float) -> float:
    """How far and how long the goods were outside their band while aboard [K·min]."""
    assert box.band is not None and product_c is not None  # a box with a product
    aboard = np.nan_to_num(product_c, nan=box.band.middle_c)
    outside_k = np.maximum(aboard - box.band.max_c, 0.0) + np.maximum(box.band.min_c - aboard, 0.0)
    return float(outside_k.sum() * dt_s / 60.0)


#: The constant set-points tried for the best thermostat, K apart: across the air's band, then
#: around the best of those.
SETPOINT_STEPS_K = (0.5, 0.1)


@dataclass(frozen=True)
class ConstantRun:
    """The best constant set-point's day: the set-point [°C], the air and the goods it starts
    from [°C] and the box following it."""

    setpoint_c: float
    start_c: tuple[float, float]
    box: BoxResult


def best_constant(box: CargoBoxParams, day: DayInputs) -> ConstantRun:
    """The fair baseline: the constant air set-point within the product's band (an on-off
    unit's: less half its differential) whose thermostat keeps the goods in their band on the
    day (as far inside it as the strategy keeps them, :func:`core.physics.strategy.margin_k`),
    for the least energy on the forecast by the strategy's objective — where none
    keeps them in, the one that leaves them out least [K·min]. Tried every
    :data:`SETPOINT_STEPS_K` on the integration's blocks (each a few milliseconds), the best
    followed at full resolution; a box leaving the depot is pre-conditioned to its
    set-point, as the thermostat's to its own."""
    band = box.band
    assert band is not None  # a box with a product
    blocks = Blocks(day.payload_kg.size, round(BOX_STEP_S / day.dt_s))
    mean = blocks.mean
    seconds = blocks.counts * day.dt_s
    mass = mean(day.payload_kg)
    _, conductance, equilibrium = _flows(box, day.outside)
    ambient = mean(day.outside[0])
    flows = (mean(conductance), mean(equilibrium), ambient)
    weight = mean(day.run.weights()[0]) * seconds
    air_j_k = air_heat_capacity_j_k(box)
    aboard = mass > 0
    swing = 0.5 * box.differential_k if box.control == "on-off" else 0.0
    low, high = min(band.min_c + swing, band.middle_c), max(band.max_c - swing, band.middle_c)

    # the goods held as the strategy holds them: its margin inside the band
    floor = min(band.min_c + margin_k(band), band.middle_c)
    ceiling = max(band.max_c - margin_k(band), band.middle_c)

    def start(setpoint_c: float) -> tuple[float, float]:
        """A box that leaves the depot pre-conditioned to the set-point, or one under way."""
        return (setpoint_c, day.start_c[1]) if day.run.from_depot else day.start_c

    def score(setpoint_c: float) -> tuple[float, float]:
        setpoint = np.full(seconds.size, setpoint_c)
        air, product, removed, added, paid = _on_blocks(
            box, (air_j_k, mass), flows, (setpoint, setpoint), seconds, start(setpoint_c)
        )
        outside_k = np.maximum(product - ceiling, 0.0) + np.maximum(floor - product, 0.0)
        minutes = float((outside_k * seconds)[aboard].sum() / 60.0)
        power = _power_w(box, ambient, air, removed, added, paid)
        return round(minutes / KELVIN_MINUTE_TOLERANCE), float((power * weight).sum())

    best = high
    span = high - low
    for step in SETPOINT_STEPS_K:
        tried = np.linspace(best - span, best + span, round(2 * span / step) + 1)
        best = min((float(t) for t in np.unique(np.clip(tried, low, high))), key=lambda t: score(t))
        span = step
    setpoints = _constant(best, day.payload_kg, start(best))
    return ConstantRun(
        best, start(best), follow(box, day.outside, day.payload_kg, day.dt_s, setpoints)
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
    nodes = two_nodes(box, (conductance, equilibrium, outside[0]), payload_kg, setpoints, dt_s)
    return _result(box, outside[0], outside[1], door_w_k, nodes, dt_s)


def _result(
    box: CargoBoxParams,
    ambient_c: FloatArray,
    solar_w: FloatArray,
    door_w_k: FloatArray,
    nodes: TwoNodes,
    dt_s: float,
) -> BoxResult:
    """The unit's power (:func:`_power_w`) and the heat flows at the air's temperature."""
    air = nodes.air_c
    power = _power_w(box, ambient_c, air, nodes.removed_w, nodes.added_w, nodes.paid_w)
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


def _power_w(
    box: CargoBoxParams,
    ambient_c: FloatArray,
    air_c: FloatArray,
    removed_w: FloatArray,
    added_w: FloatArray,
    paid_w: FloatArray,
) -> FloatArray:
    """The unit's power [W] (:func:`core.physics.cargo.unit_power_w`, eq. 12): an on-off
    unit's compressor paid for its capacity while it runs, a variable one's at its part
    load."""
    paid = paid_w if box.control == "on-off" else None
    return unit_power_w(box, ambient_c, air_c, removed_w, added_w, paid)


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
    door_w_k, conductance, equilibrium = _flows(box, outside)
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
            ambient_c=grid_outside,
            door_open=mean(door_w_k),
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
    # the air the programme keeps, from one minute's end to the next (a step up would have the
    # heater chase it); the heater holds the floor, and the air where the programme heats
    air = schedule.air_c[m:]
    ends_s = np.cumsum(counts) * dt_s
    cool_to = np.interp(
        np.arange(1, n + 1) * dt_s, np.append(0.0, ends_s), np.append(departure[0], air)
    )
    heat_to = np.repeat(np.where(schedule.added_w[m:] > 0, air, box.band.min_c), counts)
    depot = slice(0, m)
    # the grid's energy at the depot: every joule of the unit there, the compressor's at the
    # COP of the air it actually reached and its part load (the programme priced it at the
    # set-point's, at full load)
    precool_w = unit_power_w(
        box,
        day.equilibrium_c[depot],
        schedule.air_c[depot],
        schedule.removed_w[depot],
        schedule.added_w[depot],
    )
    return Setpoints(
        cool_to,
        heat_to,
        departure,
        float((precool_w * day.seconds[depot]).sum()),
        schedule.product_c[depot],
        day.seconds[depot],
        schedule.air_c[depot],
    )


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
        ambient_c=np.full(m, ambient_c),
        door_open=np.zeros(m),
    )


@dataclass(frozen=True)
class ColdChainCheck:
    """Whether the goods stayed inside their band, by the rules, from their loading on.

    Attributes
    ----------
    holds
        Never below ``min_c``, never above ``max_c + excursion_c``, and never above ``max_c``
        for longer than ``excursion_minutes`` at a time.
    product_min_c, product_max_c
        The coldest and warmest the goods were [°C], as loaded included (None: no goods).
    minutes_outside_band
        Time outside ``[min_c, max_c]`` [min], pre-cooling at the depot included.
    first_break_step
        The step of the trace in which it first breaks: −1 before departure (as loaded or
        while pre-cooling), None: it holds.
    first_break_s
        When it first breaks, seconds after departure (0: before it); None: it holds.
    reason
        Why it breaks, in words (None: it holds).
    """

    holds: bool
    product_min_c: float | None
    product_max_c: float | None
    minutes_outside_band: float
    first_break_step: int | None
    reason: str | None
    first_break_s: float | None = None


#: The goods' temperatures before a trace [°C] and how long each lasted [s]
#: (:attr:`core.physics.cargo.BoxResult.goods_before`).
Before = tuple[FloatArray, FloatArray]
NOTHING_BEFORE: Before = (np.zeros(0), np.zeros(0))


def goods_history(
    product_c: FloatArray, dt_s: float, before: Before = NOTHING_BEFORE
) -> tuple[FloatArray, FloatArray, int]:
    """The goods' temperatures [°C] from their loading on, each with how long it lasted [s]:
    ``before`` the trace (as loaded, no length; the pre-cooling at the depot), then each step
    of ``dt_s`` of the trace ``product_c`` (NaN: none aboard); and how many samples precede
    the trace."""
    values, seconds = before
    return (
        np.concatenate((values, product_c)),
        np.concatenate((seconds, np.full(product_c.size, dt_s))),
        values.size,
    )


def box_check(band: ProductBand, box: BoxResult, dt_s: float) -> ColdChainCheck:
    """The cold chain of ``box`` (its trace in steps of ``dt_s``, with a product): its goods
    from their loading on, and a unit its rating says cannot hold them."""
    assert box.product_c is not None  # a box with a product
    return check_cold_chain(band, box.product_c, dt_s, box.goods_before, box.unheld)


def check_cold_chain(
    band: ProductBand,
    product_c: FloatArray,
    dt_s: float,
    before: Before = NOTHING_BEFORE,
    unheld: tuple[int, str] | None = None,
) -> ColdChainCheck:
    """The goods' temperatures ``product_c`` per step of ``dt_s`` (NaN: none aboard), with
    what they were ``before`` the trace, held to ``band`` by the rules: the floor and the
    ceiling with its brief rise at every moment from their loading on, and each rise above
    ``max_c`` no longer than ``excursion_minutes`` (:class:`core.params.ProductBand`); broken
    too from the step ``unheld`` names on, for the reason it gives (a unit too weak for the
    band, which a steady box does not show)."""
    product_c, seconds, before_n = goods_history(product_c, dt_s, before)
    aboard = np.isfinite(product_c)
    if not aboard.any():
        return ColdChainCheck(True, None, None, 0.0, None, None)
    values = product_c[aboard]
    above = aboard & (product_c > band.max_c + 1e-9)
    outside = above | (aboard & (product_c < band.min_c - 1e-9))
    ceiling = band.max_c + band.excursion_c
    reasons = {
        "warm": aboard & (product_c > ceiling + 1e-9),
        "cold": aboard & (product_c < band.min_c - 1e-9),
        "long": _rise_too_long(above, seconds, band.excursion_minutes * 60.0),
    }
    reasons["unheld"] = np.zeros(product_c.size, dtype=bool)
    if unheld is not None:
        reasons["unheld"][before_n + unheld[0]] = True
    broken = np.flatnonzero(reasons["warm"] | reasons["cold"] | reasons["long"] | reasons["unheld"])
    if not broken.size:
        minutes = float(seconds[outside].sum() / 60.0)
        return ColdChainCheck(True, float(values.min()), float(values.max()), minutes, None, None)
    at = int(broken[0])
    kind = next(k for k, flags in reasons.items() if flags[at])
    elapsed_s = float(seconds[before_n : at + 1].sum()) if at >= before_n else 0.0
    return ColdChainCheck(
        holds=False,
        product_min_c=float(values.min()),
        product_max_c=float(values.max()),
        minutes_outside_band=float(seconds[outside].sum() / 60.0),
        first_break_step=at - before_n if at >= before_n else -1,
        reason=(
            unheld[1]
            if kind == "unheld" and unheld is not None
            else _why(band, kind, float(product_c[at]), at < before_n)
        ),
        first_break_s=elapsed_s,
    )


def _rise_too_long(above: np.ndarray, seconds: FloatArray, limit_s: float) -> np.ndarray:
    """The samples of each unbroken stretch ``above`` the band at which it has lasted longer
    than ``limit_s`` [s]."""
    lasted = np.cumsum(np.where(above, seconds, 0.0))
    # each stretch counts from the time lasted before it began
    began = np.maximum.accumulate(np.where(above, 0.0, lasted))
    return above & (lasted - began > limit_s + 1e-9)


def _why(band: ProductBand, kind: str, at_c: float, before_departure: bool) -> str:
    """The reason a chain breaks, in words."""
    when = " before departure (as loaded or at the depot)" if before_departure else ""
    if kind == "warm":
        return (
            f"the goods reached {at_c:.1f} °C{when}, above their band's "
            f"{band.max_c + band.excursion_c:g} °C"
        )
    if kind == "cold":
        return (
            f"the goods fell to {at_c:.1f} °C{when}, below their band's floor of {band.min_c:g} °C"
        )
    return (
        f"the goods stayed above their band's {band.max_c:g} °C for longer than the brief rise "
        f"the rules allow ({band.excursion_minutes:g} min){when}"
    )
