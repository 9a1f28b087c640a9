"""``POST /v1/fleet-plans`` and jobs of type ``fleet-plan``: a request → the core's fleet →
the answer."""

from __future__ import annotations

from dataclasses import replace

from app import connectors
from app.operations.answers import attribution, energy
from app.operations.encoded import Encoded, encoded
from app.operations.limits import check_fleet_size, far_stops, search_limits
from app.operations.plan import plan_response
from app.operations.vans import van_of
from app.schemas.fleet import (
    FleetPlanRequest,
    FleetPlanResponse,
    FleetRouteOut,
    FleetSolverOut,
    FleetTotals,
    UnassignedOut,
)
from app.settings import Settings
from core.exceptions import CoreError
from core.planning.fleet.planner import check_fleet, plan_fleet
from core.planning.model import (
    FleetFields,
    FleetProblem,
    FleetResult,
    FleetVehicle,
    ShiftFields,
    fields_of,
)


def fleet_problem(request: FleetPlanRequest, settings: Settings) -> FleetProblem:
    """The core problem of a fleet plan request, within the server's limits; a van's own
    errors name it (``vehicles[1].battery.min_soc``)."""
    check_fleet_size(request, len(request.vehicles), settings)
    vehicles = []
    charger = request.depot.charger
    for index, vehicle in enumerate(request.vehicles):
        try:
            van = van_of(vehicle, settings).priced(
                None if charger is None else charger.price_per_kwh
            )
        except CoreError as error:
            raise error.under(f"vehicles[{index}]") from None
        vehicles.append(FleetVehicle(**fields_of(vehicle, ShiftFields), van=van))
    return FleetProblem(
        **fields_of(request, FleetFields) | search_limits(request, settings),
        vehicles=vehicles,
    )


def check_fleet_plan(request: FleetPlanRequest, settings: Settings) -> None:
    """Everything but the solve: what a job refuses at submission."""
    check_fleet(fleet_problem(request, settings))


def run_fleet_plan(request: FleetPlanRequest, settings: Settings) -> FleetResult:
    """Plan the fleet's day with the configured road router and weather service."""
    result = plan_fleet(
        fleet_problem(request, settings),
        connectors.router(settings),
        connectors.weather_service(settings),
    )
    return replace(result, warnings=[*far_stops(request, settings), *result.warnings])


def fleet_response(
    result: FleetResult, include_geometry: bool = False, include_profile: bool = False
) -> FleetPlanResponse:
    """The answer of ``POST /v1/fleet-plans``."""
    return FleetPlanResponse(
        routes=[
            FleetRouteOut(
                **dict(plan_response(route.plan, include_geometry, include_profile)),
                vehicle_id=route.vehicle_id,
            )
            for route in result.routes
        ],
        unassigned=[UnassignedOut(**dict(u)) for u in result.unassigned],
        totals=FleetTotals(
            distance_m=result.distance_m,
            duration_s=result.duration_s,
            energy_kwh=energy(result.energy_kwh),
            grid_kwh=result.grid_kwh,
            vehicles_used=result.vehicles_used,
        ),
        solver=FleetSolverOut(
            status=result.status,
            objective=result.objective,
            objective_value=result.objective_value,
            runtime_s=result.runtime_s,
            stopped_by=result.stopped_by,
            replay=result.replay,
            verification_rounds=result.verification_rounds,
        ),
        timezone=result.timezone,
        distance_source=result.distance_source,
        warnings=result.warnings,
        attribution=attribution(result.distance_source),
    )


def answer(request: FleetPlanRequest, result: FleetResult) -> FleetPlanResponse:
    """What the endpoint answers a fleet plan request with (as JSON)."""
    return fleet_response(result, request.include_geometry, request.include_profile)


def fleet_answer(request: FleetPlanRequest, settings: Settings) -> Encoded:
    """``POST /v1/fleet-plans``'s answer, planned and written out in the worker."""
    result = run_fleet_plan(request, settings)
    return encoded(answer(request, result), runtime_s=result.runtime_s)
