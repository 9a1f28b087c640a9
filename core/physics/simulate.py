"""One speed trace in, per-consumer power, energy and state of charge out.

Everything is computed over the whole time grid at once with numpy; there is no Python loop
per time step (the dynamic cargo box steps every 10 s, :mod:`core.physics.cargo`). A trace of ``n``
samples has ``n − 1`` steps; per-step arrays hold the mean power over each step.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray, interval_rates, uniform_interp
from core.clock import SECONDS_PER_DAY, check_representable, local_clock
from core.exceptions import InvalidParameterError
from core.params import (
    BatteryParams,
    ChargingSpell,
    DoorOpening,
    Interval,
    Location,
    SetpointSpan,
    VanParams,
    Weather,
)
from core.physics import battery as battery_model
from core.physics.cabin import CAB_SETPOINT_C, auxiliaries_power_w, cab_power_w, cabin_hvac_power_w
from core.physics.cargo import BoxResult, precondition_energy_j, refrigeration
from core.physics.charging import WATTS_PER_KW, charge_curve
from core.physics.cold_chain import Run, box_with_goods
from core.physics.cycles import trace_distance_m
from core.physics.motor import power_limited
from core.physics.solar import (
    absorbed_solar_heat_w,
    declination_deg,
    direct_irradiance_w_m2,
    direct_normal_from_horizontal_w_m2,
    equation_of_time_min,
    sin_altitude,
    solar_time_h,
)
from core.physics.vehicle import step_traction_power_w
from core.physics.weather import (
    Conditions,
    DayWeather,
    Forecast,
    WeatherSource,
    conditions,
    headwind_mps,
)

#: The consumers on the battery, and what each one is.
CONSUMERS: dict[str, str] = {
    "traction": "drive train, net of regeneration",
    "auxiliaries": "lights, radio, controls",
    "cabin": "cab heating / air conditioning",
    "refrigeration": "refrigeration unit, box heater and standby",
}
#: Highest speed a trace may hold [m/s] (250 km/h): anything faster is a unit mistake.
MAX_SPEED_MPS = 250 / 3.6
#: Steepest grade accepted [–] (the steepest public streets are about 0.35).
MAX_ABS_GRADE = 0.5
#: Heaviest payload accepted [kg] (a 40 t articulated lorry's gross mass).
MAX_PAYLOAD_KG = 40_000.0
_EPOCH_DATE = dt.date(1970, 1, 1)


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
    battery_loss_kwh
        Extra battery energy of the temperature derating (:mod:`core.physics.battery`) [kWh].
    grid_kwh
        Energy drawn from the grid before departure to pre-condition cab and box [kWh].
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
    weather
        The first day's extremes.
    weather_days
        The extremes of every local day of the trace.
    weather_source
        Where the weather came from.
    warnings
        What the simulation had to change (a motor's cap the trace asked too much of).
    charges
        What each charging spell did, in the order given.
    asked_s
        For each sample, the moment of the trace asked for at the same place [s], when the
        motor's cap made the van drive it slower (:func:`core.physics.motor.power_limited`);
        None when it drove the trace as asked.
    plugged
        The share of each step plugged in at a charger [–] (the consumers on the grid),
        ``n − 1`` values.
    plugged_price_per_kwh
        That share times the charger's price [per kWh], ``n − 1`` values.
    """

    time_s: FloatArray
    speed_mps: FloatArray
    power_w: dict[str, FloatArray]
    energy_kwh: dict[str, float]
    battery_loss_kwh: float
    grid_kwh: float
    distance_m: float
    duration_s: float
    soc: FloatArray
    battery: battery_model.BatteryVerdict
    box: BoxResult
    ambient_c: FloatArray
    weather: Weather
    weather_days: list[DayWeather]
    weather_source: WeatherSource
    warnings: list[str]
    charges: list[ChargeOutcome] = field(default_factory=list)
    asked_s: FloatArray | None = None
    plugged: FloatArray = field(default_factory=lambda: np.zeros(0))
    plugged_price_per_kwh: FloatArray = field(default_factory=lambda: np.zeros(0))

    def sample_at(self, asked_sample: ArrayLike) -> Any:
        """The sample that the van drove at the place of a sample of the trace asked for."""
        if self.asked_s is None:
            return asked_sample
        moment_s = np.asarray(asked_sample, dtype=float) * (self.time_s[1] - self.time_s[0])
        return np.rint(np.interp(moment_s, self.asked_s, np.arange(self.time_s.size))).astype(int)


