import datetime as dt
from zoneinfo import ZoneInfo

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from core.params import CargoBoxParams
from core.physics.cargo import (
    MAX_CARNOT_COP,
    air_density_kg_m3,
    cooling_capacity_w,
    door_heat_w,
    heat_capacity_j_k,
    precondition_energy_j,
    refrigeration,
    refrigeration_cop,
    unit_power_w,
    wall_heat_w,
)

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


def _exact_c(ambient_c, start_c, conductance_w_k, capacity_j_k, unit_w, seconds):
    """C·dϑ/dt = G·(ϑ_amb − ϑ) − Q: ϑ(t) = ϑ_eq + (ϑ_0 − ϑ_eq)·exp(−G·t/C), ϑ_eq = ϑ_amb − Q/G."""
    equilibrium = ambient_c - unit_w / conductance_w_k
    return equilibrium + (start_c - equilibrium) * np.exp(-conductance_w_k * seconds / capacity_j_k)


UA = 2.172 * AREA  # 66.47 W/K (eq. 11)
#: A unit of constant capacity: the hand calculations of the integration below.
CONSTANT_UNIT = {"capacity_box_slope_per_k": 0.0, "capacity_ambient_slope_per_k": 0.0}


def test_dynamic_mode_warms_when_capacity_is_short():
    # 34 °C outside, 1000 W of cooling against a 1994 W wall load: the box warms along the
    # exact first-order response with the loads at its current temperature. Heat capacity:
    # 550 kg · 2300 + 8 m³ of air + 190 kJ/K of box structure.
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=1000, **CONSTANT_UNIT)
    result = _run(box, 34.0)
    capacity = heat_capacity_j_k(box, 550.0)
    assert capacity == pytest.approx(550 * 2300 + 8 * air_density_kg_m3(4.0) * 1006 + 190_000)
    expected = _exact_c(34.0, 4.0, UA, capacity, 1000.0, 600.0)  # 4.40 °C
    assert result.max_temperature_c == pytest.approx(expected, abs=2e-3)
    assert result.power_w == pytest.approx(np.full(600, 1000 / 1.5))
    # the wall gain shrinks as the box warms
    assert result.wall_heat_w[-1] == pytest.approx(UA * (34 - result.temperature_c[-1]))


def test_dynamic_mode_counts_minutes_above_product_limit():
    # empty box (air + structure ≈ 200 kJ/K): 7 °C is crossed at
    # t = −τ·ln((7 − ϑ_eq)/(4 − ϑ_eq)), τ = C/UA, ϑ_eq = 34 − 1000/UA
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=1000, **CONSTANT_UNIT)
    result = _run(box, 34.0, payload=0.0, n=1200)
    capacity = heat_capacity_j_k(box, 0.0)
    equilibrium = 34 - 1000 / UA
    crossing_s = -capacity / UA * np.log((7 - equilibrium) / (4 - equilibrium))
    assert result.minutes_above_limit == pytest.approx((1200 - crossing_s) / 60, abs=0.2)
    assert result.max_temperature_c == pytest.approx(
        _exact_c(34.0, 4.0, UA, capacity, 1000.0, 1200.0), abs=2e-3
    )


def test_dynamic_box_recovers_after_the_load_drops():
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=1000, **CONSTANT_UNIT)
    ambient = np.concatenate((np.full(300, 34.0), np.full(3000, 4.0)))
    n = ambient.size
    result = refrigeration(box, ambient, np.zeros(n), np.zeros(n), np.full(n, 550.0), 1.0)
    assert result.temperature_c[-1] == pytest.approx(4.0)
    assert result.max_temperature_c > 4.05


def test_empty_box_with_an_open_door_stays_below_the_outside_air():
    # Issue #10 repro: an empty dynamic box, 30 °C all day, door open 300 s from t = 100 s.
    # The old model reached 78 °C; walls and door at the box's temperature bound it by the
    # outside air and its sol-air excess. By hand (no sun at 03:00): G = UA + G_door,
    # ϑ_eq = 30 − 3000 W / G, exact response over the 300 s of open door.
    from core.params import DoorOpening, Location, VanParams, Weather
    from core.physics.simulate import Along, simulate

    box = CargoBoxParams(mode="dynamic", **CONSTANT_UNIT)
    van = VanParams(cargo_box=box)
    start = dt.datetime(2026, 7, 15, 3, tzinfo=ZoneInfo("Europe/Vienna"))
    result = simulate(
        np.zeros(1201),
        1,
        start,
        Location(lat=48.21, lon=16.37),
        van,
        weather=Weather(t_min_c=30, t_max_c=30),
        along=Along(payload_kg=0.0, door_openings=[DoorOpening(start_s=100, duration_s=300)]),
    )
    door_g = door_heat_w(box, 30.0, 4.0) / 26.0
    expected = _exact_c(30.0, 4.0, UA + door_g, heat_capacity_j_k(box, 0.0), 3000.0, 300.0)
    assert result.box.max_temperature_c == pytest.approx(expected, abs=0.05)
    assert result.box.max_temperature_c < 30.0
    assert result.box.temperature_c[-1] == pytest.approx(4.0)


