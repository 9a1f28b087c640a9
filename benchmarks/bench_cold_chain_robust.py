"""The refrigeration strategy against its offline optimum and under disturbance.

Each test day of :mod:`benchmarks.bench_cold_chain` is planned through the plan's entry point
(``app.operations.plan.run_plan``, what ``POST /v1/plans`` runs); the box's inputs of the
day the plan simulates (the outside, the sun, the doors, the goods aboard, the plugged-in
spells, per second) are taken as the plan's simulation hands them to
:func:`core.physics.cold_chain.box_with_goods`. Then:

* **the gap to the offline optimum** — the same model solved with perfect knowledge on a grid
  of :data:`core.physics.cold_chain.BOX_STEP_S` (the physics' own step) instead of the
  strategy's minute, both schedules followed by the full physics: the battery energy of the
  plan's schedule over the fine one's;
* **:data:`REPLAYS` disturbed replays** of the hot chilled and the hot frozen day — each
  stop's door open ±50 % (uniform), its arrival moved around the plan (a random walk of σ
  :data:`ARRIVAL_STEP_S` per stop, within ±:data:`ARRIVAL_S`), the day :data:`AMBIENT_K`
  warmer than its forecast. The optimal strategy departs with the plan's choice and is
  re-planned at each stop from the box's actual state (air and goods) over the rest of the
  plan — :func:`core.physics.cold_chain.plan_unit` from a start under way, what a plan from
  ``start_state`` runs for the box: the schedule, or the best constant set-point where that
  is better; the thermostat holds its set-point. The share of replays whose goods stayed
  inside their band for each, and whether the verdict
  (:func:`core.physics.cold_chain.check_cold_chain`, the answer's) agreed with the
  temperatures in every one.
"""

from __future__ import annotations

import functools
import itertools
import multiprocessing
import os
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

import core.physics.cold_chain as cold_chain_module
import core.physics.simulate as simulate_module
from app.operations.plan import run_plan
from app.schemas.plans import PlanRequest
from app.settings import Settings
from benchmarks.bench_cold_chain import test_days
from benchmarks.common import print_table
from core.arrays import FloatArray
from core.params import CargoBoxParams
from core.physics.battery import JOULES_PER_KWH
from core.physics.cargo import BoxResult
from core.physics.cold_chain import (
    BOX_STEP_S,
    DayInputs,
    Run,
    Setpoints,
    best_constant,
    check_cold_chain,
    follow,
    plan_setpoints,
    plan_unit,
)
from core.physics.strategy import GRID_WEIGHT
from core.physics.strategy import BoxDay as StrategyDay

#: Replays of each day (``COLDROUTE_BENCH_REPLAYS`` to change).
REPLAYS = int(os.environ.get("COLDROUTE_BENCH_REPLAYS", "200"))
#: How much warmer the day is than its forecast, unforeseen [K].
AMBIENT_K = 3.0
#: The days replayed: the hot chilled day and the hot frozen one.
REPLAYED = ("summer, chilled dairy", "summer, frozen")
#: Most an arrival moves from the plan's [s], and the step of its random walk per stop [s].
ARRIVAL_S = 15 * 60.0
ARRIVAL_STEP_S = 5 * 60.0
#: A door is open this share of its planned time at least and at most [–].
DOOR_SHARE = (0.5, 1.5)
#: A leg between stops takes at least this share of its planned time [–].
SHORTEST_LEG = 0.3


@dataclass(frozen=True)
class BoxDay:
    """A planned day's box inputs, per second: ``outside`` (ambient [°C], sun [W], door's
    open share), the goods aboard [kg], the plugged-in share, the start (air, goods) [°C],
    and the stops' doors as sample ranges ``[start, end)``."""

    box: CargoBoxParams
    outside: tuple[FloatArray, FloatArray, FloatArray]
    payload_kg: FloatArray
    plugged: FloatArray
    start_c: tuple[float, float]
    run: Run
    doors: list[tuple[int, int]]

    def rest(self, planned_at: int, clock_at: int) -> tuple[Any, FloatArray, FloatArray]:
        """The plan from its sample ``planned_at`` on, its outside at the clock from
        ``clock_at`` on: what a re-plan forecasts."""
        ambient, sun, door = self.outside
        clock = np.minimum(clock_at + np.arange(ambient.size - planned_at), ambient.size - 1)
        outside = (ambient[clock], sun[clock], door[planned_at:])
        return outside, self.payload_kg[planned_at:], self.plugged[planned_at:]


