import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from core.arrays import reflected_cumsum
from core.params import BatteryParams
from core.physics.battery import (
    JOULES_PER_KWH,
    SOC_TOLERANCE,
    battery_energy_j,
    capacity_factor,
    discharge,
    energy_factor,
)

KWH = JOULES_PER_KWH


def test_reflected_cumsum_matches_loop():
    rng = np.random.default_rng(1)
    x = rng.normal(size=500)
    expected, w = [], 2.0
    for value in x:
        w = max(0.0, w + value)
        expected.append(w)
    assert reflected_cumsum(x, initial=2.0) == pytest.approx(expected)


def test_soc_falls_with_energy_and_stops_at_full():
    battery = BatteryParams(usable_capacity_kwh=10, initial_soc=1.0, min_soc=0.1)
    soc, _ = discharge(battery, np.array([-1, 2, 3, -1]) * KWH)
    # regen at full is lost; then 1.0 → 0.8 → 0.5 → 0.6
    assert soc == pytest.approx([1.0, 1.0, 0.8, 0.5, 0.6])


def test_verdict_feasible_with_margin_and_required_capacity():
    battery = BatteryParams(usable_capacity_kwh=10, initial_soc=0.9, min_soc=0.1)
    energy = np.array([2.0, 3.0, -1.0]) * KWH
    _, result = discharge(battery, energy)
    assert result.feasible and result.first_infeasible_index is None
    assert result.min_soc == pytest.approx(0.4) and result.final_soc == pytest.approx(0.5)
    assert result.margin_kwh == pytest.approx(3.0)  # (0.4 − 0.1) · 10 kWh
    assert result.required_capacity_kwh == pytest.approx(5.0 / 0.8)


def test_verdict_infeasible_names_first_sample_below_reserve():
    battery = BatteryParams(usable_capacity_kwh=10, initial_soc=1.0, min_soc=0.2)
    energy = np.array([4.0, 3.0, 2.0, 1.0]) * KWH  # soc 1, .6, .3, .1, 0
    _, result = discharge(battery, energy)
    assert not result.feasible
    assert result.first_infeasible_index == 3
    assert result.margin_kwh == pytest.approx(-2.0)
    assert result.required_capacity_kwh == pytest.approx(10.0 / 0.8)


def test_temperature_derating_follows_aaa_2019():
    # AAA "Electric Vehicle Range Testing" (2019), HVAC off, against 23.9 °C: at −6.7 °C the
    # economy fell 9 % (energy × 1/0.91) and the range 12 % (usable energy 0.88/0.91).
    battery = BatteryParams(temperature_derating=True)
    assert energy_factor(battery, -6.7) == pytest.approx(1 / 0.91)
    assert capacity_factor(battery, -6.7) == pytest.approx(0.88 / 0.91)
    assert energy_factor(battery, 23.9) == 1.0 and capacity_factor(battery, 23.9) == 1.0
    # 95 °F (35 °C): economy −5 %; the range fell less (−4 %), so no capacity is taken away
    assert energy_factor(battery, 35.0) == pytest.approx(1 / 0.95)
    assert capacity_factor(battery, 35.0) == 1.0
    # the paper's battery knows no temperature
    assert energy_factor(BatteryParams(), -20.0) == 1.0
    assert capacity_factor(BatteryParams(), -20.0) == 1.0


def test_derated_discharge_in_the_cold():
    battery = BatteryParams(usable_capacity_kwh=10, temperature_derating=True)
    drawn = battery_energy_j(battery, np.array([1.0, -1.0]) * KWH, -6.7)
    # discharging costs 1/0.91 kWh per kWh; regenerating stores only 0.91
    assert drawn == pytest.approx(np.array([1 / 0.91, -0.91]) * KWH)
    soc, result = discharge(battery, np.array([1 / 0.91]) * KWH, capacity_factor(battery, -6.7))
    assert soc[-1] == pytest.approx(1 - (1 / 0.91) / (10 * 0.88 / 0.91))
    assert result.usable_capacity_kwh == pytest.approx(10 * 0.88 / 0.91)


def test_recharge_at_the_plug():
    battery = BatteryParams(usable_capacity_kwh=10, charging_efficiency=0.9)
    _, result = discharge(battery, np.array([2.0, 1.0]) * KWH)
    assert result.recharge_kwh == pytest.approx(3.0 / 0.9)


def test_an_empty_battery_is_never_feasible_even_without_a_reserve():
    # The trust issue's case: 23.3 kWh from a 10 kWh battery with min_soc 0. By hand: the
    # state of charge goes 1 → 1 − 23.3/10 = −1.33, the margin is −13.3 kWh.
    battery = BatteryParams(usable_capacity_kwh=10, initial_soc=1.0, min_soc=0.0)
    soc, result = discharge(battery, np.array([5.0, 10.0, 8.3]) * KWH)
    assert soc == pytest.approx([1.0, 0.5, -0.5, -1.33])
    assert not result.feasible
    assert result.min_soc == pytest.approx(-1.33) and result.final_soc == pytest.approx(-1.33)
    assert result.margin_kwh == pytest.approx(-13.3)
    assert result.first_infeasible_index == 2


def test_exactly_empty_holds_a_reserve_of_zero():
    battery = BatteryParams(usable_capacity_kwh=10, initial_soc=1.0, min_soc=0.0)
    _, result = discharge(battery, np.array([4.0, 6.0]) * KWH)
    assert result.feasible and result.min_soc == pytest.approx(0.0, abs=1e-12)


@settings(max_examples=300, deadline=None)
@given(
    energies=st.lists(st.floats(-5, 12), min_size=1, max_size=40),
    capacity=st.floats(1, 200),
    initial=st.floats(0.2, 1.0),
    reserve=st.floats(0.0, 0.19),
    share=st.floats(0.5, 1.0),
)
def test_the_verdict_agrees_with_its_series(energies, capacity, initial, reserve, share):
    """One series, three figures: feasible ⇔ min_soc ≥ reserve ⇔ margin ≥ 0, the lowest and
    last values are the series', and the margin is the lowest value's distance to the
    reserve in kWh."""
    battery = BatteryParams(usable_capacity_kwh=capacity, initial_soc=initial, min_soc=reserve)
    soc, result = discharge(battery, np.array(energies) * KWH, share)
    assert result.min_soc == soc.min() and result.final_soc == soc[-1]
    assert result.margin_kwh == pytest.approx((soc.min() - reserve) * capacity * share, abs=1e-9)
    assert result.feasible == bool(soc.min() >= reserve - SOC_TOLERANCE)
    assert result.feasible == (result.margin_kwh >= -SOC_TOLERANCE * capacity * share)
    if result.first_infeasible_index is not None:
        assert soc[result.first_infeasible_index] < reserve
        assert (soc[: result.first_infeasible_index] >= reserve - SOC_TOLERANCE).all()
