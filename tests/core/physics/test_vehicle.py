import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from core.params import GRAVITY_MPS2, VehicleParams
from core.physics.vehicle import (
    drag_force_n,
    electric_power_w,
    rolling_force_n,
    slope_force_n,
    step_traction_power_w,
    traction_force_n,
)

VAN = VehicleParams()
MASS = 1680 + 550  # Table 1 vehicle + payload [kg]


def test_rolling_force_by_hand():
    # eq. 4: 1.25 · 2230 kg · 9.80665 m/s² · 0.012 = 328.032 N
    assert rolling_force_n(VAN, MASS) == pytest.approx(328.0324, rel=1e-6)


def test_drag_force_by_hand():
    # eq. 3: ½ · 1.2 · 4.27 · 0.329 · 20² = 0.842898 · 400 = 337.159 N
    assert drag_force_n(VAN, 20.0) == pytest.approx(337.1592, rel=1e-6)


def test_slope_force_by_hand():
    # eq. 5: 2230 · 9.80665 · sin(atan(0.05)) = 2230 · 9.80665 · 0.0499376 = 1092.07 N
    assert slope_force_n(MASS, 0.05) == pytest.approx(1092.07, rel=1e-5)
    assert slope_force_n(MASS, -0.05) == pytest.approx(-1092.07, rel=1e-5)


def test_traction_force_sums_components_and_inertia():
    # eq. 2 at 10 m/s, 0.5 m/s², 2 % uphill
    expected = (
        1.25 * MASS * GRAVITY_MPS2 * 0.012
        + 0.5 * 1.2 * 4.27 * 0.329 * 100
        + MASS * GRAVITY_MPS2 * 0.02 / np.sqrt(1 + 0.02**2)
        + MASS * 0.5
    )
    assert traction_force_n(VAN, MASS, 10.0, 0.5, 0.02) == pytest.approx(expected)


def test_motoring_and_braking_power():
    # eq. 7 motoring: 10 kW / 0.85; braking: 0.6 of the braking power comes back
    assert electric_power_w(VAN, 10_000.0) == pytest.approx(11_764.7, rel=1e-4)
    assert electric_power_w(VAN, -10_000.0) == pytest.approx(-6_000.0)
    capped = VehicleParams(max_regen_power_w=4_000)
    assert electric_power_w(capped, -10_000.0) == pytest.approx(-4_000.0)
    no_regen = VehicleParams(regen_efficiency=0.0)
    assert electric_power_w(no_regen, -10_000.0) == 0.0


def test_constant_speed_step_power_by_hand():
    # (328.032 N + 337.159 N) · 20 m/s / 0.85 = 15,651.6 W
    power = step_traction_power_w(VAN, np.array([20.0, 20.0, 20.0]), 1.0, MASS, 0.0)
    assert power == pytest.approx([15_651.6, 15_651.6], rel=1e-5)


def test_step_uses_mean_speed_and_speed_change():
    # 0 → 2 m/s in 1 s: v_mean = 1 m/s, a = 2 m/s²
    power = step_traction_power_w(VAN, np.array([0.0, 2.0]), 1.0, MASS, 0.0)
    force = 328.0324 + 0.5 * 1.2 * 4.27 * 0.329 * 1.0 + MASS * 2.0
    assert power[0] == pytest.approx(force * 1.0 / 0.85, rel=1e-5)


def test_standstill_draws_no_traction():
    power = step_traction_power_w(VAN, np.zeros(10), 1.0, MASS, 0.08)
    assert np.all(power == 0)


# Traces from rest to rest: over such a trace the net kinetic energy is zero, so more mass
# (more inertia and rolling force) can only cost more when regeneration returns at most what
# motoring took (η_regen <= 1 <= 1/η_el). A trace that only brakes would regenerate more.
speeds = st.lists(st.floats(0, 40), min_size=1, max_size=50).map(lambda v: np.array([0, *v, 0]))


@given(speeds, st.floats(500, 5000), st.floats(1.01, 2.0))
def test_energy_rises_with_mass(speed, mass, factor):
    light = step_traction_power_w(VAN, speed, 1.0, mass, 0.0).sum()
    heavy = step_traction_power_w(VAN, speed, 1.0, mass * factor, 0.0).sum()
    assert heavy >= light - 1e-9 * abs(light)


@given(speeds, st.floats(0.1, 1.0), st.floats(1.01, 2.0))
def test_energy_rises_with_drag(speed, cd, factor):
    low = step_traction_power_w(VehicleParams(drag_coefficient=cd), speed, 1.0, MASS, 0.0).sum()
    high_vehicle = VehicleParams(drag_coefficient=min(cd * factor, 2.0))
    high = step_traction_power_w(high_vehicle, speed, 1.0, MASS, 0.0).sum()
    assert high >= low - 1e-9 * abs(low)


def test_headwind_drag_by_hand():
    # eq. 3 with the speed through the air: 20 m/s into a 5 m/s headwind is drag at 25 m/s,
    # ½ · 1.2 · 4.27 · 0.329 · 25² = 526.81 N; a 25 m/s tailwind on a van at 20 m/s pushes it
    assert drag_force_n(VAN, 20.0, 5.0) == pytest.approx(526.811, rel=1e-5)
    assert drag_force_n(VAN, 20.0, -25.0) == pytest.approx(-0.842898 * 25, rel=1e-5)
    # standing still: no drag on the van's own power budget
    assert traction_force_n(VAN, MASS, 0.0, 0.0, 0.0, 10.0) == 0.0


def test_regen_cap_limits_charging_power():
    capped = VehicleParams(max_regen_power_w=20_000)
    assert electric_power_w(capped, -100_000) == pytest.approx(-20_000)
    assert electric_power_w(capped, -10_000) == pytest.approx(-6_000)  # 0.6 · 10 kW
