"""Speed traces: the paper's trapezoid generator (§2.2), NEDC, and CSV drive cycles.

Generator (paper §2.2). Around a mean speed ``v̄`` the driver swings between
``v1 = v̄·(1 − dv)`` and ``v2 = v̄·(1 + dv)`` with acceleration ``ε_d·v̇_max``:
``t_a = (v2 − v1)/(ε_d·v̇_max)``, ``t_p = t_NEDC/k``, ``t_k = t_p/2 − t_a``. One wave goes from
``v̄`` up to ``v2`` (``t_a/2``), holds ``t_k``, down to ``v1`` (``t_a``), holds ``t_k`` and back to
``v̄`` (``t_a/2``); its mean speed is exactly ``v̄``. After each wave the van cruises at ``v̄``
for ``t_0``.

Traffic law (ours; the paper leaves ``t_0(ε_t)`` open): ``t_0 = t_p·(1 − ε_t)/ε_t``. Dense
traffic (``ε_t → 1``) leaves no cruising between waves (stop and go), ``ε_t = 0.5`` cruises as
long as a wave lasts, light traffic (``ε_t → 0``) is nearly constant speed.

Each leg starts and ends at rest, with ramps at ``ε_d·v̇_max`` (a driver with ``ε_d = 0``, who
keeps a constant speed as in the paper's Fig. 10, ramps at :data:`LEAST_RAMP_SHARE`), and covers its
distance exactly. The generator is deterministic: the same inputs give the same trace.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from core.arrays import FloatArray
from core.exceptions import InvalidParameterError, LimitExceededError
from core.params import (
    LEAST_RAMP_SHARE,
    MAX_TRAFFIC_DENSITY,
    MIN_TRAFFIC_DENSITY,
    NEDC_DURATION_S,
    StreetType,
)

KMH = 1 / 3.6
#: Most samples one generated leg may have (about 58 days at 1 Hz): beyond, inputs are absurd.
MAX_LEG_SAMPLES = 5_000_000


def trace_distance_m(speed_mps: FloatArray, dt_s: float) -> float:
    """Distance of a speed trace [m]: trapezoid rule, the mean of each step's end speeds."""
    if speed_mps.size < 2:
        return 0.0
    return float((speed_mps[:-1] + speed_mps[1:]).sum() * 0.5 * dt_s)


def _wave_breakpoints(
    street: StreetType, accel_mps2: float, traffic_density: float, leg_s: float
) -> tuple[FloatArray, FloatArray]:
    """Times [s] and speeds [m/s] of one trapezoid wave plus its cruise, starting at ``v̄``.

    ``leg_s`` is the leg's duration at ``v̄``: cruising longer than that, or a wave that would
    not fit in it (a nearly passive driver), makes the leg a constant-speed run.
    """
    v_mean = street.mean_speed_mps
    v1 = v_mean * (1 - street.speed_variation)
    v2 = v_mean * (1 + street.speed_variation)
    period_s = NEDC_DURATION_S / street.period_divisor
    t_a = (v2 - v1) / accel_mps2 if accel_mps2 > 0 else math.inf
    cruise_s = min(period_s * (1 - traffic_density) / traffic_density, leg_s)
    if 2 * t_a > leg_s or v2 == v1:
        return np.array([0.0, period_s + cruise_s]), np.array([v_mean, v_mean])
    # A driver too calm for the wave to fit in t_p stretches it (t_k = 0).
    t_k = max(period_s / 2 - t_a, 0.0)
    steps = [0.0, t_a / 2, t_k, t_a, t_k, t_a / 2, cruise_s]
    speeds = [v_mean, v2, v2, v1, v1, v_mean, v_mean]
    return np.cumsum(steps), np.array(speeds)


