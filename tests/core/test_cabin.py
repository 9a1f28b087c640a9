import pytest

from core.cabin import auxiliaries_power_w, cabin_hvac_power_w
from core.params import VehicleParams

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