@dataclass(frozen=True)
class ChargeOutcome:
    """One spell at a charger: the state of charge before and after [–], the energy stored
    in the battery and drawn from the grid for it [J] (``stored / charging_efficiency``), and
    what the consumers took from the grid meanwhile [J]."""

    soc_before: float
    soc_after: float
    stored_j: float
    charge_grid_j: float
    consumers_grid_j: float


def _per_step(
    value: ArrayLike, n_samples: int, name: str, low: float, high: float
) -> FloatArray | float:
    """A per-sample input as per-step values (mean of each step's two samples); a scalar stays
    a scalar."""
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        scalar = float(array)
        if not (math.isfinite(scalar) and low <= scalar <= high):
            raise InvalidParameterError(
                f"{name} = {scalar} is outside {low}..{high} or not finite", f"{name}[0]"
            )
        return scalar
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


def check_trace(speed_mps: ArrayLike, dt_s: float, min_samples: int = 2) -> FloatArray:
    """Validate a speed trace: 1-D, at least ``min_samples`` samples, finite, 0…250 km/h;
    ``dt_s`` > 0. (A single sample is a moment: a round that never leaves the depot.)"""
    speed = np.asarray(speed_mps, dtype=float)
    if speed.ndim != 1 or speed.size < min_samples:
        raise InvalidParameterError(
            f"speed_mps must be a list of at least {min_samples} samples", "speed_mps"
        )
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


def sun(utc_s: FloatArray, location: Location) -> tuple[FloatArray, FloatArray]:
    """Sine of the sun's altitude [–] and the month (1–12) at each UTC instant (eqs 13–14).

    Apparent solar time comes straight from UTC: ``t_solar = t_UTC + λ/15° + E/60``, so a
    daylight-saving change of the local clock cannot shift the sun.
    """
    epoch_day = np.floor(utc_s / SECONDS_PER_DAY).astype(int)
    first = int(epoch_day[0]) if epoch_day.size else 0
    n_days = int(epoch_day[-1]) - first + 1 if epoch_day.size else 0
    dates = [_EPOCH_DATE + dt.timedelta(days=first + d) for d in range(n_days)]
    day = epoch_day - first
    # Declination, equation of time and month change once a day: compute them per day.
    day_of_year = [d.timetuple().tm_yday for d in dates]
    utc_hour = (utc_s - epoch_day * SECONDS_PER_DAY) / 3600.0
    solar_hour = solar_time_h(utc_hour, equation_of_time_min(day_of_year)[day], location.lon, 0.0)
    month = np.array([d.month for d in dates], dtype=int)[day]
    return sin_altitude(location.lat, declination_deg(day_of_year)[day], solar_hour), month


@dataclass(frozen=True)
class Along:
    """What the van does along its speed trace besides driving it, and its box's start.

    Parameters
    ----------
    grade
        Road grade [–], a number or one value per sample (eq. 5).
    payload_kg
        Payload [kg], a number or one value per sample; ``None`` takes ``van.payload_kg``.
    door_openings
        When the cargo door is open, in seconds after the start.
    parked
        When the van stands at a stop (the cab HVAC's duty while parked), seconds after start.
    heading_deg
        Direction of travel at each sample [°, 0 north, 90 east] for the wind; NaN or None
        where unknown.
    charging
        When the van is plugged in, seconds after start, and the charger's power: the battery
        charges along its curve (:mod:`core.physics.charging`) and every consumer runs from
        the grid meanwhile.
    box_start_c
        The box's temperature at the start [°C] of a van already under way (its day planned
        again): its cab is at temperature and nothing is pre-conditioned. None: the start is
        the depot's departure (``precondition_at_depot`` says how the van leaves).
    product_start_c
        With a product in the box: the goods' temperature at the start [°C]; None: as loaded
        (``cargo_box.load_temperature_c``).
    air_setpoints
        With a product in the box: a schedule for the unit to follow instead of its strategy
        (a plan's, replayed against the day as it went), seconds after the start, in order
        and not overlapping; outside its spans the unit holds ``cargo_box.setpoint_c``.
    """

    grade: ArrayLike = 0.0
    payload_kg: ArrayLike | None = None
    door_openings: Sequence[DoorOpening] = ()
    parked: Sequence[Interval] = ()
    heading_deg: ArrayLike | None = None
    charging: Sequence[ChargingSpell] = ()
    box_start_c: float | None = None
    product_start_c: float | None = None
    air_setpoints: Sequence[SetpointSpan] = ()


