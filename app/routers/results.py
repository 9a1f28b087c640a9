"""Core results → response models: the conversions shared by the routers and the jobs."""

from __future__ import annotations

from typing import Any

from app.schemas import (
    BatteryOut,
    BoxOut,
    DayWeatherOut,
    EnergyKwh,
    EnergyShare,
    Feature,
    FleetPlanResponse,
    FleetRouteOut,
    FleetSolverOut,
    FleetTotals,
    LegOut,
    LineString,
    PlanFeatureCollection,
    PlanResponse,
    Point,
    SolverOut,
    StopOut,
    Totals,
    UnassignedOut,
    WeatherOut,
)
from core.battery import BatteryVerdict
from core.fleet import FleetResult
from core.params import Weather
from core.round import PlanResult
from core.weather import DayWeather, WeatherSource

#: Credit owed wherever OpenStreetMap data is shown (ODbL 1.0).
OSM_ATTRIBUTION = "© OpenStreetMap contributors, ODbL 1.0 (routes and distances by OSRM)"


def energy(values: dict[str, float]) -> EnergyKwh:
    return EnergyKwh(**values)


def battery(
    verdict: BatteryVerdict, first_infeasible_leg: int | None, temperature_loss_kwh: float
) -> BatteryOut:
    return BatteryOut(
        feasible=verdict.feasible,
        min_soc=verdict.min_soc,
        final_soc=verdict.final_soc,
        margin_kwh=verdict.margin_kwh,
        required_capacity_kwh=verdict.required_capacity_kwh,
        usable_capacity_kwh=verdict.usable_capacity_kwh,
        temperature_loss_kwh=temperature_loss_kwh,
        recharge_kwh=verdict.recharge_kwh,
        first_infeasible_leg=first_infeasible_leg,
    )


def weather(used: Weather, source: WeatherSource, days: list[DayWeather]) -> WeatherOut:
    return WeatherOut(
        t_min_c=used.t_min_c,
        t_max_c=used.t_max_c,
        source=source,
        days=[DayWeatherOut(date=d.date, t_min_c=d.t_min_c, t_max_c=d.t_max_c) for d in days],
    )


def box(max_temperature_c: float | None, minutes_above: float | None) -> BoxOut:
    return BoxOut(max_temperature_c=max_temperature_c, minutes_above_product_limit=minutes_above)


def plan_response(result: PlanResult, include_geometry: bool = False) -> PlanResponse:
    """The answer of ``POST /v1/plans`` for a planned round."""
    legs = []
    for leg in result.legs:
        fields = vars(leg) | {"energy_kwh": energy(leg.energy_kwh)}
        fields["geometry"] = LineString(coordinates=leg.geometry) if include_geometry else None
        legs.append(LegOut(**fields))
    stops = [
        StopOut(
            **{k: v for k, v in vars(stop).items() if k not in ("lat", "lon")}
            | {"energy_kwh": energy(stop.energy_kwh)}
        )
        for stop in result.stops
    ]
    return PlanResponse(
        tour=result.tour,
        legs=legs,
        stops=stops,
        totals=Totals(
            distance_m=result.distance_m,
            duration_s=result.duration_s,
            energy_kwh=energy(result.energy_kwh),
            energy_share=EnergyShare(**result.energy_share),
            grid_kwh=result.grid_kwh,
        ),
        battery=battery(result.battery, result.first_infeasible_leg, result.battery_loss_kwh),
        weather=weather(result.weather, result.weather_source, result.weather_days),
        timezone=result.timezone,
        box=box(result.max_box_temperature_c, result.minutes_above_product_limit),
        solver=SolverOut(
            status=result.solver_status,
            objective=result.objective,
            objective_value=result.objective_value,
            runtime_s=result.solver_runtime_s,
        ),
        distance_source=result.distance_source,
        warnings=result.warnings,
        attribution=OSM_ATTRIBUTION if result.distance_source == "osrm" else None,
    )


def fleet_response(result: FleetResult, include_geometry: bool = False) -> FleetPlanResponse:
    """The answer of ``POST /v1/fleet-plans``."""
    return FleetPlanResponse(
        routes=[
            FleetRouteOut(
                **dict(plan_response(route.plan, include_geometry)),
                vehicle_id=route.vehicle_id,
            )
            for route in result.routes
        ],
        unassigned=[UnassignedOut(**vars(u)) for u in result.unassigned],
        totals=FleetTotals(
            distance_m=result.distance_m,
            duration_s=result.duration_s,
            energy_kwh=energy(result.energy_kwh),
            grid_kwh=result.grid_kwh,
            vehicles_used=result.vehicles_used,
        ),
        solver=FleetSolverOut(
            status=result.solver_status,
            objective=result.objective,
            objective_value=result.objective_value,
            runtime_s=result.solver_runtime_s,
            verification_rounds=result.verification_rounds,
        ),
        timezone=result.timezone,
        distance_source=result.distance_source,
        warnings=result.warnings,
        attribution=OSM_ATTRIBUTION if result.distance_source == "osrm" else None,
    )


def plan_geojson(result: PlanResult, depot_lat: float, depot_lon: float) -> PlanFeatureCollection:
    """The round as a GeoJSON FeatureCollection for a web map."""
    depot_id = result.tour[0]
    features = [
        Feature(
            geometry=Point(coordinates=(depot_lon, depot_lat)),
            properties={
                "kind": "depot",
                "id": depot_id,
                "depart": result.legs[0].depart.isoformat(),
                "return": result.legs[-1].arrive.isoformat(),
                "snap_distance_m": result.depot_snap_distance_m,
            },
        )
    ]
    for order, stop in enumerate(result.stops, start=1):
        features.append(
            Feature(
                geometry=Point(coordinates=(stop.lon, stop.lat)),
                properties={
                    "kind": "stop",
                    "id": stop.id,
                    "sequence": order,
                    "arrival": stop.arrival.isoformat(),
                    "departure": stop.departure.isoformat(),
                    "door_heat_kwh": stop.door_heat_kwh,
                    "soc_arrival": stop.soc_arrival,
                    "soc_departure": stop.soc_departure,
                    "snap_distance_m": stop.snap_distance_m,
                },
            )
        )
    for index, leg in enumerate(result.legs):
        properties: dict[str, Any] = {
            "kind": "leg",
            "index": index,
            "from_id": leg.from_id,
            "to_id": leg.to_id,
            "depart": leg.depart.isoformat(),
            "arrive": leg.arrive.isoformat(),
            "distance_m": leg.distance_m,
            "duration_s": leg.duration_s,
            "street_type": leg.street_type,
            "energy_kwh": leg.energy_kwh,
            "soc_start": leg.soc_start,
            "soc_end": leg.soc_end,
        }
        features.append(
            Feature(geometry=LineString(coordinates=leg.geometry), properties=properties)
        )
    return PlanFeatureCollection(
        features=features,
        attribution=OSM_ATTRIBUTION if result.distance_source == "osrm" else None,
    )
