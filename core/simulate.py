"""One speed trace in, per-consumer power, energy and state of charge out.

Everything is computed over the whole time grid at once with numpy; there is no Python loop
per time step. A trace of ``n`` samples has ``n − 1`` steps; per-step arrays hold the mean
power over each step.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from core import battery as battery_model
from core.arrays import FloatArray
from core.cabin import auxiliaries_power_w, cabin_hvac_power_w
from core.cargo import BoxResult, refrigeration
from core.cycles import trace_distance_m
from core.exceptions import InvalidParameterError
from core.params import DoorOpening, Location, VanParams, Weather
from core.solar import (
    absorbed_solar_heat_w,
    declination_deg,
    equation_of_time_min,
    sin_altitude,
    solar_time_h,
)
from core.vehicle import step_traction_power_w
from core.weather import WeatherSource, daily_temperature_c, resolve_weather

CONSUMERS = ("traction", "auxiliaries", "cabin", "refrigeration")
#: Highest speed a trace may hold [m/s] (250 km/h): anything faster is a unit mistake.
MAX_SPEED_MPS = 250 / 3.6
#: Steepest grade accepted [–] (the steepest public streets are about 0.35).
MAX_ABS_GRADE = 0.5


@dataclass(frozen=True)
class SimulationResult:
    """Energy of one trace.

    Attributes
    ----------
    time_s
        Sample times since the start [s], ``n`` values.
    speed_mps
        Speed samples [m/s], ``n`` values.
    power_w
        Mean electric power of each consumer over each step [W], ``n − 1`` values each.
    energy_kwh
        Energy of each consumer and ``total`` [kWh].
    distance_m, duration_s
        Distance [m] and duration [s] of the trace.
    soc
        State of charge at every sample [–], ``n`` values.
    battery
        Feasibility verdict.
    box
        Cargo-box heat flows and temperatures.
    ambient_c
        Ambient temperature of each step [°C].
    weather, weather_source
        The day's extremes used and whether they came from the request or the climatology.
    """

    time_s: FloatArray
    speed_mps: FloatArray
    power_w: dict[str, FloatArray]
    energy_kwh: dict[str, float]
    distance_m: float
    duration_s: float
    soc: FloatArray
    battery: battery_model.BatteryVerdict
    box: BoxResult
    ambient_c: FloatArray
    weather: Weather
    weather_source: WeatherSource


@dataclass(frozen=True)
class LocalClock:
    """Local clock time along a trace.

    Attributes
    ----------
    hour
        Clock hour of each moment [h since local midnight].
    day_index
        Day of each moment, 0 for the start day.
    dates
        The calendar date of each day index.
    """

    hour: FloatArray
    day_index: NDArray[np.int_]
    dates: list[dt.date]

    def per_moment(self, per_day: ArrayLike) -> FloatArray:
        """Spread one value per day to every moment."""
        return np.asarray(per_day, dtype=float)[self.day_index]


def local_clock(start: dt.datetime, offsets_s: FloatArray) -> LocalClock:
    """Local clock time at ``start + offsets_s``; the start's UTC offset holds throughout.

    Parameters
    ----------
    start
        Timezone-aware start.
    offsets_s
        Seconds after the start [s], >= 0.
    """
    start_hour = start.hour + start.minute / 60 + (start.second + start.microsecond / 1e6) / 3600
    hours = start_hour + offsets_s / 3600.0
    day_index = np.floor(hours / 24.0).astype(int)
    n_days = int(day_index.max()) + 1 if day_index.size else 1
    dates = [start.date() + dt.timedelta(days=d) for d in range(n_days)]
    return LocalClock(hours - 24.0 * day_index, day_index, dates)


def door_open_fraction(
    openings: Sequence[DoorOpening], step_end_s: FloatArray, dt_s: float
) -> FloatArray:
    """Share of each step [–] during which the door is open.

    The door's total open time up to ``t`` is piecewise linear in ``t`` (slope 1 while any
    opening is under way, so overlapping openings count once); it is built from the sorted start
    and end events and read at the step edges with one interpolation. Its difference over a
    step, divided by the step length, is the share.
    """
    if not openings:
        return np.zeros(step_end_s.size)
    start = np.array([o.start_s for o in openings])
    end = start + np.array([o.duration_s for o in openings])
    events = np.concatenate((start, end))
    order = np.argsort(events, kind="stable")
    events = events[order]
    under_way = np.cumsum(np.concatenate((np.ones(start.size), -np.ones(end.size)))[order])
    slope = (under_way > 0).astype(float)
    open_until = np.concatenate(([0.0], np.cumsum(np.diff(events) * slope[:-1])))
    edges = np.concatenate(([step_end_s[0] - dt_s], step_end_s))
    total = np.interp(edges, events, open_until)
    return np.clip(np.diff(total) / dt_s, 0.0, 1.0)


def _per_step(value: ArrayLike, n_samples: int, name: str, low: float, high: float) -> FloatArray:
    """A scalar or per-sample input as per-step values (mean of each step's two samples)."""
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        array = np.full(n_samples, float(array))
    if array.shape != (n_samples,):
        raise InvalidParameterError(
            f"{name} must be a number or hold one value per speed sample ({n_samples}), "
            f"got shape {array.shape}",
            name,
        )
    bad = np.flatnonzero(~np.isfinite(array) | (array < low) | (array > high))
    if bad.size:
        raise InvalidParameterError(
            f"{name}[{bad[0]}] = {array[bad[0]]} is outside {low}..{high} or not finite",
            f"{name}[{bad[0]}]",
        )
    return 0.5 * (array[:-1] + array[1:])


def check_trace(speed_mps: ArrayLike, dt_s: float) -> FloatArray:
    """Validate a speed trace: 1-D, at least two samples, finite, 0…250 km/h; ``dt_s`` > 0."""
    speed = np.asarray(speed_mps, dtype=float)
    if speed.ndim != 1 or speed.size < 2:
        raise InvalidParameterError("speed_mps must be a list of at least 2 samples", "speed_mps")
    bad = np.flatnonzero(~np.isfinite(speed) | (speed < 0) | (speed > MAX_SPEED_MPS))
    if bad.size:
        raise InvalidParameterError(
            f"speed_mps[{bad[0]}] = {speed[bad[0]]} is outside 0..{MAX_SPEED_MPS:.1f} m/s "
            "or not finite",
            f"speed_mps[{bad[0]}]",
        )
    if not (np.isfinite(dt_s) and 0 < dt_s <= 3600):
        raise InvalidParameterError(f"dt_s must be within (0, 3600] s, got {dt_s}", "dt_s")
    return speed


def simulate(
    speed_mps: ArrayLike,
    dt_s: float,
    start: dt.datetime,
    location: Location,
    van: VanParams,
    *,
    grade: ArrayLike = 0.0,
    payload_kg: ArrayLike | None = None,
    weather: Weather | None = None,
    door_openings: Sequence[DoorOpening] = (),
) -> SimulationResult:
    """Simulate every consumer of the van along one speed trace (paper Fig. 7, one leg).

    Parameters
    ----------
    speed_mps
        Speed samples [m/s] every ``dt_s``.
    dt_s
        Sampling interval [s].
    start
        Timezone-aware time of the first sample; sets the sun, the ambient temperature and the
        cabin load through the day.
    location
        Where the van drives (latitude for the sun and the climatology; longitude for solar
        time).
    van
        Vehicle, cargo box, battery and departure payload.
    grade
        Road grade [–], a number or one value per sample (eq. 5).
    payload_kg
        Payload [kg], a number or one value per sample; ``None`` takes ``van.payload_kg``.
    weather
        The day's extremes; ``None`` uses the climatology for the date and latitude.
    door_openings
        When the cargo door is open, in seconds after the start.

    Returns
    -------
    SimulationResult
    """
    speed = check_trace(speed_mps, dt_s)
    if start.tzinfo is None or start.utcoffset() is None:
        raise InvalidParameterError("start must carry a UTC offset or a time zone", "start")
    n = speed.size
    grade_step = _per_step(grade, n, "grade", -MAX_ABS_GRADE, MAX_ABS_GRADE)
    payload = van.payload_kg if payload_kg is None else payload_kg
    payload_step = _per_step(payload, n, "payload_kg", 0.0, 40_000.0)
    end_s = (n - 1) * dt_s
    for index, opening in enumerate(door_openings):
        if opening.start_s > end_s:
            raise InvalidParameterError(
                f"door opening starts at {opening.start_s} s, after the trace ends ({end_s} s)",
                f"door_openings[{index}].start_s",
            )

    time_s = np.arange(n) * dt_s
    mid_s = time_s[1:] - 0.5 * dt_s
    clock = local_clock(start, mid_s)
    day_weather, source = resolve_weather(weather, start.date(), location.lat)
    ambient = daily_temperature_c(day_weather, clock.hour)
    # Declination, equation of time and month change once a day: compute them per day.
    day_of_year = [d.timetuple().tm_yday for d in clock.dates]
    utc_offset_h = start.utcoffset().total_seconds() / 3600.0  # type: ignore[union-attr]
    solar_hour = solar_time_h(
        clock.hour, clock.per_moment(equation_of_time_min(day_of_year)), location.lon, utc_offset_h
    )
    sin_h = sin_altitude(location.lat, clock.per_moment(declination_deg(day_of_year)), solar_hour)
    month = clock.per_moment([d.month for d in clock.dates])
    box = refrigeration(
        van.cargo_box,
        ambient,
        absorbed_solar_heat_w(van.cargo_box, sin_h, month),
        door_open_fraction(door_openings, time_s[1:], dt_s),
        payload_step,
        dt_s,
    )
    mass = van.vehicle.mass_kg + payload_step
    power = {
        "traction": step_traction_power_w(van.vehicle, speed, dt_s, mass, grade_step),
        "auxiliaries": auxiliaries_power_w(van.vehicle, n - 1),
        "cabin": cabin_hvac_power_w(van.vehicle, ambient),
        "refrigeration": box.power_w,
    }
    energy = {
        name: float(p.sum() * dt_s / battery_model.JOULES_PER_KWH) for name, p in power.items()
    }
    energy["total"] = sum(energy.values())
    step_energy = sum(power.values(), np.zeros(n - 1)) * dt_s
    soc = battery_model.state_of_charge(van.battery, step_energy)
    return SimulationResult(
        time_s=time_s,
        speed_mps=speed,
        power_w=power,
        energy_kwh=energy,
        distance_m=trace_distance_m(speed, dt_s),
        duration_s=end_s,
        soc=soc,
        battery=battery_model.verdict(van.battery, soc, step_energy),
        box=box,
        ambient_c=ambient,
        weather=day_weather,
        weather_source=source,
    )
