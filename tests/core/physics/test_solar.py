import numpy as np
import pytest

from core.params import CargoBoxParams
from core.physics.solar import (
    absorbed_solar_heat_w,
    declination_deg,
    direct_irradiance_w_m2,
    direct_normal_from_horizontal_w_m2,
    equation_of_time_min,
    sin_altitude,
    solar_time_h,
)

VIENNA_LAT = 48.2


def altitude_deg(lat, day, solar_hour):
    return np.degrees(np.arcsin(sin_altitude(lat, declination_deg(day), solar_hour)))


def test_declination_solstices_and_equinoxes():
    # Cooper's formula: ±23.45° at the solstices, about 0° at the equinoxes
    assert declination_deg(172) == pytest.approx(23.45, abs=0.01)  # 21 June
    assert declination_deg(355) == pytest.approx(-23.45, abs=0.01)  # 21 December
    # Cooper's formula crosses zero at 284 + n = 365, 547.5: days 81 and 263.5 (22 March,
    # 20 September); the real September equinox (day 266) is within its ~1° error.
    assert abs(declination_deg(81)) < 0.01
    assert abs(declination_deg(263.5)) < 0.01
    assert abs(declination_deg(266)) < 1.1


def test_noon_altitude_at_48_2_north():
    # 90° − 48.2° ± 23.45°: 65.25° on 21 June, 18.35° on 21 December (issue 2: ≈65.2, ≈18.4)
    assert altitude_deg(VIENNA_LAT, 172, 12.0) == pytest.approx(65.2, abs=0.1)
    assert altitude_deg(VIENNA_LAT, 355, 12.0) == pytest.approx(18.4, abs=0.1)


def test_equation_of_time_known_extremes():
    # Duffie & Beckman Fig. 1.5.1: about −14 min in mid-February, about +16 min early November
    assert equation_of_time_min(42) == pytest.approx(-14.3, abs=0.7)
    assert equation_of_time_min(307) == pytest.approx(16.4, abs=0.7)


def test_solar_time_from_clock():
    # Vienna 16.37° E, CEST (UTC+2), 21 June: 4·(16.37 − 30) = −54.5 min, E(172) = −1.4 min
    expected = 13.0 + (-54.52 + equation_of_time_min(172)) / 60
    assert solar_time_h(13.0, equation_of_time_min(172), 16.37, 2.0) == pytest.approx(expected)


def test_direct_irradiance_ashrae():
    # eq. 13, June (A = 1088, B = 0.205), sun at zenith: 1088·exp(−0.205) = 886.34 W/m²
    assert direct_irradiance_w_m2(1.0, 6) == pytest.approx(886.34, abs=0.01)
    # January, sun at 30°: 1230·exp(−0.142/0.5) = 925.90 W/m²
    assert direct_irradiance_w_m2(0.5, 1) == pytest.approx(925.90, abs=0.01)
    assert direct_irradiance_w_m2(-0.2, 6) == 0.0


def test_absorbed_solar_heat_by_hand():
    box = CargoBoxParams()
    # sun at 30° in January: S = 925.90 W/m²; κ* = 0.3 · 2.172/22.7 = 0.028705
    # roof 8 · 0.5 = 4; sides (2·4.182 + 3.12) · cos 30°/π = 11.484 · 0.27566 = 3.1657
    # (4 + 3.1657) · 925.90 · 0.028705 · 0.8 (shadow) = 152.34 W
    clear = direct_irradiance_w_m2(0.5, 1)
    assert clear == pytest.approx(925.90, abs=0.05)
    assert absorbed_solar_heat_w(box, 0.5, clear) == pytest.approx(152.3, abs=0.2)
    assert absorbed_solar_heat_w(box, -0.1, clear) == 0.0
    assert absorbed_solar_heat_w(CargoBoxParams(shadow_factor=0.0), 0.5, clear) == 0.0


def test_forecast_sun_with_diffuse_by_hand():
    box = CargoBoxParams()
    # Forecast: 400 W/m² direct on the horizontal at 30° altitude → S = 800 W/m² normal;
    # 100 W/m² diffuse. Roof 8 · (800 · 0.5 + 100) = 4000; sides 11.484 · (800 · cos 30°/π
    # + 50) = 11.484 · 270.53 = 3106.8; (4000 + 3106.8) · 0.028705 · 0.8 = 163.20 W
    direct = direct_normal_from_horizontal_w_m2(400.0, 0.5)
    assert direct == pytest.approx(800.0)
    assert absorbed_solar_heat_w(box, 0.5, direct, 100.0) == pytest.approx(163.20, abs=0.05)
    # below 3° of altitude the direct part is dropped (forecast noise over a tiny sine)
    assert direct_normal_from_horizontal_w_m2(5.0, 0.04) == 0.0