def captured_day(body: dict[str, Any]) -> BoxDay:
    """The box's inputs of the day ``body`` plans with the optimal strategy (module
    docstring)."""
    calls: list[tuple[Any, ...]] = []
    original = simulate_module.box_with_goods

    def capture(*args: Any) -> BoxResult:
        calls.append(args)
        return original(*args)

    simulate_module.box_with_goods = capture
    try:
        run_plan(
            PlanRequest.model_validate(body | {"refrigeration": {"strategy": "optimal"}}),
            Settings(),
        )
    finally:
        simulate_module.box_with_goods = original
    box, outside, payload, dt_s, start_c, run = calls[-1]  # the plan's own simulation
    assert dt_s == 1.0 and not np.any(run.plugged), "a day at 1 s without charges"
    door = outside[2] > 0
    edges = np.flatnonzero(np.diff(np.concatenate(([0], door.astype(int), [0]))))
    doors = list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))
    return BoxDay(box, outside, payload, run.plugged, start_c, run, doors)


def disturbed(day: BoxDay, rng: np.random.Generator) -> tuple[BoxDay, list[int]]:
    """The day as it went (module docstring), and each stop's actual arrival sample."""
    delay, moves = 0.0, []
    for _ in day.doors:
        delay = float(np.clip(delay + rng.normal(0.0, ARRIVAL_STEP_S), -ARRIVAL_S, ARRIVAL_S))
        moves.append(delay)
    # actual door runs: moved, their lengths drawn; legs kept at a share of the plan's
    actual: list[tuple[int, int]] = []
    anchors_actual, anchors_planned = [0.0], [0.0]
    last_end_actual, last_end_planned = 0.0, 0.0
    for (start, end), move in zip(day.doors, moves, strict=True):
        leg = start - last_end_planned
        begin = max(start + move, last_end_actual + SHORTEST_LEG * leg)
        length = (end - start) * rng.uniform(*DOOR_SHARE)
        actual.append((round(begin), round(begin + length)))
        anchors_actual += [begin, begin + length]
        anchors_planned += [float(start), float(end)]
        last_end_actual, last_end_planned = begin + length, float(end)
    n = day.payload_kg.size
    total = round(last_end_actual + n - last_end_planned)
    anchors_actual.append(float(total))
    anchors_planned.append(float(n))
    t = np.arange(total) + 0.5
    planned = np.minimum(np.interp(t, anchors_actual, anchors_planned).astype(int), n - 1)
    clock = np.minimum(np.arange(total), n - 1)
    ambient, sun, _ = day.outside
    door = np.zeros(total)
    for begin, end in actual:
        door[begin:end] = 1.0
    outside = (ambient[clock] + AMBIENT_K, sun[clock], door)
    went = replace(
        day,
        outside=outside,
        payload_kg=day.payload_kg[planned],
        plugged=day.plugged[planned],
        doors=actual,
    )
    return went, [begin for begin, _ in actual]


def replayed(
    day: BoxDay, went: BoxDay, arrivals: list[int], optimal: bool
) -> tuple[bool, float, bool]:
    """Whether the goods stayed in their band as the day ``went``, and the unit's battery
    energy [kWh]: the thermostat, or the optimal strategy re-planned at each arrival."""
    box, n = day.box, went.payload_kg.size
    if not optimal:
        thermostat = np.full(n, box.setpoint_c)
        result = follow(
            box, went.outside, went.payload_kg, 1.0, Setpoints(thermostat, thermostat, day.start_c)
        )
        return _verdict(box, [result])
    plan = plan_unit(box, DayInputs(day.outside, day.payload_kg, 1.0, day.start_c, day.run))
    state, results = plan.setpoints.departure_c, []
    bounds = [0, *arrivals, n]
    for k, (a, b) in enumerate(itertools.pairwise(bounds)):
        if k:  # arrived at stop k: the rest of the plan from the box's state
            outside, payload, plugged = day.rest(day.doors[k - 1][0], a)
            run = Run(day.run.strategy, plugged, from_depot=False)
            plan = plan_unit(box, DayInputs(outside, payload, 1.0, state, run))
        segment = slice(a, b)
        planned = plan.setpoints
        setpoints = Setpoints(
            _first(planned.cool_to_c, b - a), _first(planned.heat_to_c, b - a), state
        )
        part = (went.outside[0][segment], went.outside[1][segment], went.outside[2][segment])
        result = follow(box, part, went.payload_kg[segment], 1.0, setpoints)
        goods = result.product_c[np.isfinite(result.product_c)]
        state = (float(result.temperature_c[-1]), float(goods[-1]) if goods.size else state[1])
        results.append(result)
    return _verdict(box, results)


