"""What a van whose motor is capped (``max_motor_power_w``) really drives.

A trace that asks for more power at the wheels than the motor has cannot be followed: the van
accelerates more slowly, ``m·v·dv/ds = P_max/v − R(v)`` with the resistances ``R`` of eqs 3–5,
reaches the trace's speed later or not at all (a steep climb), and takes longer for the same
distance. The energy the trace needs is then delivered later — it is never dropped. Each move
(from rest to rest) is driven on a distance grid with the trace's speed at each position as the
target and the ceiling, braking as the trace brakes; the Python loop runs only through the
stretches where the cap binds, from where the van falls behind until it has caught up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from core.arrays import FloatArray
from core.exceptions import InvalidParameterError
from core.params import VehicleParams
from core.physics.vehicle import drag_force_n, rolling_force_n, slope_force_n, traction_force_n

#: Power a trace may ask for beyond the cap before it is re-driven [–]: the resampling of a
#: re-driven trace to whole seconds leaves it within this of the cap.
CAP_TOLERANCE = 0.05
#: Spacing of the distance grid a capped move is driven on [m].
GRID_M = 0.5
#: Speed below which the motor's torque, not its power, limits the acceleration [m/s]: the
#: trace's own acceleration applies there.
_TORQUE_LIMITED_MPS = 1.0


@dataclass(frozen=True)
class Retimed:
    """A trace re-driven under the motor's cap.

    Attributes
    ----------
    speed_mps
        The speed the van drives, every ``dt_s`` [m/s].
    dt_s
        Sampling interval [s], the original's.
    original_s
        For each of its samples, the moment of the original trace at the same place [s]
        (standstills keep their length and move later by the time lost before them).
    """

    speed_mps: FloatArray
    dt_s: float
    original_s: FloatArray

    @property
    def lost_s(self) -> float:
        """How much longer the trace takes [s]."""
        return (self.speed_mps.size - 1) * self.dt_s - float(self.original_s[-1])

    def moment_s(self, original_s: float) -> float:
        """When a moment of the original trace comes in the re-driven one [s]."""
        new_s = np.arange(self.speed_mps.size) * self.dt_s
        return float(np.interp(original_s, self.original_s, new_s))


def mechanical_power_w(
    vehicle: VehicleParams, speed_mps: FloatArray, dt_s: float, mass_kg: ArrayLike, grade: ArrayLike
) -> FloatArray:
    """Power at the wheels of every step of a trace [W] (eqs 2, 6): the mean speed of the
    step, its speed change for inertia."""
    v_mean = 0.5 * (speed_mps[:-1] + speed_mps[1:])
    accel = np.diff(speed_mps) / dt_s
    return traction_force_n(vehicle, mass_kg, v_mean, accel, grade) * v_mean


def power_limited(
    vehicle: VehicleParams,
    speed_mps: FloatArray,
    dt_s: float,
    mass_kg: ArrayLike,
    grade: ArrayLike = 0.0,
) -> Retimed | None:
    """The trace the van drives with its motor's cap, or None when the cap never binds.

    Parameters
    ----------
    speed_mps
        The trace asked for [m/s], ``n`` samples every ``dt_s`` [s].
    mass_kg, grade
        Total mass [kg] and grade [–] of each step: scalars or ``n − 1`` values.
    """
    cap = vehicle.max_motor_power_w
    if cap is None or speed_mps.size < 2:
        return None
    steps = speed_mps.size - 1
    mass = np.broadcast_to(np.asarray(mass_kg, dtype=float), (steps,))
    slope = np.broadcast_to(np.asarray(grade, dtype=float), (steps,))
    power = mechanical_power_w(vehicle, speed_mps, dt_s, mass, slope)
    limit = cap * (1 + CAP_TOLERANCE)
    if power.max() <= limit:
        return None
    pieces: list[FloatArray] = []
    origins: list[FloatArray] = []
    placed = 0  # the original samples before this one are in the pieces
    for first, last in _moves(speed_mps):
        if first > placed:  # standing still until this move
            pieces.append(speed_mps[placed:first])
            origins.append(np.arange(placed, first) * dt_s)
        asked = speed_mps[first : last + 1]
        if power[first:last].max() <= limit:  # the cap does not bind on this move: as asked
            driven, origin = asked, np.arange(first, last + 1) * dt_s
        else:
            driven = _drive_move(vehicle, cap, asked, dt_s, mass[first:last], slope[first:last])
            origin = first * dt_s + _origin_s(asked, driven, dt_s)
        shared = 1 if placed > first else 0  # a one-sample stop both moves touch
        pieces.append(driven[shared:])
        origins.append(origin[shared:])
        placed = last + 1
    if placed < speed_mps.size:  # standing still after the last move
        pieces.append(speed_mps[placed:])
        origins.append(np.arange(placed, speed_mps.size) * dt_s)
    return Retimed(np.concatenate(pieces), dt_s, np.concatenate(origins))


def _moves(speed_mps: FloatArray) -> list[tuple[int, int]]:
    """The moves of a trace: (first, last) sample of each run from rest to rest (a trace that
    starts or ends moving counts its first or last sample as rest)."""
    moving = speed_mps > 0
    edges = np.flatnonzero(np.diff(moving.astype(np.int8)))
    starts = [int(e) for e in edges if not moving[e]] + ([0] if moving[0] else [])
    ends = [int(e) + 1 for e in edges if moving[e]] + ([speed_mps.size - 1] if moving[-1] else [])
    return list(zip(sorted(starts), sorted(ends), strict=True))


def _drive_move(
    vehicle: VehicleParams,
    cap_w: float,
    speed_mps: FloatArray,
    dt_s: float,
    mass_kg: FloatArray,
    grade: FloatArray,
) -> FloatArray:
    """One move, from rest to rest, driven under the cap: samples every ``dt_s`` [m/s]."""
    travelled = np.concatenate(([0.0], np.cumsum(0.5 * (speed_mps[:-1] + speed_mps[1:]) * dt_s)))
    total = float(travelled[-1])
    grid = np.append(np.arange(0.0, total, min(GRID_M, total / 4)), total)
    target = np.interp(grid, travelled, speed_mps)
    step_at = np.minimum(np.searchsorted(travelled, grid, side="right") - 1, mass_kg.size - 1)
    step_at = np.maximum(step_at, 0)
    mass, slope = mass_kg[step_at], grade[step_at]
    speed = _capped_speed(vehicle, cap_w, grid, target, mass, slope)
    mean = 0.5 * (speed[:-1] + speed[1:])
    clock = np.concatenate(([0.0], np.cumsum(np.diff(grid) / np.maximum(mean, 1e-3))))
    trace: FloatArray = np.interp(np.arange(0.0, clock[-1] + dt_s, dt_s), clock, speed)
    trace[0] = trace[-1] = 0.0
    covered = 0.5 * float((trace[:-1] + trace[1:]).sum()) * dt_s
    return trace * (total / covered) if covered > 0 else trace


def _capped_speed(
    vehicle: VehicleParams,
    cap_w: float,
    grid_m: FloatArray,
    target_mps: FloatArray,
    mass_kg: FloatArray,
    grade: FloatArray,
) -> FloatArray:
    """The speed on the distance grid [m/s]: the target where the motor can follow it, else
    what the capped power reaches, ``v_{i+1}² = v_i² + 2·Δs·(P_max/v_i − R(v_i))/m``."""
    ds = np.diff(grid_m)
    squared = target_mps**2
    # Where the motor can follow the target at all, step by step (on the target itself).
    need = mass_kg[:-1] * (squared[1:] - squared[:-1]) / (2 * ds) + _resistance_n(
        vehicle, target_mps[:-1], mass_kg[:-1], grade[:-1]
    )
    followable = need * np.maximum(target_mps[:-1], _TORQUE_LIMITED_MPS) <= cap_w
    speed = target_mps.copy()
    binding = np.flatnonzero(~followable)
    i = int(binding[0]) if binding.size else speed.size
    while i < speed.size - 1:
        v = max(speed[i], 0.0)
        power_n = cap_w / max(v, _TORQUE_LIMITED_MPS)
        accel = (power_n - _resistance_n(vehicle, v, mass_kg[i], grade[i])) / mass_kg[i]
        reach = v * v + 2.0 * ds[i] * accel
        if reach <= 0.0:  # the van cannot climb this at all: it stalls
            raise _stalled(vehicle, float(grade[i]), cap_w)
        following = math.sqrt(reach) >= target_mps[i + 1]
        speed[i + 1] = target_mps[i + 1] if following else math.sqrt(reach)
        i += 1
        if following:  # caught up: on to where the target is next out of reach
            later = binding[binding >= i]
            i = int(later[0]) if later.size else speed.size
    return speed


def _resistance_n(
    vehicle: VehicleParams, speed_mps: ArrayLike, mass_kg: ArrayLike, grade: ArrayLike
) -> NDArray[np.float64]:
    """Rolling, drag and slope at a speed [N] (eqs 3–5)."""
    return (
        rolling_force_n(vehicle, mass_kg)
        + drag_force_n(vehicle, speed_mps)
        + slope_force_n(mass_kg, grade)
    )


def _origin_s(asked_mps: FloatArray, driven_mps: FloatArray, dt_s: float) -> FloatArray:
    """For each sample of a re-driven move, the moment of the asked-for move at the same place
    [s after the move's start]."""
    asked_at = np.concatenate(([0.0], np.cumsum(0.5 * (asked_mps[:-1] + asked_mps[1:]) * dt_s)))
    driven_at = np.concatenate(([0.0], np.cumsum(0.5 * (driven_mps[:-1] + driven_mps[1:]) * dt_s)))
    times = np.arange(asked_mps.size) * dt_s
    # Distance never falls; at standstill within a move the first moment there is taken.
    return np.interp(driven_at, asked_at, times)


def _stalled(vehicle: VehicleParams, grade: float, cap_w: float) -> InvalidParameterError:
    return InvalidParameterError(
        f"with a motor of {cap_w / 1000:g} kW the van cannot climb a grade of {grade:.0%}",
        "vehicle.max_motor_power_w",
    )
