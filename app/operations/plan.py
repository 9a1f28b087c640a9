"""``POST /v1/plans`` and jobs of type ``plan``: a request → the core's round → the answer."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from app import connectors
from app.operations.answers import attribution, battery, box, empty_at, energy, weather
from app.operations.encoded import Encoded, encoded
from app.operations.limits import check_round, far_stops, search_limits
from app.operations.vans import van_of
from app.schemas.base import (
    ColdChainOut,
    EnergySeries,
    EnergyShare,
    LineString,
    Point,
    RefrigerationOut,
)
from app.schemas.plans import (
    BreakOut,
    ChargeOut,
    DayProfileOut,
    Feature,
    LegOut,
    PlanFeatureCollection,
    PlanRequest,
    PlanResponse,
    ReloadOut,
    SolverOut,
    StopOut,
    Totals,
    VisitOut,
)
from app.settings import Settings
from core.planning.model import DayProfile, PlanFields, PlanProblem, PlanResult, fields_of
from core.planning.round.planner import check, plan

#: The media type of a round as a map (RFC 7946).
GEOJSON = "application/geo+json"


def plan_problem(request: PlanRequest, settings: Settings) -> PlanProblem:
    """The core problem of a plan request, within the server's limits."""
    check_round(request, settings)
    charger = request.depot.charger
    return PlanProblem(
        **fields_of(request, PlanFields) | search_limits(request, settings),
        van=van_of(request, settings).priced(None if charger is None else charger.price_per_kwh),
    )


def check_plan(request: PlanRequest, settings: Settings) -> None:
    """Everything but the solve: what a job refuses at submission."""
    check(plan_problem(request, settings))


def run_plan(request: PlanRequest, settings: Settings) -> PlanResult:
    """Plan a round with the configured road router and weather service."""
    result = plan(
        plan_problem(request, settings),
        connectors.router(settings),
        connectors.weather_service(settings),
    )
    return replace(result, warnings=[*far_stops(request, settings), *result.warnings])


def plan_response(
    result: PlanResult, include_geometry: bool = False, include_profile: bool = False
) -> PlanResponse:
    """The answer of ``POST /v1/plans`` for a planned round."""
    legs = [
        LegOut(
            **dict(leg)
            | {
                "energy_kwh": energy(leg.energy_kwh),
                "geometry": LineString(coordinates=leg.geometry) if include_geometry else None,
            }
        )
        for leg in result.legs
    ]
    stops = [
        StopOut(**dict(stop) | {"energy_kwh": energy(stop.energy_kwh)}) for stop in result.stops
    ]
    return PlanResponse(
        tour=result.tour,
        legs=legs,
        stops=stops,
        charges=[ChargeOut(**dict(charge)) for charge in result.charges],
        reloads=[ReloadOut(**dict(reload)) for reload in result.reloads],
        breaks=[BreakOut(**dict(rest)) for rest in result.breaks],
        visits=[VisitOut(**dict(v) | {"energy_kwh": energy(v.energy_kwh)}) for v in result.visits],
        totals=Totals(
            distance_m=result.distance_m,
            duration_s=result.duration_s,
            energy_kwh=energy(result.energy_kwh),
            energy_share=EnergyShare(**result.energy_share),
            grid_kwh=result.grid_kwh,
        ),
        battery=battery(
            result.battery,
            result.first_infeasible_leg,
            result.battery_loss_kwh,
            empty_at(result),
        ),
        weather=weather(result.weather, result.weather_source, result.weather_days),
        timezone=result.timezone,
        box=box(
            result.max_box_temperature_c,
            result.minutes_above_product_limit,
            result.product_limit_c,
        ),
        cold_chain=None if result.cold_chain is None else ColdChainOut(**dict(result.cold_chain)),
        refrigeration=(
            None if result.refrigeration is None else RefrigerationOut(**dict(result.refrigeration))
        ),
        solver=SolverOut(**dict(result.solved), objective=result.objective),
        distance_source=result.distance_source,
        warnings=result.warnings,
        attribution=attribution(result.distance_source),
        profile=day_profile(result.profile) if include_profile else None,
    )


def day_profile(profile: DayProfile) -> DayProfileOut:
    return DayProfileOut(**dict(profile) | {"energy_kwh": EnergySeries(**profile.energy_kwh)})


def answer(request: PlanRequest, result: PlanResult) -> PlanResponse:
    """What the endpoint answers a plan request with (as JSON)."""
    return plan_response(result, request.include_geometry, request.include_profile)


def plan_answer(request: PlanRequest, settings: Settings, geojson: bool = False) -> Encoded:
    """``POST /v1/plans``'s answer, planned and written out in the worker: as JSON, or as
    GeoJSON for a map when ``geojson``."""
    result = run_plan(request, settings)
    runtime_s = result.solved.runtime_s
    if geojson:
        collection = plan_geojson(result, request.depot.lat, request.depot.lon)
        return encoded(collection, GEOJSON, runtime_s)
    return encoded(answer(request, result), runtime_s=runtime_s)


def plan_geojson(result: PlanResult, depot_lat: float, depot_lon: float) -> PlanFeatureCollection:
    """The round as a GeoJSON FeatureCollection for a web map."""
    features = [
        Feature(
            geometry=Point(coordinates=(depot_lon, depot_lat)),
            properties={
                "kind": "depot",
                "id": result.tour[0],
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
    for charge in result.charges:
        features.append(
            Feature(
                geometry=Point(coordinates=(charge.lon, charge.lat)),
                properties={"kind": "charge"} | ChargeOut(**dict(charge)).model_dump(mode="json"),
            )
        )
    for reload in result.reloads:
        features.append(
            Feature(
                geometry=Point(coordinates=(depot_lon, depot_lat)),
                properties={"kind": "reload"} | ReloadOut(**dict(reload)).model_dump(mode="json"),
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
    return PlanFeatureCollection(features=features, attribution=attribution(result.distance_source))
