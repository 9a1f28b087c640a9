import numpy as np
import pytest

from core.params import VehicleParams
from core.physics.cabin import auxiliaries_power_w, cab_power_w, cabin_hvac_power_w

VAN = VehicleParams()


@pytest.mark.parametrize(
    ("ambient_c", "power_w"),
    [
        # Paper Table 2 points and linear interpolation between them, by hand.
        (-20, 4200),
        (-15, 3700),  # (4200 + 3200) / 2
        (-10, 3200),
        (5, 1600),  # (2300 + 900) / 2
        (20, 0),
        (25, 300),  # (0 + 600) / 2
        (30, 600),
        (-35, 4200),  # flat below the table
        (42, 600),  # flat above the table
    ],
)
def test_hvac_table_2(ambient_c, power_w):
    assert cabin_hvac_power_w(VAN, ambient_c) == pytest.approx(power_w)


def test_hvac_can_be_switched_off():
    assert cabin_hvac_power_w(VehicleParams(cabin_hvac_enabled=False), -10) == 0


def test_auxiliaries_are_the_papers_constant():
    # paper §2.3: 0.4 kW
    assert list(auxiliaries_power_w(VAN, 3)) == [400, 400, 400]


def _cab(mode, ambient_c=-10.0, parked=((600.0, 600.0),), n=3600, deficit_j=0.0, **fields):
    vehicle = VehicleParams(cab_hvac_at_stops=mode, **fields)
    return cab_power_w(vehicle, np.full(n, ambient_c), 1.0, list(parked), deficit_j)


# At −10 °C Table 2 gives 3200 W for a 30 K difference: G = 106.7 W/K. With the default
# 60 kJ/K the parked cab drifts with τ = 60,000 / 106.7 = 562.5 s.
TAU_S = 60_000 / (3200 / 30)


def test_cab_on_at_stops_is_the_papers_constant_power():
    assert _cab("on") == pytest.approx(np.full(3600, 3200.0))


def test_cab_off_at_a_stop_saves_the_parked_power_and_pays_the_recovery():
    # drift 30 K · (1 − e^(−600/562.5)) = 19.67 K; recovery 60 kJ/K · 19.67 K = 1.180 MJ,
    # delivered with the spare 6000 − 3200 = 2800 W in 421.5 s after the stop
    power = _cab("off")
    deficit_j = 60_000 * 30 * (1 - np.exp(-600 / TAU_S))
    assert power[600:1200] == pytest.approx(np.zeros(600))  # parked, HVAC off
    assert power[1200] == pytest.approx(6000.0)  # full power right after the stop
    assert power.sum() == pytest.approx(3200 * 3000 + deficit_j, rel=1e-9)
    assert power[1200 + 425 :] == pytest.approx(np.full(3600 - 1625, 3200.0))


def test_cab_reduced_draws_its_share_and_recovers_the_smaller_drift():
    power = _cab("reduced", cab_reduced_share=0.25)
    deficit_j = 0.75 * 60_000 * 30 * (1 - np.exp(-600 / TAU_S))
    assert power[700] == pytest.approx(800.0)
    assert power.sum() == pytest.approx(3200 * 3000 + 800 * 600 + deficit_j, rel=1e-9)


def test_a_cab_at_the_outside_temperature_is_brought_to_20_c_at_departure():
    # 60 kJ/K · 30 K = 1.8 MJ at the spare 2800 W: 642.9 s of 6 kW
    power = _cab("on", parked=(), deficit_j=1.8e6)
    assert power.sum() == pytest.approx(3200 * 3600 + 1.8e6)
    assert power[0] == pytest.approx(6000.0) and power[700] == pytest.approx(3200.0)


def test_no_drift_at_20_c():
    # Table 2 gives 0 W at 20 °C: nothing to hold, nothing to recover after an hour parked.
    vehicle = VehicleParams(cab_hvac_at_stops="off")
    power = cab_power_w(vehicle, np.full(7200, 20.0), 1.0, [(1800.0, 3600.0)], 0.0)
    assert power == pytest.approx(np.zeros(7200))
