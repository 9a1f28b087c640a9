"""Core results → response models: the few conversions shared by the routers."""

from __future__ import annotations

from app.schemas import BatteryOut, BoxOut, EnergyKwh, WeatherOut
from core.battery import BatteryVerdict
from core.params import Weather
from core.weather import WeatherSource


def energy(values: dict[str, float]) -> EnergyKwh:
    return EnergyKwh(**values)


def battery(verdict: BatteryVerdict, first_infeasible_leg: int | None) -> BatteryOut:
    return BatteryOut(
        feasible=verdict.feasible,
        min_soc=verdict.min_soc,
        final_soc=verdict.final_soc,
        margin_kwh=verdict.margin_kwh,
        required_capacity_kwh=verdict.required_capacity_kwh,
        first_infeasible_leg=first_infeasible_leg,
    )


def weather(used: Weather, source: WeatherSource) -> WeatherOut:
    return WeatherOut(t_min_c=used.t_min_c, t_max_c=used.t_max_c, source=source)


def box(max_temperature_c: float | None, minutes_above: float | None) -> BoxOut:
    return BoxOut(max_temperature_c=max_temperature_c, minutes_above_product_limit=minutes_above)
