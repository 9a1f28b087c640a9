import math

import pytest

from core.exceptions import InvalidParameterError
from core.params import (
    PRESETS,
    BatteryParams,
    CargoBoxParams,
    VehicleParams,
    Weather,
    get_preset,
)


def test_paper_generic_carries_table_1():
    # Paper Table 1.
    preset = PRESETS["paper-generic"]
    v, box = preset.vehicle, preset.cargo_box
    assert (v.mass_kg, preset.payload_kg) == (1680, 550)
    assert (v.drag_coefficient, v.rolling_resistance_coefficient, v.frontal_area_m2) == (
        0.329,
        0.012,
        4.27,
    )
    assert v.rolling_resistance_factor == 1.25  # eq. 4
    assert box.cargo_specific_heat_j_kgk == 2300
    assert (box.volume_m3, box.wall_heat_transfer_w_m2k) == (8, 2.172)
    assert (box.roof_area_m2, box.side_area_m2, box.back_area_m2) == (8, 4.182, 3.12)
    assert box.heat_transfer_area_m2 == pytest.approx(2 * (8 + 4.182 + 3.12))


@pytest.mark.parametrize(
    ("model", "field", "value", "rule"),
    [
        (VehicleParams, "mass_kg", -1.0, "greater than or equal to 100"),
        (VehicleParams, "drivetrain_efficiency", 1.2, "less than or equal to 1"),
        (VehicleParams, "drivetrain_efficiency", 0.0, "greater than or equal to 0.1"),
        (VehicleParams, "regen_efficiency", math.nan, "finite"),
        (VehicleParams, "drag_coefficient", math.inf, "finite"),
        (CargoBoxParams, "cop", -2.0, "greater than or equal to 0.1"),
        (CargoBoxParams, "curtain_effectiveness", 1.0, "less than 1"),
        (BatteryParams, "usable_capacity_kwh", 0.0, "greater than or equal to 0.1"),
    ],
)
def test_bad_parameter_names_field_and_rule(model, field, value, rule):
    with pytest.raises(InvalidParameterError) as caught:
        model(**{field: value})
    assert caught.value.field == field
    assert field in str(caught.value) and rule in str(caught.value)


def test_unknown_parameter_is_rejected():
    with pytest.raises(InvalidParameterError, match="mass_lbs"):
        VehicleParams(mass_lbs=3000)


def test_cross_field_rules():
    with pytest.raises(InvalidParameterError, match=r"min_soc must be at least 0\.01 below"):
        BatteryParams(initial_soc=0.2, min_soc=0.3)
    with pytest.raises(InvalidParameterError, match=r"min_soc must be at least 0\.01 below"):
        BatteryParams(initial_soc=0.5, min_soc=0.495)
    with pytest.raises(InvalidParameterError, match="t_min_c must not exceed t_max_c"):
        Weather(t_min_c=20, t_max_c=10)
    with pytest.raises(InvalidParameterError, match="product_limit_c must be above setpoint_c"):
        CargoBoxParams(setpoint_c=8, product_limit_c=7)


def test_unknown_preset_lists_known_ones():
    with pytest.raises(InvalidParameterError, match="paper-generic") as caught:
        get_preset("tesla-semi")
    assert caught.value.field == "preset"


def test_preset_van_drops_name_only():
    preset = PRESETS["reference-zoe"]
    van = preset.van()
    assert van.vehicle == preset.vehicle and van.payload_kg == preset.payload_kg == 0
