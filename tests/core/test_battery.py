import numpy as np
import pytest

from core.arrays import reflected_cumsum
from core.battery import JOULES_PER_KWH, state_of_charge, verdict
from core.params import BatteryParams

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
    soc = state_of_charge(battery, np.array([-1, 2, 3, -1]) * KWH)
    # regen at full is lost; then 1.0 → 0.8 → 0.5 → 0.6
    assert soc == pytest.approx([1.0, 1.0, 0.8, 0.5, 0.6])


def test_verdict_feasible_with_margin_and_required_capacity():
    battery = BatteryParams(usable_capacity_kwh=10, initial_soc=0.9, min_soc=0.1)
    energy = np.array([2.0, 3.0, -1.0]) * KWH
    result = verdict(battery, state_of_charge(battery, energy), energy)
    assert result.feasible and result.first_infeasible_index is None
    assert result.min_soc == pytest.approx(0.4) and result.final_soc == pytest.approx(0.5)
    assert result.margin_kwh == pytest.approx(3.0)  # (0.4 − 0.1) · 10 kWh
    assert result.required_capacity_kwh == pytest.approx(5.0 / 0.8)


def test_verdict_infeasible_names_first_sample_below_reserve():
    battery = BatteryParams(usable_capacity_kwh=10, initial_soc=1.0, min_soc=0.2)
    energy = np.array([4.0, 3.0, 2.0, 1.0]) * KWH  # soc 1, .6, .3, .1, 0
    result = verdict(battery, state_of_charge(battery, energy), energy)
    assert not result.feasible
    assert result.first_infeasible_index == 3
    assert result.margin_kwh == pytest.approx(-2.0)
    assert result.required_capacity_kwh == pytest.approx(10.0 / 0.8)
