"""Core results → the parts of an answer that several operations share."""

from __future__ import annotations

from app.schemas.base import (
    BatteryOut,
    BoxOut,
    DayWeatherOut,
    EnergyKwh,
    RunsEmptyOut,
    WeatherOut,
)
from core.params import Weather
from core.physics.battery import BatteryVerdict
from core.physics.weather import DayWeather, WeatherSource
from core.planning.model import PlanResult

#: Credit owed wherever OpenStreetMap data is shown (ODbL 1.0).
OSM_ATTRIBUTION = "© OpenStreetMap contributors, ODbL 1.0 (routes and distances by OSRM)"


def energy(values: dict[str, float]) -> EnergyKwh:
    return EnergyKwh(**values)


def battery(
    verdict: BatteryVerdict,
    first_infeasible_leg: int | None,
    temperature_loss_kwh: float,
    runs_empty: RunsEmptyOut | None = None,
) -> BatteryOut:
    return BatteryOut(
        feasible=verdict.feasible,
        min_soc=verdict.min_soc,
        reserve_soc=verdict.reserve_soc,
        final_soc=verdict.final_soc,
        margin_kwh=verdict.margin_kwh,
        required_capacity_kwh=verdict.required_capacity_kwh,
        usable_capacity_kwh=verdict.usable_capacity_kwh,
        temperature_loss_kwh=temperature_loss_kwh,
        recharge_kwh=verdict.recharge_kwh,
        first_infeasible_leg=first_infeasible_leg,
        runs_empty=runs_empty,
    )


def empty_at(result: PlanResult) -> RunsEmptyOut | None:
    """Where the day's charge first falls below 0 — on a leg or at a visit, its moment by
    the charge's fall across it — and the energy the day lacks; None while it never does."""
    verdict = result.battery
    if verdict.min_soc >= 0:
        return None
    spans = [
        (leg.depart, leg.arrive, leg.soc_start, leg.soc_end, f"between '{leg.from_id}' and "
         f"'{leg.to_id}'")
        for leg in result.legs
    ] + [
        (visit.arrive, visit.depart, visit.soc_arrival, visit.soc_departure, f"at '{visit.id}'")
        for visit in result.visits
    ]  # fmt: skip
    for begin, end, soc_begin, soc_end, where in sorted(spans, key=lambda span: span[0]):
        if soc_end < 0:
            share = 0.0 if soc_begin <= 0 else soc_begin / (soc_begin - soc_end)
            return RunsEmptyOut(
                at=begin + (end - begin) * share,
                where=where,
                missing_kwh=-verdict.min_soc * verdict.usable_capacity_kwh,
            )
    return None  # below 0 between the samples the answer shows: no place to name


def weather(used: Weather, source: WeatherSource, days: list[DayWeather]) -> WeatherOut:
    return WeatherOut(
        t_min_c=used.t_min_c,
        t_max_c=used.t_max_c,
        source=source,
        days=[DayWeatherOut(**dict(d)) for d in days],
    )


def box(
    max_temperature_c: float | None, minutes_above: float | None, product_limit_c: float
) -> BoxOut:
    return BoxOut(
        max_temperature_c=max_temperature_c,
        minutes_above_product_limit=minutes_above,
        product_limit_c=product_limit_c,
    )


def attribution(distance_source: str) -> str | None:
    """The credit for the map data an answer's legs were routed on, if any."""
    return OSM_ATTRIBUTION if distance_source == "osrm" else None
