import numpy as np
import pytest

from core.cargo import (
    air_density_kg_m3,
    door_heat_w,
    heat_capacity_j_k,
    refrigeration,
    wall_heat_w,
)
from core.params import CargoBoxParams

BOX = CargoBoxParams()
AREA = 2 * (8 + 4.182 + 3.12)  # 30.604 m²


def test_wall_heat_by_hand():
    # eq. 11: 2.172 W/(m²·K) · 30.604 m² · (34 − 4) K = 1994.2 W
    assert wall_heat_w(BOX, 34.0, 4.0) == pytest.approx(1994.16, abs=0.05)
    assert wall_heat_w(BOX, -6.0, 4.0) == pytest.approx(-664.72, abs=0.05)


def test_air_density_ideal_gas():
    # 101325 / (287.05 · 293.15) = 1.2041 kg/m³ at 20 °C
    assert air_density_kg_m3(20.0) == pytest.approx(1.2041, abs=1e-4)


def test_door_heat_gosney_olama_by_hand():
    # ASHRAE Refrigeration ch. 24: box 4 °C, ambient 34 °C, door 1.2 × 1.5 m
    rho_box, rho_amb = 101325 / (287.05 * 277.15), 101325 / (287.05 * 307.15)
    fm = (2 / (1 + (rho_box / rho_amb) ** (1 / 3))) ** 1.5
    flow = 0.221 * 1.2 * 1.5 * np.sqrt(9.80665 * 1.5) * np.sqrt(1 - rho_amb / rho_box) * fm
    expected = rho_box * flow * 1006 * 30 * 0.25  # D_f 0.25, no curtain
    assert door_heat_w(BOX, 34.0, 4.0) == pytest.approx(expected, rel=1e-9)


def test_ten_minutes_of_open_door_match_two_hours_of_wall_gain():
    # DESIGN.md calibration: 10 min open, 8 m³ box, 30 K, no curtain ≈ 2 h of closed-door wall
    # gain of an ATP-class box (K = 0.4 W/(m²·K)): 0.4 · 30.604 · 30 · 7200 s = 0.7345 kWh.
    door_kwh = door_heat_w(BOX, 34.0, 4.0) * 600 / 3.6e6
    assert 0.5 <= door_kwh <= 1.5
    assert door_kwh == pytest.approx(0.4 * AREA * 30 * 7200 / 3.6e6, rel=0.1)


def test_curtain_and_cold_air():
    with_curtain = CargoBoxParams(curtain_effectiveness=0.9)
    assert door_heat_w(with_curtain, 34.0, 4.0) == pytest.approx(0.1 * door_heat_w(BOX, 34, 4))
    assert door_heat_w(BOX, -16.0, 4.0) < 0  # cold outside air cools the box


def _run(box, ambient, solar=0.0, door=0.0, payload=550.0, n=600):
    return refrigeration(
        box, np.full(n, ambient), np.full(n, solar), np.full(n, door), np.full(n, payload), 1.0
    )


def test_steady_power_is_load_over_cop():
    # eq. 12: (1994.16 W wall + 100 W sun) / 1.5 = 1396.1 W
    result = _run(BOX, 34.0, solar=100.0)
    assert result.power_w == pytest.approx(np.full(600, (1994.16 + 100) / 1.5), abs=0.05)
    assert result.max_temperature_c == 4.0 and result.minutes_above_limit == 0


def test_cold_day_no_cooling_heater_optional():
    assert np.all(_run(BOX, -6.0).power_w == 0)
    heated = _run(CargoBoxParams(heater_enabled=True), -6.0)
    assert heated.power_w == pytest.approx(np.full(600, 664.72), abs=0.05)  # resistive heat


def test_dynamic_mode_with_ample_capacity_equals_steady():
    dynamic = _run(CargoBoxParams(mode="dynamic", refrigeration_capacity_w=5000), 34.0, door=0.5)
    steady = _run(BOX, 34.0, door=0.5)
    assert dynamic.power_w == pytest.approx(steady.power_w)
    assert dynamic.max_temperature_c == 4.0


def test_dynamic_mode_warms_when_capacity_is_short():
    # load 1994.16 W vs capacity 1000 W for 600 s: E = 994.16 · 600 = 596.5 kJ above set-point;
    # heat capacity 550 kg · 2300 + 8 m³ air (1.2736 kg/m³ · 1006) = 1,265,250 J/K → +0.4714 K
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=1000)
    result = _run(box, 34.0)
    capacity = heat_capacity_j_k(box, 550.0)
    assert capacity == pytest.approx(550 * 2300 + 8 * air_density_kg_m3(4.0) * 1006)
    assert result.max_temperature_c == pytest.approx(4 + 994.16 * 600 / capacity, abs=1e-3)
    assert result.power_w == pytest.approx(np.full(600, 1000 / 1.5))


def test_dynamic_mode_counts_minutes_above_product_limit():
    # empty box (air only, 10.25 kJ/K): 994 W excess lifts it 3 K (to the 7 °C limit) in 31 s
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=1000)
    result = _run(box, 34.0, payload=0.0)
    crossing_s = 3.0 * heat_capacity_j_k(box, 0.0) / 994.16
    assert result.minutes_above_limit == pytest.approx((600 - np.ceil(crossing_s)) / 60, abs=0.02)


def test_dynamic_box_recovers_after_the_load_drops():
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=1000)
    ambient = np.concatenate((np.full(300, 34.0), np.full(3000, 4.0)))
    n = ambient.size
    result = refrigeration(box, ambient, np.zeros(n), np.zeros(n), np.full(n, 550.0), 1.0)
    assert result.temperature_c[-1] == pytest.approx(4.0)
    assert result.max_temperature_c > 4.1
