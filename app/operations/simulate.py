"""``POST /v1/simulate``: one speed trace, sent or generated, and its energy."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from app import connectors
from app.operations.answers import battery, box, energy, weather
from app.operations.vans import van_of
from app.schemas.base import ColdChainOut, ConsumptionWhPerKm, PowerSeries
from app.schemas.simulate import Series, SimulateRequest, SimulateResponse
from app.settings import Settings
from core.arrays import FloatArray
from core.exceptions import InvalidParameterError, LimitExceededError
from core.params import STREET_TYPES, CargoBoxParams, VanParams
from core.physics.cargo import BoxResult
from core.physics.cold_chain import box_check
from core.physics.cycles import generate_leg
from core.physics.simulate import Along, check_trace, simulate
from core.physics.weather import forecast_for
from core.planning.model import ColdChainResult

#: Shortest distance for which energy per km is reported [m].
MIN_DISTANCE_FOR_PER_KM_M = 1.0


def simulate_trace(request: SimulateRequest, settings: Settings) -> SimulateResponse:
    """Energy of one speed trace, sent or generated (``POST /v1/simulate``)."""
    van = van_of(request, settings).priced(None)
    if request.cycle is not None:
        cycle = request.cycle
        street = STREET_TYPES[cycle.street_type]
        # Check the size before generating: a trace at least as long as cruising at v̄.
        if cycle.distance_m / street.mean_speed_mps / request.dt_s > settings.max_trace_samples:
            raise LimitExceededError(
                f"a {cycle.distance_m:g} m {cycle.street_type} trace at dt_s {request.dt_s:g} "
                f"has more than {settings.max_trace_samples} samples",
                "cycle.distance_m",
            )
        speed = generate_leg(
            cycle.distance_m,
            street,
            cycle.driver_aggressiveness,
            van.vehicle.max_acceleration_mps2,
            cycle.traffic_density,
            request.dt_s,
        )
    else:
        speed = np.asarray(request.speed_mps, dtype=float)
    if speed.size > settings.max_trace_samples:
        raise LimitExceededError(
            f"the trace has {speed.size} samples; this server simulates at most "
            f"{settings.max_trace_samples}",
            "speed_mps" if request.cycle is None else "cycle.distance_m",
        )
    check_trace(speed, request.dt_s)  # at least 2 samples; before asking for the weather
    _check_replay(request, van)
    van.cargo_box.check_day((speed.size - 1) * request.dt_s)
    forecast, warnings = forecast_for(
        request.weather,
        connectors.weather_service(settings),
        request.location.lat,
        request.location.lon,
        request.start,
        (speed.size - 1) * request.dt_s,
    )
    result = simulate(
        speed,
        request.dt_s,
        request.start,
        request.location,
        van,
        weather=forecast,
        along=Along(
            grade=request.grade,
            door_openings=request.door_openings,
            parked=request.parked,
            air_setpoints=request.air_setpoints,
        ),
    )
    km = result.distance_m / 1000
    # Per-km figures of a trace that (nearly) stands still mean nothing: null below a metre.
    moved = result.distance_m >= MIN_DISTANCE_FOR_PER_KM_M
    per_km = {k: (v * 1000 / km if moved else None) for k, v in result.energy_kwh.items()}
    series = None
    if request.include_series:
        series = Series(
            time_s=result.time_s.tolist(),
            speed_mps=result.speed_mps.tolist(),
            power_w=PowerSeries(**{k: [0.0, *p.tolist()] for k, p in result.power_w.items()}),
            soc=result.soc.tolist(),
            air_temperature_c=_at_samples(result.box.temperature_c),
            air_setpoint_c=_at_samples(
                np.full(result.box.temperature_c.shape, van.cargo_box.setpoint_c)
                if result.box.setpoint_c is None
                else result.box.setpoint_c
            ),
            product_temperature_c=(
                None if result.box.product_c is None else _at_samples(result.box.product_c)
            ),
        )
    dynamic = van.cargo_box.mode == "dynamic"
    return SimulateResponse(
        distance_m=result.distance_m,
        duration_s=result.duration_s,
        energy_kwh=energy(result.energy_kwh),
        consumption_wh_per_km=ConsumptionWhPerKm(**per_km),
        battery=battery(result.battery, None, result.battery_loss_kwh),
        weather=weather(result.weather, result.weather_source, result.weather_days),
        box=box(
            result.box.max_temperature_c if dynamic else None,
            result.box.minutes_above_limit if dynamic else None,
            van.cargo_box.product_limit_c,
        ),
        cold_chain=_cold_chain(van.cargo_box, result.box, request.dt_s),
        series=series,
        grid_kwh=result.grid_kwh,
        warnings=[*warnings, *result.warnings],
    )


def _check_replay(request: SimulateRequest, van: VanParams) -> None:
    """A schedule to replay needs goods to hold and no strategy of its own."""
    if not request.air_setpoints:
        return
    if van.cargo_box.product is None:
        raise InvalidParameterError(
            "air_setpoints replays a schedule on the goods: it needs cargo_box.product",
            "air_setpoints",
        )
    if van.refrigeration.strategy != "thermostat":
        raise InvalidParameterError(
            "air_setpoints is a schedule to follow, refrigeration.strategy 'optimal' one to "
            "plan: send one of them",
            "air_setpoints",
        )


def _at_samples(per_step: FloatArray) -> list[Any]:
    """A box trace at each step's end as one value per sample (the first sample's: the first
    step's end); NaN (no goods aboard) as null."""
    values = [float(per_step[0]), *per_step.tolist()] if per_step.size else []
    return [v if math.isfinite(v) else None for v in values]


def _cold_chain(box: CargoBoxParams, simulated: BoxResult, dt_s: float) -> ColdChainOut | None:
    band = box.band
    if band is None or simulated.product_c is None:
        return None
    return ColdChainOut(**dict(ColdChainResult.of(band, box_check(band, simulated, dt_s))))
