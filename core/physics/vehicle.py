"""Longitudinal vehicle dynamics (paper §2.1, eqs 1–8).

A speed trace sampled every ``dt_s`` seconds is simulated step by step: step ``k`` runs from
sample ``k-1`` to sample ``k``. Each step uses the mean of its start and end speed for drag and
power and the speed change over the step for inertia; using the end speed alone overstates
city-cycle energy by up to 10 % (docs/validation.md).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray
from core.params import GRAVITY_MPS2, VehicleParams


def rolling_force_n(vehicle: VehicleParams, mass_kg: ArrayLike) -> FloatArray:
    """Rolling resistance ``F_fric = f·m·g·c_r`` [N] (eq. 4, f = 1.25 in the paper).

    Parameters
    ----------
    vehicle
        Vehicle parameters (``rolling_resistance_factor``, ``rolling_resistance_coefficient``).
    mass_kg
        Total mass, vehicle plus payload [kg].
    """
    return (
        vehicle.rolling_resistance_factor
        * np.asarray(mass_kg, dtype=float)
        * GRAVITY_MPS2
        * vehicle.rolling_resistance_coefficient
    )


def drag_force_n(
    vehicle: VehicleParams, speed_mps: ArrayLike, headwind_mps: ArrayLike = 0.0
) -> FloatArray:
    """Aerodynamic drag ``F_drag = ½·ρ·A_f·c_d·v_air·|v_air|`` [N] (eq. 3).

    ``v_air = v + w`` is the speed through the air with a headwind ``w``; the paper's still air
    is ``w = 0``. A tailwind faster than the van pushes it (negative drag).

    Parameters
    ----------
    speed_mps
        Speed over ground [m/s].
    headwind_mps
        Wind component against the direction of travel [m/s]; negative for a tailwind.
    """
    airspeed = np.asarray(speed_mps, dtype=float) + np.asarray(headwind_mps, dtype=float)
    return (
        0.5
        * vehicle.air_density_kg_m3
        * vehicle.frontal_area_m2
        * vehicle.drag_coefficient
        * airspeed
        * np.abs(airspeed)
    )


def slope_force_n(mass_kg: ArrayLike, grade: ArrayLike) -> FloatArray:
    """Slope force ``F_sl = m·g·sin(arctan(s))`` [N] (eq. 5).

    Parameters
    ----------
    mass_kg
        Total mass [kg].
    grade
        Road grade s as rise over run [–] (0.05 = 5 %); negative downhill.
    """
    s = np.asarray(grade, dtype=float)
    # sin(arctan(s)) = s / sqrt(1 + s²), without two transcendental calls per sample.
    return np.asarray(mass_kg, dtype=float) * GRAVITY_MPS2 * s / np.sqrt(1.0 + s * s)


def traction_force_n(
    vehicle: VehicleParams,
    mass_kg: ArrayLike,
    speed_mps: ArrayLike,
    accel_mps2: ArrayLike,
    grade: ArrayLike,
    headwind_mps: ArrayLike = 0.0,
) -> FloatArray:
    """Tractive force ``F_acc = F_fric + F_drag + F_sl + m·dv/dt`` [N] (eq. 2).

    Rolling resistance and drag act only while the van moves (zero at standstill).
    """
    v = np.asarray(speed_mps, dtype=float)
    m = np.asarray(mass_kg, dtype=float)
    moving = v > 0
    rolling = np.where(moving, rolling_force_n(vehicle, m), 0.0)
    drag = np.where(moving, drag_force_n(vehicle, v, headwind_mps), 0.0)
    return rolling + drag + slope_force_n(m, grade) + m * np.asarray(accel_mps2)


def electric_power_w(
    vehicle: VehicleParams, mechanical_power_w: ArrayLike, regen_floor_w: ArrayLike = -np.inf
) -> FloatArray:
    """Battery power for a mechanical power at the wheels [W] (eq. 7, with regeneration).

    Motoring (``P_mech >= 0``): ``P_el = P_mech / η_el``. Braking: ``P_el = η_regen ·
    max(P_mech, floor)`` (negative: charges the battery) — the friction brakes take what lies
    below ``regen_floor_w``, the motor's braking limit — capped at ``max_regen_power_w``. The
    paper's eq. 7 applied to braking would return more than the brakes take in, hence the
    separate efficiency.
    """
    p = np.asarray(mechanical_power_w, dtype=float)
    regen = vehicle.regen_efficiency * np.maximum(p, regen_floor_w)
    if vehicle.max_regen_power_w is not None:
        regen = np.maximum(regen, -vehicle.max_regen_power_w)
    return np.where(p >= 0, p / vehicle.drivetrain_efficiency, regen)


def step_traction_power_w(
    vehicle: VehicleParams,
    speed_mps: FloatArray,
    dt_s: float,
    mass_kg: ArrayLike,
    grade: ArrayLike,
    headwind_mps: ArrayLike = 0.0,
) -> FloatArray:
    """Electric traction power of every step of a speed trace [W] (eqs 2, 6, 7).

    The trace is driven as it is: a motor's cap changes the trace the van can drive
    (:func:`core.physics.motor.power_limited`), not the power of a trace.

    Parameters
    ----------
    speed_mps
        Speed samples, ``n`` values [m/s].
    dt_s
        Sampling interval [s].
    mass_kg, grade, headwind_mps
        Total mass [kg], grade [–] and headwind [m/s] of each step: scalars or ``n − 1``
        values (grade may also carry leading axes, e.g. a table of grades).

    Returns
    -------
    numpy.ndarray
        ``n − 1`` values: the mean battery power over each step [W].
    """
    v_start, v_end = speed_mps[:-1], speed_mps[1:]
    v_mean = 0.5 * (v_start + v_end)
    accel = (v_end - v_start) / dt_s
    mechanical = traction_force_n(vehicle, mass_kg, v_mean, accel, grade, headwind_mps) * v_mean
    return electric_power_w(vehicle, mechanical, regen_floor_w(vehicle, mass_kg, v_mean))


def regen_floor_w(vehicle: VehicleParams, mass_kg: ArrayLike, speed_mps: ArrayLike) -> FloatArray:
    """The most braking power the motor takes at a speed [W, negative]: its braking force
    ``m · max_regen_deceleration_mps2`` times the speed; −∞ without that limit."""
    limit = vehicle.max_regen_deceleration_mps2
    if limit is None:
        return np.full(np.shape(speed_mps), -np.inf)
    return -np.asarray(mass_kg, dtype=float) * limit * np.asarray(speed_mps, dtype=float)
