"""Sun position and absorbed solar heat on the cargo box (paper §3.3, eqs 13–17)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray
from core.params import CargoBoxParams

# ASHRAE clear-sky model, monthly apparent extraterrestrial irradiance A [W/m²] and
# atmospheric extinction coefficient B [–], January → December (ASHRAE Handbook –
# Fundamentals 1985, ch. 27; docs/architecture.md lists them with the paper's eq. 13).
ASHRAE_A_W_M2 = np.array(
    [1230, 1215, 1186, 1136, 1104, 1088, 1085, 1107, 1151, 1192, 1221, 1233], dtype=float
)
ASHRAE_B = np.array(
    [0.142, 0.144, 0.156, 0.180, 0.196, 0.205, 0.207, 0.201, 0.177, 0.160, 0.149, 0.142]
)


def declination_deg(day_of_year: ArrayLike) -> FloatArray:
    """Solar declination δ = 23.45°·sin(360°·(284 + n)/365) [°] (Cooper 1969).

    Parameters
    ----------
    day_of_year
        n, 1 on 1 January [–].
    """
    n = np.asarray(day_of_year, dtype=float)
    return 23.45 * np.sin(np.radians(360.0 * (284.0 + n) / 365.0))


def equation_of_time_min(day_of_year: ArrayLike) -> FloatArray:
    """Equation of time [min]: apparent minus mean solar time.

    ``E = 9.87·sin 2B − 7.53·cos B − 1.5·sin B`` with ``B = 360°·(n − 81)/364``
    (Duffie & Beckman, *Solar Engineering of Thermal Processes*, eq. 1.5.3 form).
    """
    b = np.radians(360.0 * (np.asarray(day_of_year, dtype=float) - 81.0) / 364.0)
    return 9.87 * np.sin(2 * b) - 7.53 * np.cos(b) - 1.5 * np.sin(b)


def solar_time_h(
    clock_hour: ArrayLike, equation_of_time: ArrayLike, lon_deg: float, utc_offset_h: float
) -> FloatArray:
    """Apparent solar time [h] from local clock time.

    ``t_solar = t_clock + (4 min/° · (λ − 15°/h · UTC offset) + E) / 60``.

    Parameters
    ----------
    clock_hour
        Local clock time [h since midnight].
    equation_of_time
        E [min] of the day (:func:`equation_of_time_min`).
    lon_deg
        Longitude λ [°], east positive.
    utc_offset_h
        Offset of the local clock from UTC [h] (+1 for CET, +2 for CEST).
    """
    correction_min = 4.0 * (lon_deg - 15.0 * utc_offset_h) + np.asarray(equation_of_time)
    return np.asarray(clock_hour, dtype=float) + correction_min / 60.0


def sin_altitude(lat_deg: float, declination: ArrayLike, solar_hour: ArrayLike) -> FloatArray:
    """Sine of the sun's altitude h [–] (eq. 14).

    ``sin h = sin χ·sin δ + cos χ·cos δ·cos ω`` with hour angle ``ω = 15°·(t_solar − 12)``.
    Negative when the sun is below the horizon.

    Parameters
    ----------
    lat_deg
        Latitude χ [°].
    declination
        Solar declination δ [°] (:func:`declination_deg`).
    solar_hour
        Apparent solar time [h].
    """
    chi = np.radians(lat_deg)
    delta = np.radians(np.asarray(declination, dtype=float))
    omega = np.radians(15.0 * (np.asarray(solar_hour, dtype=float) - 12.0))
    return np.sin(chi) * np.sin(delta) + np.cos(chi) * np.cos(delta) * np.cos(omega)


def direct_irradiance_w_m2(sin_h: ArrayLike, month: ArrayLike) -> FloatArray:
    """Direct normal irradiance on a clear day ``S = A·exp(−B / sin h)`` [W/m²] (eq. 13).

    Zero when the sun is at or below the horizon.

    Parameters
    ----------
    sin_h
        Sine of the sun's altitude [–].
    month
        Month number 1–12, selecting ASHRAE's A and B.
    """
    s = np.asarray(sin_h, dtype=float)
    index = np.asarray(month, dtype=int) - 1
    up = s > 0
    safe = np.where(up, s, 1.0)
    return np.where(up, ASHRAE_A_W_M2[index] * np.exp(-ASHRAE_B[index] / safe), 0.0)


def direct_normal_from_horizontal_w_m2(
    direct_horizontal_w_m2: ArrayLike, sin_h: ArrayLike
) -> FloatArray:
    """Direct normal irradiance from direct irradiance on a horizontal surface [W/m²].

    ``S = S_h / sin h``; zero with the sun below 3° (where the division amplifies forecast noise
    and the low sun's share is negligible).
    """
    s = np.asarray(sin_h, dtype=float)
    high_enough = s > math.sin(math.radians(3.0))
    safe = np.where(high_enough, s, 1.0)
    return np.where(high_enough, np.asarray(direct_horizontal_w_m2, dtype=float) / safe, 0.0)


def absorbed_solar_heat_w(
    box: CargoBoxParams,
    sin_h: ArrayLike,
    direct_normal_w_m2: ArrayLike,
    diffuse_horizontal_w_m2: ArrayLike = 0.0,
) -> FloatArray:
    """Solar heat entering the cargo box [W] (eqs 15–17).

    Roof ``κ*·A_r·(S·sin h + D)`` plus sides and back ``κ*·(2A_s + A_b)·(S·cos h/π + D/2)``,
    times the shadow factor ``b_sh``; zero at night. ``S`` is the direct normal irradiance and
    ``D`` the diffuse irradiance on a horizontal surface, which the paper leaves out (clear sky)
    and a forecast provides; a vertical wall sees half the sky. The effective absorption
    coefficient is ``κ* = a_s·α/h_o``: the surface absorbs ``a_s`` of the sun, and of that the
    share ``α/h_o`` crosses the insulated wall instead of going back to the outside air (sol-air
    temperature method, ASHRAE Handbook – Fundamentals, ch. 18).

    Parameters
    ----------
    sin_h
        Sine of the sun's altitude [–].
    direct_normal_w_m2
        S [W/m²] (:func:`direct_irradiance_w_m2` for the clear sky).
    diffuse_horizontal_w_m2
        D [W/m²].
    """
    s = np.clip(np.asarray(sin_h, dtype=float), 0.0, 1.0)
    direct = np.where(s > 0, np.asarray(direct_normal_w_m2, dtype=float), 0.0)
    diffuse = np.asarray(diffuse_horizontal_w_m2, dtype=float)
    kappa = box.solar_absorptivity * min(
        1.0, box.wall_heat_transfer_w_m2k / box.outside_film_coefficient_w_m2k
    )
    cos_h = np.sqrt(1.0 - s**2)
    roof = box.roof_area_m2 * (direct * s + diffuse)
    sides = (2.0 * box.side_area_m2 + box.back_area_m2) * (direct * cos_h / np.pi + diffuse / 2)
    return kappa * (roof + sides) * box.shadow_factor
