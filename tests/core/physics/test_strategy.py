"""The refrigeration unit's optimal strategy (core/physics/strategy.py through
cold_chain.box_with_goods): an empty box let warm to its band's ceiling against a thermostat by
hand, the goods' thermal mass and pre-cooling spared from the battery with the goods inside
their band, the simulation following the programme's schedule, a winter day kept above the
floor by the heater, a day the unit cannot hold answered with the band broken, the cost
objective's weights by hand, an on-off unit's runs and pauses, and the receding horizon's
re-plan from a warm box under way."""

from __future__ import annotations

import math

import numpy as np
import pytest

from core.params import PRODUCT_CLASSES, CargoBoxParams, RefrigerationStrategy, get_preset
from core.physics.cargo import air_heat_capacity_j_k
from core.physics.cold_chain import (
    Run,
    _flows,
    box_with_goods,
    check_cold_chain,
    follow,
    grid_step_s,
    plan_setpoints,
    two_nodes,
)
from core.physics.strategy import MARGIN_K

HOUR = 3600
THERMOSTAT = RefrigerationStrategy()
OPTIMAL = RefrigerationStrategy(strategy="optimal", precool_minutes=0.0)


def day(box, strategy, hours=8.0, ambient=30.0, sun=0.0, payload=None, doors=(), start=None):
    n = int(hours * HOUR)
    door = np.zeros(n)
    for t in doors:
        door[t : t + 120] = 1.0
    mass = np.zeros(n) if payload is None else np.asarray(payload, dtype=float)
    begin = start or (box.setpoint_c, box.load_c)
    outside = (np.full(n, ambient), np.full(n, sun), door)
    return box_with_goods(box, outside, mass, 1.0, begin, Run(strategy, np.zeros(n)))


def reference_box(**changes) -> CargoBoxParams:
    """The ev-van-3.5t-reefer's box with chilled dairy (0–6 °C, set-point 3 °C) at 4 °C."""
    box = get_preset("ev-van-3.5t-reefer").cargo_box
    return box.model_copy(
        update={"product": "chilled-dairy", "load_temperature_c": 4.0, "setpoint_c": 3.0} | changes
    )


def cooling_kwh(result, box) -> float:
    return float((result.power_w - box.standby_power_w).sum()) / 3.6e6


def test_an_empty_box_is_let_warm_to_its_bands_ceiling_and_held_there():
    # no goods, a constant COP: the thermostat removes α·A·(30 − 3) all day; the optimum lets
    # the air warm freely (nothing removed) from 3 to dairy's 6 °C — for τ·ln(27/24) with
    # τ = C_a/(α·A) — and removes α·A·(30 − 6) from then on
    box = reference_box(cop_model="constant", cop=2.0, standby_power_w=0.0)
    hours = 10.0
    thermostat = day(box, THERMOSTAT, hours=hours)
    optimal = day(box, OPTIMAL, hours=hours)
    assert optimal.temperature_c[-1] == pytest.approx(6.0, abs=0.01)
    tau_s = air_heat_capacity_j_k(box) / (box.wall_heat_transfer_w_m2k * box.heat_transfer_area_m2)
    warming_s = tau_s * math.log(27.0 / 24.0)  # about 36 min
    by_hand = 24.0 * (hours * HOUR - warming_s) / (27.0 * hours * HOUR)
    ratio = cooling_kwh(optimal, box) / cooling_kwh(thermostat, box)
    assert ratio == pytest.approx(by_hand, abs=0.005)


def summer_day(box, strategy):
    """30 stops of 2-minute doors 940 s apart, 500 kg delivered evenly, 30 °C, 250 W of sun."""
    n = 8 * HOUR
    stops = 600 + np.arange(30) * 940
    delivered = np.searchsorted(stops + 120, np.arange(n), side="right")
    payload = 500.0 * (1.0 - delivered / 30)
    return day(box, strategy, payload=payload, doors=stops.tolist(), sun=250.0)