def test_unloading_changes_the_heat_capacity_not_the_temperature():
    # 550 kg unloaded in one step while the box is warm: no jump (the old model jumped
    # 4.6 → 38.9 °C, dividing the stored heat by a smaller capacity).
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=500)
    n = 1800
    payload = np.where(np.arange(n) < 900, 550.0, 0.0)
    result = refrigeration(box, np.full(n, 34.0), np.zeros(n), np.zeros(n), payload, 1.0)
    steps = np.abs(np.diff(result.temperature_c))
    assert steps.max() < 0.05
    # the lighter box then warms faster
    assert np.diff(result.temperature_c)[1000] > np.diff(result.temperature_c)[800]


@settings(max_examples=60, deadline=None)
@given(
    ambient=st.lists(st.floats(-30, 50), min_size=2, max_size=6),
    solar_w=st.floats(0, 3000),
    door=st.floats(0, 1),
    payload_kg=st.floats(0, 2000),
    cooling_w=st.floats(100, 8000),
    heater=st.booleans(),
    start_c=st.one_of(st.none(), st.floats(-30, 50)),
)
def test_box_stays_within_what_outside_air_sun_and_setpoint_allow(
    ambient, solar_w, door, payload_kg, cooling_w, heater, start_c
):
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=cooling_w, heater_enabled=heater)
    n = 600 * len(ambient)
    ambient_c = np.repeat(ambient, 600)
    solar = np.full(n, solar_w)
    result = refrigeration(
        box, ambient_c, solar, np.full(n, door), np.full(n, payload_kg), 1.0, start_c
    )
    # sol-air: the warmest the walls can drive the box is ϑ_amb + Q_sol/UA
    warmest = max(box.setpoint_c, float((ambient_c + solar / UA).max()), start_c or -99)
    coldest = min(box.setpoint_c, float(ambient_c.min()), start_c if start_c is not None else 99)
    assert result.temperature_c.max() <= warmest + 1e-6
    assert result.temperature_c.min() >= coldest - 1e-6
    assert np.all(result.power_w >= 0)


def test_carnot_cop_by_hand():
    # evaporator 4 − 10 = −6 °C (267.15 K), condenser 30 + 15 = 45 °C (318.15 K):
    # 0.3 · 267.15 / 51 = 1.5715 — the paper's η_RU 1.5 at its design point
    box = CargoBoxParams(cop_model="carnot")
    assert refrigeration_cop(box, 30.0, 4.0) == pytest.approx(1.5715, abs=1e-4)
    # frozen goods: 0.3 · 243.15 / 75 = 0.9726
    assert refrigeration_cop(box, 30.0, -20.0) == pytest.approx(0.9726, abs=1e-4)
    # a cool day cannot make the compressor arbitrarily efficient
    assert refrigeration_cop(box, -10.0, 4.0) == MAX_CARNOT_COP
    assert refrigeration_cop(CargoBoxParams(), 40.0, 4.0) == 1.5  # the paper's constant


def test_cold_day_heats_over_heating_cop_with_standby():
    box = CargoBoxParams(heater_enabled=True, heating_cop=2.0, standby_power_w=150)
    result = _run(box, -6.0)
    # wall loss 664.72 W less the fans' 150 W of heat, over COP_heat 2, + the fans' 150 W
    assert result.power_w == pytest.approx(np.full(600, (664.72 - 150) / 2 + 150), abs=0.05)


def test_dynamic_heater_short_of_the_loss_lets_the_box_cool():
    box = CargoBoxParams(mode="dynamic", heater_enabled=True, heating_capacity_w=300)
    result = _run(box, -10.0, n=1800)
    expected = _exact_c(-10.0, 4.0, UA, heat_capacity_j_k(box, 550.0), -300.0, 1800.0)
    assert result.temperature_c[-1] == pytest.approx(expected, abs=2e-3)
    assert result.power_w == pytest.approx(np.full(1800, 300.0))