def _first(values: FloatArray, n: int) -> FloatArray:
    """The first ``n`` of ``values``, the last repeated past their end."""
    return values[np.minimum(np.arange(n), values.size - 1)]


def _verdict(box: CargoBoxParams, results: list[BoxResult]) -> tuple[bool, float, bool]:
    """Whether the goods stayed inside their band throughout, the battery's kWh, and whether
    the verdict agrees: it holds exactly where the goods never left the band's ceiling with
    its brief rise nor its floor, and no rise outlasted its limit."""
    band = box.band
    assert band is not None and all(r.product_c is not None for r in results)
    product = np.concatenate([r.product_c for r in results])  # type: ignore[misc]
    power = np.concatenate([r.power_w for r in results])
    aboard = product[np.isfinite(product)]
    inside = bool(np.all((aboard >= band.min_c - 1e-9) & (aboard <= band.max_c + 1e-9)))
    verdict = check_cold_chain(band, product, 1.0)
    within = bool(
        np.all((aboard >= band.min_c - 1e-9) & (aboard <= band.max_c + band.excursion_c + 1e-9))
    )
    agrees = (not verdict.holds) or within
    return inside, float(power.sum()) / JOULES_PER_KWH, agrees


def _replay_many(
    args: tuple[BoxDay, int, int],
) -> list[tuple[bool, float, bool, bool, float, bool]]:
    day, first, count = args
    out = []
    for seed in range(first, first + count):
        went, arrivals = disturbed(day, np.random.default_rng(seed))
        out.append((*replayed(day, went, arrivals, False), *replayed(day, went, arrivals, True)))
    return out