def test_the_goods_mass_and_pre_cooling_spare_the_battery_inside_the_band():
    box = reference_box()
    band = PRODUCT_CLASSES["chilled-dairy"]
    thermostat = summer_day(box, THERMOSTAT)
    results = {
        minutes: summer_day(box, RefrigerationStrategy(strategy="optimal", precool_minutes=minutes))
        for minutes in (0.0, 60.0)
    }
    spared = {m: 1.0 - r.power_w.sum() / thermostat.power_w.sum() for m, r in results.items()}
    # the goods (500 kg from 4 °C) warm towards 6 °C less the margin instead of being cooled
    # to 3 °C: about a tenth of the unit's energy; an hour of pre-cooling on the grid more
    assert spared[0.0] > 0.08 and spared[60.0] > spared[0.0] + 0.02
    assert results[0.0].precool_grid_j == 0.0 < results[60.0].precool_grid_j
    for result in results.values():
        check = check_cold_chain(band, result.product_c, 1.0)
        assert check.holds and check.product_max_c <= band.max_c - MARGIN_K + 0.05
        # the thermostat's draw on the same day rides along for the answer's comparison
        assert result.thermostat_power_w == pytest.approx(thermostat.power_w)


def test_the_simulation_follows_the_programmes_schedule():
    box = reference_box()
    result = summer_day(box, OPTIMAL)
    assert result.setpoint_c is not None
    # the thermostat on the schedule reaches each set-point at the end of the programme's
    # minutes, but where a door outruns the unit
    minute_ends = np.arange(59, 8 * HOUR, 60)
    gap = np.abs(result.temperature_c[minute_ends] - result.setpoint_c[minute_ends])
    assert np.median(gap) < 0.05
    # the air floats within the band and is pulled down before the doors open
    assert box.band is not None
    assert result.setpoint_c.min() >= box.band.min_c - 1e-6
    assert result.setpoint_c.max() <= box.band.max_c + 1e-6


def test_a_winter_day_keeps_chilled_goods_above_their_floor_with_the_heater():
    box = reference_box(heater_enabled=True, load_temperature_c=3.0)
    band = PRODUCT_CLASSES["chilled-dairy"]
    result = day(box, OPTIMAL, ambient=-15.0, payload=np.full(6 * HOUR, 500.0), hours=6.0)
    check = check_cold_chain(band, result.product_c, 1.0)
    assert check.holds and check.product_min_c >= band.min_c + MARGIN_K - 0.05
    # heating less than the thermostat: the air is let cool towards the floor, not held at 3
    assert result.power_w.sum() < result.thermostat_power_w.sum()


def test_a_day_the_unit_cannot_hold_is_answered_with_the_band_broken():
    # a 300 W unit against 30 minutes of open door at 35 °C with chilled minced meat (≤ 2 °C)
    box = reference_box(product="chilled-minced-meat", setpoint_c=0.5, load_temperature_c=1.5)
    box = box.model_copy(update={"refrigeration_capacity_w": 300.0})
    doors = [600 + 120 * k for k in range(15)]
    result = day(
        box, OPTIMAL, ambient=35.0, payload=np.full(2 * HOUR, 500.0), hours=2.0, doors=doors
    )
    check = check_cold_chain(PRODUCT_CLASSES["chilled-minced-meat"], result.product_c, 1.0)
    assert not check.holds and "above their band's 2 °C" in (check.reason or "")


def test_the_objectives_weights_by_hand():
    # a quarter of the first step and all of the second plugged in, at 0.40 per kWh there;
    # the depot at 0.30 with charging at 90 %: a battery kWh costs 0.30/0.9 = 0.333
    plugged = np.array([0.25, 1.0, 0.0])
    energy, at_depot = Run(OPTIMAL, plugged).weights()
    assert energy == pytest.approx([0.75 + 0.025, 0.1, 1.0]) and at_depot == 0.1
    cost = OPTIMAL.model_copy(update={"objective": "cost", "depot_price_per_kwh": 0.3})
    weights, at_depot = Run(cost, plugged, priced=plugged * 0.4, charging_efficiency=0.9).weights()
    battery = 0.3 / 0.9
    assert weights == pytest.approx([0.75 + 0.1 / battery, 0.4 / battery, 1.0])
    assert at_depot == pytest.approx(0.9)  # a grid kWh at the depot against a refilled one


