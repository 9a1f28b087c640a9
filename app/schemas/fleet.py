"""POST /v1/fleet-plans: the day's stops and the fleet, and the fleet's verified routes."""

from __future__ import annotations

from pydantic import Field

from app.schemas.base import ApiModel, AttributionOut, DistanceSourceOut, EnergyKwh, VanRequest
from app.schemas.plans import AnswerOptions, PlanResponse
from core.params import Objective
from core.planning.model import (
    FleetFields,
    FleetStatus,
    Replay,
    ShiftFields,
    Unassigned,
    vehicles_field,
)
from core.routing.effort import SearchEnd


class FleetVehicleRequest(VanRequest, ShiftFields):
    """One van of the fleet: the van exactly as in /v1/plans (a preset and the parameters to
    change) and its driver's shift."""


class FleetPlanRequest(AnswerOptions, FleetFields):
    """The day's stops and the fleet that serves them from one depot."""

    vehicles: list[FleetVehicleRequest] = vehicles_field()  # type: ignore[assignment]


class FleetRouteOut(PlanResponse):
    """The planned and simulated day of one van, as a /v1/plans answer, with the van's id."""

    vehicle_id: str = Field(..., description="The van that drives this route.")


class UnassignedOut(ApiModel, Unassigned):
    """A stop no van serves."""


class FleetTotals(ApiModel):
    """Every route of the fleet together."""

    distance_m: float = Field(..., description="Distance driven by every van [m].")
    duration_s: float = Field(
        ..., description="Sum of each van's time from departure to return [s]."
    )
    energy_kwh: EnergyKwh = Field(..., description="Energy of each consumer over the fleet [kWh].")
    grid_kwh: float = Field(
        ..., description="Pre-conditioning from the grid at the depot, every van [kWh]."
    )
    vehicles_used: int = Field(..., description="Vans that drive.")


class FleetSolverOut(ApiModel):
    """How the fleet search ended."""

    status: FleetStatus = Field(
        ...,
        description="feasible: the best routes found that hold (a fleet's search proves "
        "nothing); no_solution: no route serves any stop (unassigned says why).",
    )
    stopped_by: SearchEnd = Field(
        "work",
        description="work: the search did all its work (work_s); time_limit: time_limit_s "
        "stopped it first — the answer may then differ on a retry (a warning says so).",
    )
    objective: Objective = Field(..., description="What the routes minimised.")
    objective_value: float = Field(
        ..., description="Of every route together, in m, s or Wh (estimate)."
    )
    replay: Replay | None = Field(
        None,
        description="The work the searches did: sent back as the request's replay, the same "
        "answer to the byte but for the runtime_s fields.",
    )
    runtime_s: float = Field(
        ...,
        description="Time the search and the verification took [s]. A timing field: it differs "
        "between runs.",
    )
    verification_rounds: int = Field(
        ...,
        description="How often the routes were simulated in full; above 1 when a simulation "
        "broke a rule the estimates missed and the fleet was solved again.",
    )


class FleetPlanResponse(ApiModel):
    """The fleet's day: every route verified by the full simulation."""

    routes: list[FleetRouteOut] = Field(
        ...,
        description="One per van that drives, in the order of vehicles[]: everything a "
        "/v1/plans answer holds.",
    )
    unassigned: list[UnassignedOut] = Field(
        ..., description="Stops no van serves, in request order, each with its reason."
    )
    totals: FleetTotals = Field(..., description="Every route together.")
    solver: FleetSolverOut = Field(..., description="How the search ended.")
    timezone: str = Field(..., description="Time zone of the times, or the solar-time note.")
    distance_source: DistanceSourceOut
    warnings: list[str] = Field(
        default_factory=list, description="What the plan had to do without."
    )
    attribution: AttributionOut = None