def replays(day: BoxDay, count: int) -> list[tuple[bool, float, bool, bool, float, bool]]:
    """``count`` seeded replays of ``day`` on the machine's cores: (in band, kWh, verdict
    agrees) of the thermostat's and of the optimal strategy's, each."""
    workers = max(os.cpu_count() or 1, 1)
    chunks = [
        (day, k * count // workers, (k + 1) * count // workers - k * count // workers)
        for k in range(workers)
    ]
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        return [row for part in pool.map(_replay_many, chunks) for row in part]


def offline_gap(day: BoxDay) -> tuple[float, float]:
    """What the plan's schedule and the same model's optimum on the physics' own grid each
    cost when followed by the physics, in the strategy's measure: the battery's kWh and the
    grid's at :data:`core.physics.strategy.GRID_WEIGHT` (pre-cooling, plugged-in spells)."""

    def followed(grid_s: float | None) -> float:
        box, outside, payload = day.box, day.outside, day.payload_kg
        plan = plan_setpoints(box, outside, payload, 1.0, day.start_c, day.run, grid_s)
        power = follow(box, outside, payload, 1.0, plan).power_w
        weight = 1.0 - (1.0 - GRID_WEIGHT) * day.plugged
        return (float((power * weight).sum()) + GRID_WEIGHT * plan.precool_grid_j) / JOULES_PER_KWH

    return followed(None), followed(BOX_STEP_S)  # the plan's own grid, and the physics'


#: The strategy's mechanisms, added one by one in this order (:func:`decomposition`).
MECHANISMS = ("the goods' thermal mass", "door timing", "COP", "pre-cooling")


def decomposition(day: BoxDay) -> tuple[float, list[tuple[float, float]]]:
    """The best constant set-point's battery energy on ``day`` [kWh] and the battery saving
    against it [share of it] as the programme learns of each of :data:`MECHANISMS` in turn,
    each schedule followed by the full physics: first the air and the goods let float within
    the band (the doors' heat spread over the day, its COP one mean, no pre-cooling), then
    the doors when they open, then the COP of each step, then pre-cooling at the depot —
    the last is the product's own schedule. Each mechanism's share is its step's gain; with
    each saving the goods' warmest [°C] (a programme blind to the doors plans the air in its
    band through them, and the goods end nearer their ceiling than planned)."""
    box = day.box
    strategy = day.run.strategy
    inputs = DayInputs(day.outside, day.payload_kg, 1.0, day.start_c, day.run)
    best = best_constant(box, inputs)
    on_battery = 1.0 - day.plugged
    best_kwh = float((best.box.power_w * on_battery).sum()) / JOULES_PER_KWH
    savings = []
    original = cold_chain_module.optimal_schedule
    for known in range(1, len(MECHANISMS) + 1):
        precool = strategy.precool_minutes if known >= 4 else 0.0
        run = replace(day.run, strategy=strategy.model_copy(update={"precool_minutes": precool}))
        cold_chain_module.optimal_schedule = functools.partial(_blind, original, known)
        try:
            plan = plan_setpoints(box, day.outside, day.payload_kg, 1.0, day.start_c, run)
        finally:
            cold_chain_module.optimal_schedule = original
        result = follow(box, day.outside, day.payload_kg, 1.0, plan)
        saved = 1.0 - float((result.power_w * on_battery).sum()) / JOULES_PER_KWH / best_kwh
        savings.append((saved, float(np.nanmax(result.product_c))))
    return best_kwh, savings


def _blind(original: Any, known: int, *args: Any) -> Any:
    """The programme ``original`` on its day as :func:`_unaware` of the later mechanisms."""
    box, band, air_j_k, grid_day, *rest = args
    return original(box, band, air_j_k, _unaware(grid_day, known, rest), *rest)


def _unaware(grid_day: StrategyDay, known: int, rest: list[Any]) -> StrategyDay:
    """``grid_day`` as a programme that knows only the first ``known`` mechanisms sees it:
    the doors' conductance spread evenly over the day after the depot's steps (``rest``:
    the start and the depot's steps), one mean COP."""
    held = rest[1] if len(rest) > 1 else 0
    changes: dict[str, Any] = {}
    if known < 2:
        door = np.asarray(grid_day.door_open, dtype=float)
        wall = grid_day.conductance_w_k - door
        spread = door.copy()
        spread[held:] = door[held:].mean()
        heat = (
            grid_day.conductance_w_k * grid_day.equilibrium_c + (spread - door) * grid_day.ambient_c
        )
        conductance = wall + spread
        changes |= {
            "conductance_w_k": conductance,
            "equilibrium_c": heat / conductance,
            "door_open": np.zeros_like(door),
        }
    if known < 3:
        changes["cop"] = np.full_like(grid_day.cop, float(np.mean(grid_day.cop)))
    return replace(grid_day, **changes)


def main() -> None:
    shares = []
    for name, body in test_days():
        best_kwh, savings = decomposition(captured_day(body))
        steps = np.diff([0.0, *(saved for saved, _ in savings)])
        shares.append(
            [name, f"{best_kwh:.2f}", f"{savings[-1][0] * 100:+.1f} %"]
            + [
                f"{step * 100:+.1f} pp ({warmest:.1f})"
                for step, (_, warmest) in zip(steps, savings, strict=True)
            ]
        )
    print_table(
        "Where the optimal schedule's battery saving against the best constant set-point comes "
        "from (each mechanism added in turn, followed by the full physics)",
        ["day", "best constant [kWh]", "saving", *(f"{m} (goods' max [°C])" for m in MECHANISMS)],
        shares,
    )
    rows = []
    for name, body in test_days():
        if name not in REPLAYED:
            continue
        day = captured_day(body)
        minute, fine = offline_gap(day)
        outcomes = np.array(replays(day, REPLAYS))
        rows.append(
            [
                name,
                f"{minute:.3f}",
                f"{fine:.3f}",
                f"{(minute / fine - 1) * 100:+.2f} %",
                f"{outcomes[:, 0].mean():.1%}",
                f"{outcomes[:, 3].mean():.1%}",
                f"{outcomes[:, 2].all() and outcomes[:, 5].all()}",
                f"{outcomes[:, 1].mean():.2f} / {outcomes[:, 4].mean():.2f}",
            ]
        )
    print_table(
        f"Refrigeration strategy: offline optimum and {REPLAYS} disturbed replays per day "
        f"(doors ±50 %, arrivals ±15 min, {AMBIENT_K:g} °C warmer than forecast, re-planned at "
        "each stop)",
        [
            "day",
            "plan's schedule [kWh, grid a tenth]",
            "offline optimum at 10 s [kWh, grid a tenth]",
            "gap",
            "in band: thermostat",
            "in band: optimal",
            "verdict agrees (every replay)",
            "mean battery kWh thermostat / optimal",
        ],
        rows,
    )


if __name__ == "__main__":
    main()