def test_an_on_off_unit_runs_full_or_not_at_all_for_its_shortest_run_and_pause():
    # the thermostat on a fixed-speed unit (2 K differential, 3-minute runs and pauses): the
    # heat it removes is its capacity or none, every run and pause but the last lasts at
    # least 3 minutes, and the air swings about the set-point by about the differential
    box = reference_box(mode="dynamic", control="on-off", min_on_minutes=3.0, min_off_minutes=3.0)
    n = 4 * HOUR
    outside = (np.full(n, 30.0), np.zeros(n), np.zeros(n))
    nodes = two_nodes(
        box,
        air_heat_capacity_j_k(box),
        *_flows(box, outside)[1:],
        np.full(n, 500.0),
        np.full(n, box.setpoint_c),
        1.0,
        (box.setpoint_c, box.load_c),
    )
    capacity = box.refrigeration_capacity_w
    assert set(np.unique(nodes.removed_w)) == {0.0, capacity}
    on = nodes.removed_w > 0
    edges = np.flatnonzero(np.diff(on.astype(int))) + 1
    spells = np.diff(np.concatenate(([0], edges, [n])))
    assert len(spells) > 6  # it switches many times in four hours
    assert spells[1:-1].min() >= 180  # the first spell starts at rest; the last is cut off
    settled = nodes.air_c[HOUR:]
    assert settled.max() - settled.min() == pytest.approx(box.differential_k, abs=1.0)


def test_a_re_plan_from_a_warm_box_under_way_brings_the_air_back_and_keeps_the_goods():
    # the receding horizon: a long stop has left the air at 12 °C and the goods at 5.2 °C;
    # the rest of the day planned from that state (no depot minutes) keeps the goods inside
    # dairy's 0–6 °C band and draws less than the thermostat from the same state
    box = reference_box()
    n = 3 * HOUR
    outside = (np.full(n, 30.0), np.full(n, 250.0), np.zeros(n))
    payload = np.full(n, 300.0)
    start = (12.0, 5.2)
    run = Run(RefrigerationStrategy(strategy="optimal"), np.zeros(n), from_depot=False)
    planned = plan_setpoints(box, outside, payload, 1.0, start, run)
    assert planned.departure_c == start and planned.precool_grid_j == 0.0
    followed = follow(box, outside, payload, 1.0, planned)
    check = check_cold_chain(PRODUCT_CLASSES["chilled-dairy"], followed.product_c, 1.0)
    assert check.holds and check.product_max_c <= 6.0
    kept = box_with_goods(box, outside, payload, 1.0, start, Run(THERMOSTAT, np.zeros(n)))
    assert followed.power_w.sum() < kept.power_w.sum()


def test_days_on_the_road_are_planned_on_a_coarser_grid_and_still_hold():
    # a minute up to a day of 1,440 minutes; three days: 3 minutes, 1,440 steps again
    assert grid_step_s(8 * HOUR) == 60.0 and grid_step_s(24 * HOUR) == 60.0
    assert grid_step_s(72 * HOUR) == pytest.approx(180.0)
    # three days at 30 °C with the goods aboard, on a one-minute trace: the coarse programme
    # keeps them inside dairy's band and spares the battery against the thermostat
    box = reference_box()
    n = 72 * 60
    outside = (np.full(n, 30.0), np.full(n, 250.0), np.zeros(n))
    payload = np.full(n, 400.0)
    start = (box.setpoint_c, box.load_c)
    optimal = box_with_goods(box, outside, payload, 60.0, start, Run(OPTIMAL, np.zeros(n)))
    check = check_cold_chain(PRODUCT_CLASSES["chilled-dairy"], optimal.product_c, 60.0)
    assert check.holds
    assert optimal.power_w.sum() < optimal.thermostat_power_w.sum()