def test_warm_box_structure_is_pulled_down_at_the_units_capacity():
    # steady mode, not pre-cooled: 190 kJ/K · (30 − 4) K = 4.94 MJ extra at 3 kW → 1647 s
    box = CargoBoxParams()
    cold = _run(box, 30.0, n=3600)
    warm = refrigeration(
        box, np.full(3600, 30.0), np.zeros(3600), np.zeros(3600), np.full(3600, 550.0), 1.0, 30.0
    )
    extra_j = (warm.power_w - cold.power_w).sum() * box.cop
    assert extra_j == pytest.approx(190_000 * 26, rel=1e-9)
    assert (warm.power_w - cold.power_w)[0] == pytest.approx(3000 / 1.5)
    assert precondition_energy_j(box, 30.0) == pytest.approx(190_000 * 26 / 1.5)


def test_capacity_falls_with_a_colder_box_and_a_hotter_day():
    # rated at ATP's 0 °C inside / 30 °C outside; 2.2 %/K of box air, 1 %/K of outside air:
    # −20 °C inside → 1 − 0.44 = 56 % (small van units' ratings), 40 °C outside → 90 %
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=2500)
    assert cooling_capacity_w(box, 30.0, 0.0) == pytest.approx(2500.0)
    assert cooling_capacity_w(box, 30.0, -20.0) == pytest.approx(0.56 * 2500)
    assert cooling_capacity_w(box, 40.0, 0.0) == pytest.approx(0.90 * 2500)
    assert cooling_capacity_w(box, 35.0, 4.0) == pytest.approx((1 + 0.088 - 0.05) * 2500)
    # never below a tenth of the rating; the paper's steady box is rated alike (its check)
    assert cooling_capacity_w(box, 80.0, -40.0) == pytest.approx(250.0)
    assert cooling_capacity_w(BOX, 30.0, -20.0) == pytest.approx(0.56 * 3000)  # its rating


def test_a_frozen_box_warms_where_the_rating_at_0_c_would_hold_it():
    # an empty box at −20 °C, 30 °C outside: walls UA·50 = 3323 W against a 4000 W rating at
    # 0 °C, but 0.56 · 4000 = 2240 W at −20 °C: the box warms towards where the capacity
    # meets the walls, UA·(30 − ϑ) = 4000·(1 + 0.022·ϑ) → ϑ = (30·UA − 4000)/(UA + 88)
    box = CargoBoxParams(
        mode="dynamic", refrigeration_capacity_w=4000, setpoint_c=-20.0, product_limit_c=-15.0
    )
    result = _run(box, 30.0, payload=0.0, n=4 * 3600)
    meets_c = (30 * UA - 4000) / (UA + 88)  # −13.0 °C
    assert result.temperature_c[-1] == pytest.approx(meets_c, abs=0.05)
    constant = box.model_copy(update={"capacity_box_slope_per_k": 0.0})
    assert _run(constant, 30.0, payload=0.0).max_temperature_c == -20.0


def test_the_fans_heat_the_box_while_the_unit_runs_and_stop_with_it():
    # 150 W of fans: the unit removes the walls' 1994.16 W and the fans' 150 W (eq. 12 at
    # COP 1.5) and draws the fans'; on a cold day without heater it is off: nothing at all
    box = CargoBoxParams(standby_power_w=150.0)
    assert _run(box, 34.0).power_w == pytest.approx(
        np.full(600, (1994.16 + 150) / 1.5 + 150), abs=0.05
    )
    assert np.all(_run(box, -6.0).power_w == 0)
    dynamic = CargoBoxParams(mode="dynamic", standby_power_w=150.0, min_modulation=0.0)
    held = _run(dynamic, 34.0)
    assert held.power_w == pytest.approx(np.full(600, (1994.16 + 150) / 1.5 + 150), abs=0.05)
    cold = _run(dynamic, -6.0, payload=0.0, n=3600)
    assert np.all(cold.power_w == 0) and cold.temperature_c[-1] < 0


def test_a_variable_unit_below_its_least_speed_cycles_and_loses_its_degradation():
    # 300 W of load on a 3000 W unit that modulates down to 30 %: run-time fraction
    # x = 0.1/0.3, PLF = 1 − 0.25·(1 − 1/3) = 0.8333 (AHRI 210/240); above 900 W no loss
    box = CargoBoxParams(mode="dynamic", refrigeration_capacity_w=3000, **CONSTANT_UNIT)
    low = unit_power_w(box, 30.0, 0.0, np.array([300.0]), 0.0)
    assert low == pytest.approx([300 / 1.5 / (1 - 0.25 * (1 - 1 / 3))])
    assert unit_power_w(box, 30.0, 0.0, np.array([1200.0]), 0.0) == pytest.approx([800.0])
    steady = CargoBoxParams()  # the paper's unit: none
    assert unit_power_w(steady, 30.0, 0.0, np.array([300.0]), 0.0) == pytest.approx([200.0])