def simulate(
    speed_mps: ArrayLike,
    dt_s: float,
    start: dt.datetime,
    location: Location,
    van: VanParams,
    weather: Forecast | None = None,
    along: Along = Along(),
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
        cabin load through the day. Time advances in true seconds (UTC), so a trace across a
        daylight-saving change keeps its sun and temperature.
    location
        Where the van drives (latitude for the sun and the climatology; longitude for solar
        time).
    van
        Vehicle, cargo box, battery and departure payload.
    weather
        An hourly forecast, the day's extremes, or ``None`` for the climatology of each day.
    along
        The grade, payload, doors, stands, heading and charges along the trace, and the box's
        start.

    Returns
    -------
    SimulationResult
    """
    trace = _driven(van, speed_mps, dt_s, along)
    n = trace.speed.size
    check_representable(start, (n - 1) * dt_s)
    outside = _environment(start, location, van, weather, n - 1, dt_s)
    power, box, cab_gap_j = _consumers(
        van, trace, dt_s, outside, (along.box_start_c, along.product_start_c)
    )
    departs_depot = van.precondition_at_depot and along.box_start_c is None
    grid_j = cab_gap_j + precondition_energy_j(van.cargo_box, outside.start_c) + box.precool_grid_j
    return _result(
        trace,
        dt_s,
        outside,
        (power, box),
        _battery(van.battery, power, dt_s, (outside.ambient_c, outside.start_c), trace.charging),
        grid_j / battery_model.JOULES_PER_KWH if departs_depot else 0.0,
    )


def _result(
    trace: _Trace,
    dt_s: float,
    outside: _Environment,
    consumers: tuple[dict[str, FloatArray], BoxResult],
    battery: tuple[FloatArray, battery_model.BatteryVerdict, float, list[ChargeOutcome]],
    grid_kwh: float,
) -> SimulationResult:
    """The simulation's answer from its parts: the trace, the outside, each consumer's power
    [W] and the box, the battery (state of charge, verdict, loss [J], charges) and the
    pre-conditioning from the grid [kWh]."""
    (power, box), (soc, verdict, loss_j, charges) = consumers, battery
    n = trace.speed.size
    return SimulationResult(
        time_s=np.arange(n) * dt_s,
        speed_mps=trace.speed,
        power_w=power,
        energy_kwh=_energy_kwh(power, dt_s),
        battery_loss_kwh=loss_j / battery_model.JOULES_PER_KWH,
        grid_kwh=grid_kwh,
        distance_m=trace_distance_m(trace.speed, dt_s),
        duration_s=(n - 1) * dt_s,
        soc=soc,
        battery=verdict,
        box=box,
        ambient_c=outside.ambient_c,
        weather=outside.first_day,
        weather_days=outside.days,
        weather_source=outside.source,
        warnings=[*trace.warnings, *box.notes],
        charges=charges,
        asked_s=trace.asked_s,
        plugged=plugged_share(trace.charging, n - 1, dt_s),
        plugged_price_per_kwh=plugged_share(trace.charging, n - 1, dt_s, priced=True),
    )


@dataclass(frozen=True)
class _Trace:
    """The trace the van drives and what each of its steps carries."""

    speed: FloatArray
    grade_step: FloatArray | float
    payload_step: FloatArray | float
    heading_deg: ArrayLike | None
    door_openings: Sequence[DoorOpening]
    parked: Sequence[Interval]
    warnings: list[str]
    charging: Sequence[ChargingSpell] = ()
    asked_s: FloatArray | None = None
    air_setpoints: Sequence[SetpointSpan] = ()


def _driven(van: VanParams, speed_mps: ArrayLike, dt_s: float, along: Along) -> _Trace:
    """The inputs checked, and the trace the van drives: the one asked for, or — when it asks
    for more than the motor's cap — the slower one the van can drive
    (:func:`core.physics.motor.power_limited`), with every per-sample input and every interval
    moved to the moment the van reaches its place."""
    speed = check_trace(speed_mps, dt_s, min_samples=1)
    n = speed.size
    payload = van.payload_kg if along.payload_kg is None else along.payload_kg
    grade_step = _per_step(along.grade, n, "grade", -MAX_ABS_GRADE, MAX_ABS_GRADE)
    payload_step = _per_step(payload, n, "payload_kg", 0.0, MAX_PAYLOAD_KG)
    door_openings, parked, charging = along.door_openings, along.parked, along.charging
    air_setpoints, heading_deg = along.air_setpoints, along.heading_deg
    _check_within(
        (n - 1) * dt_s,
        door_openings=door_openings,
        parked=parked,
        charging=charging,
        air_setpoints=air_setpoints,
    )
    _check_in_order(air_setpoints)
    retimed = power_limited(
        van.vehicle, speed, dt_s, van.vehicle.mass_kg + payload_step, grade_step
    )
    if retimed is None:
        return _Trace(
            speed,
            grade_step,
            payload_step,
            heading_deg,
            door_openings,
            parked,
            [],
            charging,
            air_setpoints=air_setpoints,
        )
    m = retimed.speed_mps.size
    at = retimed.original_s / dt_s  # where each new sample lies in the original's samples

    def linear(values: ArrayLike) -> ArrayLike:
        array = np.asarray(values, dtype=float)
        return array if array.ndim == 0 else np.interp(at, np.arange(n), array)

    def stepwise(values: ArrayLike) -> ArrayLike:
        array = np.asarray(values, dtype=float)
        return array if array.ndim == 0 else array[np.minimum(np.floor(at).astype(int), n - 1)]

    def moved(interval: Interval) -> Any:
        return interval.model_copy(update={"start_s": float(retimed.moment_s(interval.start_s))})

    cap_kw = (van.vehicle.max_motor_power_w or 0.0) / 1000
    return _Trace(
        retimed.speed_mps,
        _per_step(linear(along.grade), m, "grade", -MAX_ABS_GRADE, MAX_ABS_GRADE),
        _per_step(stepwise(payload), m, "payload_kg", 0.0, MAX_PAYLOAD_KG),
        None if heading_deg is None else stepwise(heading_deg),
        [moved(d) for d in door_openings],
        [moved(p) for p in parked],
        [
            f"the motor's {cap_kw:g} kW cap cannot follow the trace: the van drives it "
            f"{retimed.lost_s:,.0f} s slower (the same distance, the energy delivered later)"
        ],
        [moved(c) for c in charging],
        retimed.original_s,
        [moved(a) for a in air_setpoints],
    )


def _consumers(
    van: VanParams,
    trace: _Trace,
    dt_s: float,
    outside: _Environment,
    start_c: tuple[float | None, float | None] = (None, None),
) -> tuple[dict[str, FloatArray], BoxResult, float]:
    """Each consumer's power over each step [W] (:data:`CONSUMERS`), the box, and the energy a
    cab at the outside temperature needs to reach 20 °C [J] (none for a van under way: the
    box's temperature given in ``start_c``, beside the goods')."""
    box_start_c, product_start_c = start_c
    speed = trace.speed
    n_steps = speed.size - 1
    initial_c = (
        box_start_c
        if box_start_c is not None
        else (None if van.precondition_at_depot else outside.start_c)
    )
    door = door_open_fraction(trace.door_openings, np.arange(1, n_steps + 1) * dt_s, dt_s)
    payload = np.broadcast_to(trace.payload_step, outside.ambient_c.shape).astype(float)
    box_params = van.cargo_box
    if box_params.product is None:
        box = refrigeration(
            box_params, outside.ambient_c, outside.solar_heat_w, door, payload, dt_s, initial_c
        )
    else:
        box = box_with_goods(
            box_params,
            (outside.ambient_c, outside.solar_heat_w, door),
            payload,
            dt_s,
            (
                box_params.setpoint_c if initial_c is None else initial_c,
                box_params.load_c if product_start_c is None else product_start_c,
            ),
            Run(
                van.refrigeration,
                plugged_share(trace.charging, n_steps, dt_s),
                initial_c is None,
                plugged_share(trace.charging, n_steps, dt_s, priced=True),
                van.battery.charging_efficiency,
                schedule_c(trace.air_setpoints, n_steps, dt_s) if trace.air_setpoints else None,
            ),
        )
    cab_gap_j = 0.0 if box_start_c is not None else _cab_gap_j(van, outside.start_c)
    power = {
        "traction": step_traction_power_w(
            van.vehicle,
            speed,
            dt_s,
            van.vehicle.mass_kg + trace.payload_step,
            trace.grade_step,
            _headwind_mps(outside, trace.heading_deg, speed.size),
        ),
        "auxiliaries": auxiliaries_power_w(van.vehicle, n_steps),
        "cabin": _cabin_power_w(van, outside, dt_s, trace.parked, cab_gap_j),
        "refrigeration": box.power_w,
    }
    return power, box, cab_gap_j


def with_battery(result: SimulationResult, battery: BatteryParams) -> SimulationResult:
    """The day ``result`` simulated, with ``battery`` for the van's: its state of charge,
    verdict and loss in the cold or heat. Exact for a day without charging — no consumer
    depends on the battery (its capacity, reserve or departure charge), only the energy it
    gives them does — so candidates that differ in their battery alone share one simulation."""
    if result.charges:
        raise ValueError("a day with charges depends on the battery: simulate it again")
    dt_s = float(result.time_s[1] - result.time_s[0]) if result.time_s.size > 1 else 1.0
    soc, verdict, loss_j, _ = _battery(
        battery, result.power_w, dt_s, (result.ambient_c, float(result.ambient_c[0])), ()
    )
    return replace(
        result, soc=soc, battery=verdict, battery_loss_kwh=loss_j / battery_model.JOULES_PER_KWH
    )


def _battery(
    battery: BatteryParams,
    power_w: dict[str, FloatArray],
    dt_s: float,
    ambient: tuple[FloatArray, float],
    charging: Sequence[ChargingSpell],
) -> tuple[FloatArray, battery_model.BatteryVerdict, float, list[ChargeOutcome]]:
    """The state of charge at every sample, the verdict, the battery's own loss in the cold
    or heat [J], and what each charging spell did; ``ambient``: the outside temperature of
    each step and at the start [°C]. Plugged in, the consumers run from the grid and the
    battery charges along its curve from the state of charge it arrived with."""
    ambient_c, start_c = ambient
    consumer_j = sum(power_w.values(), np.zeros(ambient_c.size)) * dt_s
    drawn_j = battery_model.battery_energy_j(battery, consumer_j, ambient_c)
    usable_share = battery_model.capacity_factor(battery, start_c)
    charges = []
    for spell in sorted(charging, key=lambda c: c.start_s):
        first = min(round(spell.start_s / dt_s), drawn_j.size)
        last = min(round((spell.start_s + spell.duration_s) / dt_s), drawn_j.size)
        grid_loads_j = float(consumer_j[first:last].sum())
        drawn_j[first:last] = 0.0
        before = float(battery_model.discharge(battery, drawn_j[:first], usable_share)[0][-1])
        curve = charge_curve(battery, spell.power_kw * WATTS_PER_KW, usable_share)
        # A battery run below empty (infeasible already) charges from empty; its shortfall stays.
        reached = curve.soc_after(max(before, 0.0), np.arange(0, last - first + 1) * dt_s)
        drawn_j[first:last] = -np.diff(reached) * curve.capacity_j
        stored_j = float((reached[-1] - reached[0]) * curve.capacity_j)
        charges.append(
            ChargeOutcome(
                soc_before=before,
                soc_after=before + float(reached[-1] - reached[0]),
                stored_j=stored_j,
                charge_grid_j=stored_j / battery.charging_efficiency,
                consumers_grid_j=grid_loads_j,
            )
        )
    soc, verdict = battery_model.discharge(battery, drawn_j, usable_share)
    charged_j = sum(c.stored_j for c in charges)
    # Never negative (the derating takes more and stores less); clipped of float noise.
    loss_j = max(
        float((drawn_j - consumer_j).sum()) + charged_j + sum(c.consumers_grid_j for c in charges),
        0.0,
    )
    return soc, verdict, loss_j, charges


def _cabin_power_w(
    van: VanParams,
    outside: _Environment,
    dt_s: float,
    parked: Sequence[Interval],
    cab_gap_j: float,
) -> FloatArray:
    """The cab HVAC's power of each step [W]: a cab not pre-conditioned starts ``cab_gap_j``
    away from 20 °C."""
    return cab_power_w(
        van.vehicle,
        outside.ambient_c,
        dt_s,
        [(p.start_s, p.duration_s) for p in parked],
        0.0 if van.precondition_at_depot else cab_gap_j,
        outside.cab_hvac_w,
    )


def _headwind_mps(
    outside: _Environment, heading_deg: ArrayLike | None, n: int
) -> FloatArray | float:
    """Wind against the direction of travel in each step [m/s]; 0 in calm air or without
    headings."""
    if heading_deg is None or outside.calm:
        return 0.0
    return headwind_mps(
        outside.wind_from_east_mps, outside.wind_from_north_mps, _step_heading(heading_deg, n)
    )


def _check_in_order(spans: Sequence[SetpointSpan]) -> None:
    """A schedule's spans in time order, none overlapping the one before."""
    for index, (before, span) in enumerate(itertools.pairwise(spans), start=1):
        if span.start_s < before.start_s + before.duration_s:
            raise InvalidParameterError(
                f"air_setpoints[{index}] starts at {span.start_s:g} s, before the span before "
                f"it ends ({before.start_s + before.duration_s:g} s): spans in time order, "
                "none overlapping",
                f"air_setpoints[{index}].start_s",
            )


def schedule_c(spans: Sequence[SetpointSpan], n_steps: int, dt_s: float) -> FloatArray:
    """The air set-point of each step [°C] from a schedule's spans (in order): the span's at
    the step's middle, NaN outside every span."""
    middle_s = (np.arange(n_steps) + 0.5) * dt_s
    starts = np.array([span.start_s for span in spans])
    ends = starts + np.array([span.duration_s for span in spans])
    values = np.array([span.air_setpoint_c for span in spans])
    at = np.searchsorted(starts, middle_s, side="right") - 1
    inside = (at >= 0) & (middle_s < ends[np.maximum(at, 0)])
    return np.where(inside, values[np.maximum(at, 0)], np.nan)


def _check_within(end_s: float, **intervals: Sequence[Interval]) -> None:
    """Every interval starts within the trace (``end_s`` its last moment [s])."""
    for name, windows in intervals.items():
        for index, window in enumerate(windows):
            if window.start_s > end_s:
                raise InvalidParameterError(
                    f"{name}[{index}] starts at {window.start_s} s, after the trace ends "
                    f"({end_s} s)",
                    f"{name}[{index}].start_s",
                )


def _cab_gap_j(van: VanParams, outside_c: float) -> float:
    """Electric energy to bring a cab at the outside temperature to 20 °C [J]."""
    vehicle = van.vehicle
    heated = float(cabin_hvac_power_w(vehicle, outside_c) > 0)
    return vehicle.cab_recovery_energy_j_k * abs(CAB_SETPOINT_C - outside_c) * heated


def _energy_kwh(power_w: dict[str, FloatArray], dt_s: float) -> dict[str, float]:
    """Each consumer's energy and the total [kWh]; a consumer without a finite energy is an
    error naming the parameters behind it (a last guard for parameters at the edges of their
    ranges, combined)."""
    energy = {
        name: float(p.sum() * dt_s / battery_model.JOULES_PER_KWH) for name, p in power_w.items()
    }
    energy["total"] = sum(energy.values())
    broken = [name for name, value in energy.items() if not np.isfinite(value)]
    if broken:
        box = broken[0] == "refrigeration"
        raise InvalidParameterError(
            f"the van's parameters give no finite {broken[0]} energy; check the "
            f"{'cargo box' if box else 'vehicle'} parameters",
            "cargo_box" if box else "vehicle",
        )
    return energy


def plugged_share(
    charging: Sequence[ChargingSpell], n_steps: int, dt_s: float, priced: bool = False
) -> FloatArray:
    """Share of each step [–] plugged in at a charger; ``priced``: times its price [per
    kWh]."""
    return interval_rates(
        [c.start_s for c in charging],
        [c.start_s + c.duration_s for c in charging],
        n_steps,
        dt_s,
        [c.price_per_kwh for c in charging] if priced else None,
    )


def door_open_fraction(
    openings: Sequence[DoorOpening], step_end_s: FloatArray, dt_s: float
) -> FloatArray:
    """Share of each step [–] during which the door is open (overlaps count once)."""
    return interval_rates(
        [o.start_s for o in openings],
        [o.start_s + o.duration_s for o in openings],
        step_end_s.size,
        dt_s,
    )


#: Spacing of the points at which the slowly changing outside conditions (temperature, sun,
#: wind) are computed before they are interpolated to every step [s]: the daily sine changes by
#: under 0.003 K between a minute's linear interpolation and the curve.
ENVIRONMENT_STEP_S = 60.0


@dataclass(frozen=True)
class _Environment:
    """Outside conditions of every step, and the cab's Table 2 power that follows from them."""

    ambient_c: FloatArray
    start_c: float
    solar_heat_w: FloatArray
    cab_hvac_w: FloatArray
    wind_from_east_mps: FloatArray
    wind_from_north_mps: FloatArray
    calm: bool
    days: list[DayWeather]
    source: WeatherSource

    @property
    def first_day(self) -> Weather:
        """The first day's extremes, rounded to a hundredth of a kelvin [°C]."""
        day = self.days[0]
        return Weather(t_min_c=round(day.t_min_c, 2), t_max_c=round(day.t_max_c, 2))


def _environment(
    start: dt.datetime,
    location: Location,
    van: VanParams,
    weather: Forecast | None,
    n_steps: int,
    dt_s: float,
) -> _Environment:
    """Temperature, absorbed sun, cab power and wind at the middle of each of ``n_steps``
    steps, computed every :data:`ENVIRONMENT_STEP_S` (on the last moment at most) and
    interpolated linearly."""
    per_interval = max(round(ENVIRONMENT_STEP_S / dt_s), 1)
    first_s, last_s = 0.5 * dt_s, max(n_steps - 0.5, 0.5) * dt_s
    coarse_s = np.minimum(
        first_s
        + per_interval * dt_s * np.arange(math.ceil(max(n_steps - 1, 0) / per_interval) + 1),
        last_s,
    )
    clock = local_clock(start, coarse_s)
    outside = conditions(weather, clock, location.lat)
    sin_h, month = sun(clock.utc_s, location)

    def fine(values: FloatArray) -> FloatArray:
        return uniform_interp(values, per_interval, n_steps)

    calm = not (np.any(outside.wind_from_east_mps) or np.any(outside.wind_from_north_mps))
    still = np.zeros(0)
    return _Environment(
        ambient_c=fine(outside.ambient_c),
        start_c=float(outside.ambient_c[0]),
        solar_heat_w=fine(_solar_heat_w(van, outside, sin_h, month)),
        cab_hvac_w=fine(cabin_hvac_power_w(van.vehicle, outside.ambient_c)),
        wind_from_east_mps=still if calm else fine(outside.wind_from_east_mps),
        wind_from_north_mps=still if calm else fine(outside.wind_from_north_mps),
        calm=calm,
        days=outside.days,
        source=outside.source,
    )


def _solar_heat_w(
    van: VanParams, outside: Conditions, sin_h: FloatArray, month: FloatArray
) -> FloatArray:
    """Absorbed sun on the box [W]: the forecast's sun if there is one, else the clear sky."""
    if outside.direct_horizontal_w_m2 is None or outside.diffuse_horizontal_w_m2 is None:
        return absorbed_solar_heat_w(van.cargo_box, sin_h, direct_irradiance_w_m2(sin_h, month))
    direct = direct_normal_from_horizontal_w_m2(outside.direct_horizontal_w_m2, sin_h)
    return absorbed_solar_heat_w(van.cargo_box, sin_h, direct, outside.diffuse_horizontal_w_m2)


def _step_heading(heading_deg: ArrayLike, n_samples: int) -> FloatArray:
    """Heading of each step [°]: the value at the step's end sample (headings wrap at 360°, so
    they are not averaged)."""
    heading = np.asarray(heading_deg, dtype=float)
    if heading.ndim == 0:
        return np.full(n_samples - 1, float(heading))
    if heading.shape != (n_samples,):
        raise InvalidParameterError(
            f"heading_deg must hold one value per speed sample ({n_samples})", "heading_deg"
        )
    return heading[1:]