def generate_leg(
    distance_m: float,
    street: StreetType,
    driver_aggressiveness: float,
    max_acceleration_mps2: float,
    traffic_density: float | None = None,
    dt_s: float = 1.0,
) -> FloatArray:
    """A speed trace for one leg, from rest to rest, covering ``distance_m`` (paper §2.2).

    Parameters
    ----------
    distance_m
        Leg distance [m], >= 0. A zero-length leg gives a single sample at rest.
    street
        Street type (mean speed, dv, k, default traffic density).
    driver_aggressiveness
        ε_d [–], 0…1: share of the maximum acceleration the driver uses.
    max_acceleration_mps2
        v̇_max [m/s²].
    traffic_density
        ε_t [–] in (0, 1); None takes the street type's default.
    dt_s
        Sampling interval [s].

    Returns
    -------
    numpy.ndarray
        Speed samples [m/s] every ``dt_s``, first and last 0; their trapezoid distance equals
        ``distance_m`` to rounding.
    """
    _check_leg_inputs(distance_m, driver_aggressiveness, traffic_density, dt_s)
    if distance_m == 0:
        return np.zeros(1)
    if distance_m / street.mean_speed_mps / dt_s > MAX_LEG_SAMPLES:
        raise LimitExceededError(
            f"a {distance_m:g} m leg sampled every {dt_s:g} s needs more than "
            f"{MAX_LEG_SAMPLES:,} samples",
            "distance_m",
        )
    density = street.traffic_density if traffic_density is None else traffic_density
    accel = driver_aggressiveness * max_acceleration_mps2
    ramp_accel = max(driver_aggressiveness, LEAST_RAMP_SHARE) * max_acceleration_mps2
    v_mean = street.mean_speed_mps

    wave_t, wave_v = _wave_breakpoints(street, accel, density, distance_m / v_mean)
    wave_length_m = v_mean * wave_t[-1]
    n_waves = int(distance_m // wave_length_m) + 2
    ramp_s = v_mean / ramp_accel
    offsets = ramp_s + wave_t[-1] * np.arange(n_waves)
    times = np.concatenate(([0.0], (offsets[:, None] + wave_t[None, :]).ravel()))
    speeds = np.concatenate(([0.0], np.tile(wave_v, n_waves)))
    grid = np.arange(0.0, times[-1] + dt_s, dt_s)
    outbound = np.interp(grid, times, speeds)

    # Cut where the distance so far plus the braking distance reaches the target; this sum
    # never decreases while |dv/dt| <= ramp_accel, so the first crossing is the cut.
    travelled = np.concatenate(([0.0], np.cumsum(0.5 * (outbound[:-1] + outbound[1:]) * dt_s)))
    reach = travelled + outbound**2 / (2 * ramp_accel)
    cut = int(np.searchsorted(reach, distance_m)) if reach[-1] >= distance_m else len(reach) - 1
    cut = max(cut, 1)
    v_cut = outbound[cut]
    n_brake = max(math.ceil(v_cut / (ramp_accel * dt_s)), 1)
    braking = v_cut * (1 - np.arange(1, n_brake + 1) / n_brake)
    trace = np.concatenate((outbound[: cut + 1], braking))
    return trace * (distance_m / trace_distance_m(trace, dt_s))


def stretch_to_duration(speed_mps: FloatArray, dt_s: float, duration_s: float) -> FloatArray:
    """Stretch a trace in time to last ``duration_s`` while covering the same distance.

    Used when a client's road router gives a leg's duration: the generated shape is kept, time
    is scaled by ``duration / original duration`` and speed by its inverse.

    Parameters
    ----------
    speed_mps
        Speed samples [m/s] every ``dt_s`` [s], starting and ending at rest.
    duration_s
        Target duration [s], > 0.
    """
    if speed_mps.size < 2 or duration_s <= 0:
        return speed_mps
    distance = trace_distance_m(speed_mps, dt_s)
    old_t = np.arange(speed_mps.size) * dt_s
    n_steps = max(round(duration_s / dt_s), 1)
    new_t = np.linspace(0.0, old_t[-1], n_steps + 1)
    stretched = np.interp(new_t, old_t, speed_mps)
    total = trace_distance_m(stretched, dt_s)
    return stretched * (distance / total) if total > 0 else stretched


#: The shortest leg driven [m]: shorter is standing still (a micrometre; a leg of 5e-324 m
#: has a trace whose distance is no number to scale by).
LEAST_DRIVEN_M = 1e-6
#: How much steeper than the van's acceleration a sampled ramp may come out [–]: sampling a
#: trapezoid's corners on whole steps and scaling it to its distance adds up to a few per cent.
RAMP_TOLERANCE = 0.05


def rest_to_rest(
    distance_m: float, duration_s: float, accel_mps2: float, top_mps: float, dt_s: float = 1.0
) -> FloatArray:
    """The plainest trace that covers ``distance_m`` from rest to rest in ``duration_s`` —
    accelerate at ``accel_mps2``, cruise, brake at ``accel_mps2`` — or, when that is too short
    for a van that accelerates so and tops out at ``top_mps``, in the least time it can.

    The cruising speed solves ``d = v·(T − v/a)``: ``v = (a·T − √(a²T² − 4·a·d))/2``; the least
    time is ``2·√(d/a)`` (no cruise) or ``d/v_top + v_top/a``. The trace starts and ends at
    rest on whole steps (at least two) and covers exactly ``distance_m``: where sampling the
    shape on ``dt_s`` and scaling it to the distance would ask for more than ``top_mps`` or
    clearly more than ``accel_mps2`` (:data:`RAMP_TOLERANCE`), it takes a step longer.

    Parameters
    ----------
    distance_m, duration_s
        The leg [m] and the time it should take [s].
    accel_mps2, top_mps
        The van's acceleration (and deceleration) [m/s²] and top speed [m/s].
    """
    if distance_m < LEAST_DRIVEN_M:  # no drive (a subnormal number's trace has no distance)
        return np.zeros(max(round(duration_s / dt_s), 0) + 1)
    least_s = float(fastest_s(distance_m, accel_mps2, top_mps))
    steps = max(math.ceil(max(duration_s, least_s) / dt_s - 1e-9), 2)
    while True:
        trace = _trapezoid(distance_m, steps * dt_s, accel_mps2, dt_s)
        steepest = float(np.abs(np.diff(trace)).max()) / dt_s
        if trace.max() <= top_mps and steepest <= accel_mps2 * (1 + RAMP_TOLERANCE):
            return trace
        steps += 1


def _trapezoid(distance_m: float, total_s: float, accel_mps2: float, dt_s: float) -> FloatArray:
    """Accelerate, cruise, brake over ``total_s`` (a whole number of ``dt_s``, no less than
    the least time), sampled every ``dt_s`` and scaled to cover ``distance_m`` exactly."""
    a = accel_mps2
    # v = (a·T − √(a²T² − 4·a·d))/2, written without the difference of two near numbers
    root = math.sqrt(max(a * a * total_s * total_s - 4 * a * distance_m, 0.0))
    cruise = 2 * a * distance_m / (a * total_s + root)
    ramp_s = cruise / a
    times = np.array([0.0, ramp_s, total_s - ramp_s, total_s])
    grid = np.arange(round(total_s / dt_s) + 1) * dt_s
    trace = np.interp(grid, times, np.array([0.0, cruise, cruise, 0.0]))
    return trace * (distance_m / trace_distance_m(trace, dt_s))


def fastest_s(
    distance_m: float | FloatArray, accel_mps2: float, top_mps: float
) -> float | FloatArray:
    """The least time a van covers ``distance_m`` from rest to rest with ``accel_mps2`` and a
    top speed of ``top_mps`` [s]: accelerating then braking, with a cruise at the top speed
    between when the distance allows one. Elementwise over an array of distances."""
    distance = np.asarray(distance_m, dtype=float)
    ramps = 2.0 * np.sqrt(distance / accel_mps2)
    cruise = distance / top_mps + top_mps / accel_mps2
    least = np.where(distance <= top_mps * top_mps / accel_mps2, ramps, cruise)
    return float(least) if least.ndim == 0 else least


#: Spacing of the distance grid on which a road speed profile is driven [m].
PROFILE_GRID_M = 1.0
#: Most grid points of one driven profile (beyond, the grid coarsens).
_MAX_PROFILE_POINTS = 400_000
#: Slowest and fastest speed a road segment may ask for [m/s] (a router's 0 or absurd speeds).
_SEGMENT_SPEED_RANGE_MPS = (1.0, 60.0)


def drive_profile(
    segment_distance_m: FloatArray,
    segment_speed_mps: FloatArray,
    street: StreetType,
    driver_aggressiveness: float,
    max_acceleration_mps2: float,
    traffic_density: float | None = None,
    dt_s: float = 1.0,
) -> tuple[FloatArray, FloatArray]:
    """Drive a road's speed profile: a trace from rest to rest and the distance at each sample.

    Each segment's speed (from a road router) is the target and the ceiling. The traffic's
    slow-downs come on top: the trapezoid wave of ``street`` (paper §2.2; spaced along the road
    at the leg's mean speed, denser with more traffic, ramps set by the driver) as a factor on
    the target, capped at 1 — the router's free-flow speed is not exceeded. The van moves
    between targets at ``max(ε_d, 0.2)·v̇_max``, braking ahead of slower segments and of the
    end: on a 1 m distance grid the speed is the lowest of every target reachable from the
    start or the end, ``v(s)² = min_j (v_j² + 2·a·|s − s_j|)``, with running minima (no loop).
    Time follows from ``ds / v``; the trace is resampled every ``dt_s`` and scaled to cover
    the road's distance exactly.

    Parameters
    ----------
    segment_distance_m, segment_speed_mps
        Length [m] and target speed [m/s] of each road segment, in driving order.
    street
        Street type whose wave the driver and traffic add.
    driver_aggressiveness, max_acceleration_mps2, traffic_density, dt_s
        As for :func:`generate_leg`.

    Returns
    -------
    tuple of numpy.ndarray
        Speed samples [m/s] every ``dt_s`` (first and last 0) and the distance driven at each
        sample [m].
    """
    lengths, targets, mean_speed = _segments(segment_distance_m, segment_speed_mps)
    total = float(lengths.sum())
    _check_leg_inputs(total, driver_aggressiveness, traffic_density, dt_s)
    if total == 0:
        return np.zeros(1), np.zeros(1)
    if total / _SEGMENT_SPEED_RANGE_MPS[0] / dt_s > MAX_LEG_SAMPLES:
        raise LimitExceededError(f"a {total:g} m leg needs too many samples", "distance_m")
    step_m = max(PROFILE_GRID_M, total / _MAX_PROFILE_POINTS)
    grid = np.append(np.arange(0.0, total, step_m), total)
    segment = np.minimum(np.searchsorted(np.cumsum(lengths), grid, side="right"), lengths.size - 1)
    # The traffic's wave as a slow-down of the road's speed, never above it.
    density = street.traffic_density if traffic_density is None else traffic_density
    wave_street = street.model_copy(update={"mean_speed_mps": mean_speed})
    wave_t, wave_v = _wave_breakpoints(
        wave_street, driver_aggressiveness * max_acceleration_mps2, density, total / mean_speed
    )
    slowdown = np.minimum(wave_v / mean_speed, 1.0)
    target = targets[segment] * np.interp(
        grid % (mean_speed * wave_t[-1]), wave_t * mean_speed, slowdown
    )
    accel = max(driver_aggressiveness, LEAST_RAMP_SHARE) * max_acceleration_mps2
    trace = _in_time(grid, _within_acceleration(grid, target, accel), dt_s)
    if trace_distance_m(trace, dt_s) == 0:  # a hop shorter than one sample: the plain ramp
        trace = generate_leg(
            total, street, driver_aggressiveness, max_acceleration_mps2, None, dt_s
        )
    trace *= total / trace_distance_m(trace, dt_s)
    travelled = np.concatenate(([0.0], np.cumsum(0.5 * (trace[:-1] + trace[1:]) * dt_s)))
    return trace, travelled


def _segments(
    segment_distance_m: FloatArray, segment_speed_mps: FloatArray
) -> tuple[FloatArray, FloatArray, float]:
    """A road's segment lengths [m] and speeds [m/s], checked, with absurd or missing speeds
    brought within :data:`_SEGMENT_SPEED_RANGE_MPS` (missing ones to the road's mean), and the
    road's mean speed [m/s]."""
    lengths = np.asarray(segment_distance_m, dtype=float)
    targets = np.asarray(segment_speed_mps, dtype=float)
    if lengths.ndim != 1 or lengths.shape != targets.shape:
        raise InvalidParameterError(
            "segment distances and speeds must be 1-D and of equal length", "segment_speed_mps"
        )
    if lengths.size == 0 or not np.all(np.isfinite(lengths) & (lengths >= 0)):
        raise InvalidParameterError("segment distances must be finite and >= 0", "distance_m")
    low, high = _SEGMENT_SPEED_RANGE_MPS
    moving = lengths > 0
    if not moving.any():
        return lengths, np.full(lengths.size, low), low
    known = np.clip(np.where(np.isfinite(targets[moving]), targets[moving], low), low, high)
    mean_speed = float(np.sum(lengths[moving]) / np.sum(lengths[moving] / known))
    return (
        lengths,
        np.clip(np.where(np.isfinite(targets), targets, mean_speed), low, high),
        mean_speed,
    )


def _within_acceleration(
    grid_m: FloatArray, target_mps: FloatArray, accel_mps2: float
) -> FloatArray:
    """The speed on a distance grid [m/s]: the lowest of every target reachable from the start
    or the end at ``accel_mps2``, ``v(s)² = min_j (v_j² + 2·a·|s − s_j|)``, from rest to rest,
    with running minima (no loop)."""
    squared = target_mps**2
    squared[0] = squared[-1] = 0.0
    reach = 2.0 * accel_mps2 * grid_m
    forward = reach + np.minimum.accumulate(squared - reach)
    backward = -reach + np.minimum.accumulate((squared + reach)[::-1])[::-1]
    return np.sqrt(np.maximum(np.minimum(forward, backward), 0.0))


def _in_time(grid_m: FloatArray, speed_mps: FloatArray, dt_s: float) -> FloatArray:
    """A speed profile over distance as samples every ``dt_s`` [m/s], ending at rest: time
    follows from ``ds / v``."""
    mean_cell = 0.5 * (speed_mps[:-1] + speed_mps[1:])
    cell_s = np.diff(grid_m) / np.maximum(mean_cell, 1e-3)
    clock = np.concatenate(([0.0], np.cumsum(cell_s)))
    trace: FloatArray = np.interp(np.arange(0.0, clock[-1] + dt_s, dt_s), clock, speed_mps)
    trace[-1] = 0.0
    return trace


def _check_leg_inputs(
    distance_m: float, driver_aggressiveness: float, traffic_density: float | None, dt_s: float
) -> None:
    if not (math.isfinite(distance_m) and distance_m >= 0):
        raise InvalidParameterError(
            f"distance_m must be finite and >= 0, got {distance_m}", "distance_m"
        )
    if not 0 <= driver_aggressiveness <= 1:
        raise InvalidParameterError(
            f"driver_aggressiveness must be within 0..1, got {driver_aggressiveness}",
            "driver_aggressiveness",
        )
    if traffic_density is not None and not (
        MIN_TRAFFIC_DENSITY <= traffic_density <= MAX_TRAFFIC_DENSITY
    ):
        raise InvalidParameterError(
            f"traffic_density must be within {MIN_TRAFFIC_DENSITY}..{MAX_TRAFFIC_DENSITY}, "
            f"got {traffic_density}",
            "traffic_density",
        )
    if not (math.isfinite(dt_s) and dt_s > 0):
        raise InvalidParameterError(f"dt_s must be finite and > 0, got {dt_s}", "dt_s")


# --- Standard cycles --------------------------------------------------------------------------

# ECE-15 elementary urban cycle, UNECE Regulation No. 83, Annex 4a, Table 1: breakpoints of
# (time [s], speed [km/h]); linear in between. 195 s, 0.994 km.
_ECE15 = (
    (0, 0),
    (11, 0),
    (15, 15),
    (23, 15),
    (25, 10),
    (28, 0),
    (49, 0),
    (54, 15),
    (56, 15),
    (61, 32),
    (85, 32),
    (93, 10),
    (96, 0),
    (117, 0),
    (122, 15),
    (124, 15),
    (133, 35),
    (135, 35),
    (143, 50),
    (155, 50),
    (163, 35),
    (178, 35),
    (185, 10),
    (188, 0),
    (195, 0),
)
# Extra-urban driving cycle (EUDC), same regulation, Annex 4a, Table 2. 400 s, 6.955 km.
_EUDC = (
    (0, 0),
    (20, 0),
    (25, 15),
    (27, 15),
    (36, 35),
    (38, 35),
    (46, 50),
    (48, 50),
    (61, 70),
    (111, 70),
    (119, 50),
    (188, 50),
    (201, 70),
    (251, 70),
    (286, 100),
    (316, 100),
    (336, 120),
    (346, 120),
    (362, 80),
    (370, 50),
    (380, 0),
    (400, 0),
)


@dataclass(frozen=True)
class DriveCycle:
    """A speed trace at a fixed sampling interval.

    Attributes
    ----------
    name
        Where it came from.
    dt_s
        Sampling interval [s].
    speed_mps
        Speed samples [m/s].
    grade
        Road grade of each sample [–].
    """

    name: str
    dt_s: float
    speed_mps: FloatArray
    grade: FloatArray

    @property
    def distance_m(self) -> float:
        """Trapezoid distance [m]."""
        return trace_distance_m(self.speed_mps, self.dt_s)

    @property
    def duration_s(self) -> float:
        """Duration [s]."""
        return (self.speed_mps.size - 1) * self.dt_s


def _from_breakpoints(name: str, points: tuple[tuple[int, int], ...]) -> DriveCycle:
    t, v = np.array(points, dtype=float).T
    grid = np.arange(0.0, t[-1] + 1.0)
    return DriveCycle(name, 1.0, np.interp(grid, t, v) * KMH, np.zeros(grid.size))


def nedc() -> DriveCycle:
    """The New European Driving Cycle at 1 Hz: 4 × ECE-15 then EUDC (1180 s, ≈ 10.93 km)."""
    ece = _from_breakpoints("ECE-15", _ECE15).speed_mps
    eudc = _from_breakpoints("EUDC", _EUDC).speed_mps
    # Each part starts and ends at rest; drop the duplicated joint sample.
    speed = np.concatenate([ece] + [ece[1:]] * 3 + [eudc[1:]])
    return DriveCycle("NEDC", 1.0, speed, np.zeros(speed.size))


# Column names of the time, speed and grade columns, by header style.
_HEADER_STYLES = (
    ("time_seconds", "speed_meters_per_second", "grade"),  # FASTSim 3
    ("cycSecs", "cycMps", "cycGrade"),  # FASTSim 2
    ("time_s", "speed_mps", "grade"),  # coldroute
)


def load_cycle_csv(path: str | Path) -> DriveCycle:
    """Read a drive cycle from CSV: time [s], speed [m/s] and optionally grade [–].

    Accepts the FASTSim-3 header (``time_seconds,speed_meters_per_second,grade``), the FASTSim-2
    header (``cycSecs,cycMps,cycGrade,...``) and ``time_s,speed_mps,grade``; a UTF-8 BOM and CRLF
    line ends are fine. Time must start anywhere, rise in equal steps; speed must be finite
    and >= 0.
    """
    path = Path(path)
    with path.open(newline="", encoding="utf-8-sig") as handle:
        rows = list(csv.DictReader(handle))
    if not rows:
        raise InvalidParameterError(f"{path.name}: no data rows", "cycle")
    header = set(rows[0])
    for time_col, speed_col, grade_col in _HEADER_STYLES:  # noqa: B007 (used after break)
        if {time_col, speed_col} <= header:
            break
    else:
        raise InvalidParameterError(
            f"{path.name}: unknown header {sorted(header)}; expected one of "
            f"{[style[:2] for style in _HEADER_STYLES]}",
            "cycle",
        )
    try:
        time_s = np.array([float(r[time_col]) for r in rows])
        speed = np.array([float(r[speed_col]) for r in rows])
        grade = np.array([float(r.get(grade_col) or 0.0) for r in rows])
    except ValueError as error:
        raise InvalidParameterError(f"{path.name}: non-numeric value ({error})", "cycle") from None
    steps = np.diff(time_s)
    if steps.size == 0 or not np.all(np.isfinite(time_s)) or steps.min() <= 0:
        raise InvalidParameterError(f"{path.name}: time must rise strictly", "cycle")
    if np.ptp(steps) > 1e-6 * steps.mean():
        raise InvalidParameterError(f"{path.name}: time steps must be equal", "cycle")
    if not np.all(np.isfinite(speed)) or speed.min() < 0:
        raise InvalidParameterError(f"{path.name}: speed must be finite and >= 0", "cycle")
    return DriveCycle(path.stem, float(steps.mean()), speed, grade)
