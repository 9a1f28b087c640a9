"""Fleet planning: the day's stops split across several vans from one depot, with delivery time
windows, shifts, payload and the battery as constraints — and every returned route verified by
the full simulation of its day.

1. The solver (:mod:`core.vrp`) plans with estimates: each arc's driving time, and its energy
   as traction by the arc's distance and grade for the van's mass plus the standing loads
   (auxiliaries, cab, box) times its duration, with each stop's service and door openings;
   the usable battery energy between departure charge and reserve is the van's budget.
2. Each route is driven and simulated in full (:func:`core.round.simulate_round`: traction,
   auxiliaries, cab, refrigeration with the door openings, at the time of day each leg is
   really driven). A route that breaks a rule — its charge below the reserve, a window missed,
   back after its shift — tightens the estimate that misled the solver (that van's energy
   budget by the simulated shortfall; the driving times of the arcs driven, exactly, and of the
   others by the ratio seen) and the fleet is solved again from the routes that held, within
   the time budget.
3. Whatever still fails when the budget is spent loses stops, one at a time, until its
   simulation holds. A stop no van can serve is listed with its reason — never a route reported
   feasible that the simulation says is not.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
import time
from collections import Counter
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from pydantic import Field, ValidationInfo, field_validator

from core.battery import JOULES_PER_KWH, capacity_factor, energy_factor
from core.cargo import door_heat_w, refrigeration_cop
from core.clock import at, check_representable, departure
from core.exceptions import InvalidParameterError
from core.geo import DistanceSource, Legs, build_legs
from core.params import (
    NORMAL_DRIVER,
    ClockTime,
    Depot,
    IsoDate,
    Objective,
    Params,
    RoadMatrix,
    Stop,
    VanParams,
    Weather,
)
from core.roads import RememberingRouter, RoadRouter
from core.round import (
    MAX_ROUND_S,
    PlanProblem,
    PlanResult,
    Solved,
    WeatherFor,
    check_stop_ids,
    cost_matrix,
    drive_time_s,
    energy_matrix_j,
    leg_routes,
    simulate_round,
    standing,
    windows_after,
)
from core.simulate import CONSUMERS
from core.tsp import SolverStatus
from core.vrp import RoutingInput, VehicleSpec, solve_routes
from core.weather import Forecast, WeatherService, forecast_for

UnassignedReason = Literal["time_window", "capacity", "battery", "shift", "unreachable"]
#: Most vans in one fleet plan.
MAX_VEHICLES = 100
#: Share of the remaining budget one solve may take (the rest verifies and re-solves).
_SOLVE_SHARE = 0.9
#: Budget below which no new solve starts [s].
_MIN_SOLVE_S = 0.05
#: A tightened energy budget is cut this much below the simulated need, so the next
#: solution does not land on the edge again.
_TIGHTEN_MARGIN = 0.98
#: Which reason names a stop that vans refuse for different reasons, when as many refuse it for
#: each.
_REASON_ORDER: tuple[UnassignedReason, ...] = ("capacity", "time_window", "shift", "battery")
#: Stops whose arcs are driven before the first solve to learn the simulation's driving times.
_CALIBRATION_STOPS = 12
#: Energy in the solver: tenths of a watt-hour per joule.
_TENTH_WH_PER_J = 1 / 360.0


def shift_in_order(start: dt.time | None, end: dt.time) -> dt.time:
    """``end`` when it is after ``start`` (shifts end on the day they start)."""
    if start is not None and end <= start:
        raise ValueError("shift_end must be after shift_start (shifts end on the same day)")
    return end


class FleetVehicle(Params):
    """One van of the fleet and its driver's shift."""

    id: str = Field(..., min_length=1, max_length=64, description="Identifier of the van.")
    van: VanParams = Field(default_factory=VanParams, description="The van, as in a plan.")
    shift_start: ClockTime = Field(
        dt.time(8, 0), description="Earliest departure from the depot, local HH:MM."
    )
    shift_end: ClockTime = Field(
        dt.time(18, 0), description="Latest return to the depot, local HH:MM; after the start."
    )

    @field_validator("shift_end")
    @classmethod
    def _after_start(cls, value: dt.time, info: ValidationInfo) -> dt.time:
        return shift_in_order(info.data.get("shift_start"), value)


class FleetProblem(Params):
    """The day's stops and the fleet that serves them from one depot."""

    date: IsoDate = Field(..., description="Day of the rounds.")
    timezone: str | None = Field(
        None, description="IANA time zone; null uses local mean solar time at the depot."
    )
    depot: Depot
    vehicles: list[FleetVehicle] = Field(..., min_length=1, max_length=MAX_VEHICLES)
    stops: list[Stop] = Field(..., min_length=1)
    objective: Objective = "distance"
    minimize_vehicles: bool = True
    weather: Weather | None = None
    driver_aggressiveness: float = Field(NORMAL_DRIVER, ge=0, le=1)
    traffic_density: float | None = Field(None, gt=0, lt=1)
    matrix: RoadMatrix | None = None
    time_limit_s: float = Field(5.0, gt=0, le=600)


@dataclass(frozen=True)
class VanShift:
    """One van as the engine sees it: its round (van, stops, conditions), its earliest
    departure and its latest return (None: the planner's longest round)."""

    id: str
    problem: PlanProblem
    start: dt.datetime
    end: dt.datetime | None


@dataclass(frozen=True)
class Unassigned:
    """A stop no van serves, why (``reason``) and a sentence that says so (``detail``)."""

    id: str
    reason: UnassignedReason
    detail: str


@dataclass(frozen=True)
class FleetRoute:
    """The simulated day of one van that drives."""

    vehicle_id: str
    plan: PlanResult


@dataclass(frozen=True)
class Routed:
    """What the engine found: the verified routes, the stops left out, the rounds of
    verification and the time it took [s]."""

    routes: list[FleetRoute]
    unassigned: list[Unassigned]
    verification_rounds: int
    runtime_s: float
    objective_value: float


@dataclass(frozen=True)
class FleetResult:
    """The fleet's plan for the day.

    Attributes
    ----------
    routes
        One simulated day per van that drives, in the order of the request's vans.
    unassigned
        The stops no van serves, each with its reason.
    distance_m, duration_s
        Over every route: driven distance [m] and time from each departure to its return [s].
    energy_kwh
        Energy per consumer and ``total`` over every route [kWh].
    grid_kwh
        Pre-conditioning on grid power at the depot, over every route [kWh].
    vehicles_used
        Vans that drive.
    objective, objective_value
        What the solver minimised, and its value over the routes (m, s or Wh, estimated).
    solver_status, solver_runtime_s, verification_rounds
        How the search ended, the whole time taken [s], and how often the fleet was verified
        by simulation (and re-solved after a failed verification).
    """

    routes: list[FleetRoute]
    unassigned: list[Unassigned]
    distance_m: float
    duration_s: float
    energy_kwh: dict[str, float]
    grid_kwh: float
    vehicles_used: int
    objective: Objective
    objective_value: float
    solver_status: SolverStatus
    solver_runtime_s: float
    verification_rounds: int
    timezone: str
    distance_source: DistanceSource
    warnings: list[str]


def plan_fleet(
    problem: FleetProblem,
    router: RoadRouter | None = None,
    weather_service: WeatherService | None = None,
) -> FleetResult:
    """Split the stops across the fleet, order each van's stops and verify every route by the
    full simulation of its day.

    Parameters
    ----------
    problem
        The fleet and the day's stops.
    router
        A road router for the matrix and the roads, as in :func:`core.plan.plan`.
    weather_service
        An hourly forecast for the day, as in :func:`core.plan.plan`.
    """
    shifts, timezone_name = check_fleet(problem)
    places: list[Depot] = [problem.depot, *problem.stops]
    table = router.table(places) if router is not None and problem.matrix is None else None
    legs = build_legs(places, problem.matrix, table)
    first = min(shift.start for shift in shifts)
    last = max(shift.end for shift in shifts if shift.end is not None)
    # One forecast for the whole day, shared by every van.
    day_weather, day_warnings = forecast_for(
        problem.weather,
        weather_service,
        problem.depot.lat,
        problem.depot.lon,
        first,
        last.timestamp() - first.timestamp() + 2 * 3600.0,
    )

    def weather_for(begin: dt.datetime, span_s: float) -> tuple[Forecast | None, list[str]]:
        return day_weather, day_warnings

    routed = FleetSolver(
        shifts,
        places,
        legs,
        timezone_name,
        None if router is None else RememberingRouter(router),
        weather_for,
        energy_budget=True,
    ).run(problem.minimize_vehicles)
    plans = [route.plan for route in routed.routes]
    energy = {name: sum(p.energy_kwh[name] for p in plans) for name in (*CONSUMERS, "total")}
    return FleetResult(
        routes=routed.routes,
        unassigned=routed.unassigned,
        distance_m=sum(p.distance_m for p in plans),
        duration_s=sum(p.duration_s for p in plans),
        energy_kwh=energy,
        grid_kwh=sum(p.grid_kwh for p in plans),
        vehicles_used=len(plans),
        objective=problem.objective,
        objective_value=routed.objective_value,
        solver_status="feasible",
        solver_runtime_s=routed.runtime_s,
        verification_rounds=routed.verification_rounds,
        timezone=timezone_name,
        distance_source=legs.source,
        warnings=list(day_warnings),
    )


def check_fleet(problem: FleetProblem) -> tuple[list[VanShift], str]:
    """Everything about a fleet plan that can be checked without solving it: unique ids of
    stops and vans, each shift's start and end on the day in the zone, the client's matrix.
    Raises :class:`core.exceptions.CoreError` naming the field; returns each van's shift and
    the zone's name."""
    check_stop_ids(problem.depot, problem.stops)
    vans: dict[str, int] = {}
    for index, vehicle in enumerate(problem.vehicles):
        if vehicle.id in vans:
            raise InvalidParameterError(
                f"vehicle id '{vehicle.id}' is used twice (also by vehicles[{vans[vehicle.id]}])"
                "; ids must be unique",
                f"vehicles[{index}].id",
            )
        vans[vehicle.id] = index
    timezone_name = ""
    shifts = []
    for index, vehicle in enumerate(problem.vehicles):
        ends = []
        for name in ("shift_start", "shift_end"):
            try:
                moment, timezone_name = departure(
                    problem.date, getattr(vehicle, name), problem.timezone, problem.depot.lon
                )
            except InvalidParameterError as error:
                raise InvalidParameterError(error.message, f"vehicles[{index}].{name}") from None
            ends.append(moment)
        check_representable(ends[1], 86_400.0, "date")
        round_problem = PlanProblem(
            date=problem.date,
            start_time=vehicle.shift_start,
            timezone=problem.timezone,
            depot=problem.depot,
            stops=problem.stops,
            van=vehicle.van,
            weather=problem.weather,
            driver_aggressiveness=problem.driver_aggressiveness,
            traffic_density=problem.traffic_density,
            objective=problem.objective,
            matrix=problem.matrix,
            time_limit_s=problem.time_limit_s,
        )
        shifts.append(VanShift(vehicle.id, round_problem, ends[0], ends[1]))
    if problem.matrix is not None:
        build_legs([problem.depot, *problem.stops], problem.matrix)
    return shifts, timezone_name


@dataclass
class _Kind:
    """The solver's estimates for one kind of van (same parameters and departure)."""

    arc_cost: np.ndarray
    unit_value: float
    offset: float
    energy_j: np.ndarray  # arc energy with the service at its origin [J]
    budget_j: float
    wait_cost_per_s: int  # the objective's cost of a second waiting for a window


@dataclass(frozen=True)
class _Failure:
    """Why a simulated route does not hold: the rule and, for the stop-bound rules, the stop."""

    reason: UnassignedReason
    node: int | None
    detail: str


class FleetSolver:
    """Routes for the vans, each verified by the simulation of its day: solve, verify, tighten,
    solve again (see the module).

    Parameters
    ----------
    shifts
        The vans; their problems share the depot, the stops, the date and the conditions.
    places, legs
        The depot then the stops, and every ordered pair's leg.
    timezone_name
        The zone's name, for the answers.
    router
        For the roads of the legs driven (OSRM), or None.
    weather_for
        The weather for a span of the day.
    energy_budget
        Whether the battery and the payload are constraints (a fleet) or only reported (one
        round, whose payload is checked beforehand).
    """

    def __init__(
        self,
        shifts: list[VanShift],
        places: list[Depot],
        legs: Legs,
        timezone_name: str,
        router: RoadRouter | None,
        weather_for: WeatherFor,
        *,
        energy_budget: bool,
    ) -> None:
        self.started = time.perf_counter()
        self.shifts = shifts
        self.places = places
        self.legs = legs
        self.timezone_name = timezone_name
        self.router = router
        self.weather_for = weather_for
        self.energy_budget = energy_budget
        base = shifts[0].problem
        self.base = base
        self.deadline = self.started + base.time_limit_s
        self.stops = base.stops
        n = len(places)
        self.reference = min(shift.start for shift in shifts)
        origin = self.reference.timestamp()
        self.shift_s = [
            (
                shift.start.timestamp() - origin,
                (shift.end if shift.end is not None else at(shift.start, MAX_ROUND_S)).timestamp()
                - origin,
            )
            for shift in shifts
        ]
        self.horizon_s = math.floor(max(end for _, end in self.shift_s))
        self.windows_s = windows_after(base.stops, base.date, self.reference)
        self.unreachable = set(legs.unreachable())
        finite = np.isfinite(legs.duration_s) & np.isfinite(legs.distance_m)
        self.finite = finite
        self.duration_s = np.where(finite, legs.duration_s, 0.0)
        # Driving times the simulation showed, per arc; the ratio to the matrix for the rest.
        self.traced_s: dict[tuple[int, int], float] = {}
        self.time_ratio = 1.0
        self.service_s = np.array([0.0] + [math.ceil(s.service_time_s) for s in base.stops])
        self.demand_g = np.array([0] + [math.ceil(s.delivery_kg * 1000) for s in base.stops])
        self.kinds: dict[str, _Kind] = {}
        self.kind_of = [self._kind(shift) for shift in shifts]
        self.budget_scale = [1.0] * len(shifts)
        self.n = n
        self._calibrate_times()
        self.travel = self._travel_s()

    # --- the solver's view -------------------------------------------------------------------

    def _kind(self, shift: VanShift) -> str:
        key = f"{shift.problem.van.model_dump_json()}@{shift.start.isoformat()}"
        if key in self.kinds:
            return key
        problem = shift.problem
        finite_legs = self._finite_legs()
        arc_cost, unit_value, offset = cost_matrix(problem, finite_legs, shift.start)
        still = standing(problem, shift.start, parked=True)
        ambient_c = float(still.ambient_c[0])
        parked_w = float(sum(still.power_w[name][0] for name in CONSUMERS if name != "traction"))
        box = problem.van.cargo_box
        door_j = np.array(
            [0.0]
            + [
                abs(float(door_heat_w(box, ambient_c, box.setpoint_c)))
                * stop.door_open_s
                / float(refrigeration_cop(box, ambient_c, box.setpoint_c))
                for stop in self.stops
            ]
        )
        stop_j = parked_w * self.service_s + door_j
        arc_j = energy_matrix_j(problem, finite_legs, shift.start) + stop_j[:, None]
        battery = problem.van.battery
        budget_j = (
            (battery.initial_soc - battery.min_soc)
            * battery.usable_capacity_kwh
            * JOULES_PER_KWH
            * capacity_factor(battery, ambient_c)
            / float(energy_factor(battery, ambient_c))
        )
        # Waiting for a window costs time, and energy: the van stands with its loads on.
        wait_cost = {"distance": 0, "duration": 1}.get(
            problem.objective, max(round(parked_w * _TENTH_WH_PER_J), 1)
        )
        self.kinds[key] = _Kind(arc_cost, unit_value, offset, arc_j, budget_j, wait_cost)
        return key

    def _finite_legs(self) -> Legs:
        """The legs with the arcs that have no road made long (the solver never picks them)."""
        legs = self.legs
        if self.finite.all():
            return legs
        far_m = float(np.nanmax(legs.distance_m)) * 10 + 1e6
        far_s = float(np.nanmax(legs.duration_s)) * 10 + 1e5
        return Legs(
            distance_m=np.where(self.finite, legs.distance_m, far_m),
            duration_s=np.where(self.finite, legs.duration_s, far_s),
            grade=legs.grade,
            street_type=legs.street_type,
            source=legs.source,
            snap_distance_m=legs.snap_distance_m,
        )

    def _calibrate_times(self) -> None:
        """Drive a sample of arcs as the simulation will (out of the depot, and on to each
        sampled stop's nearest neighbour) and take the slowest ratio to the matrix for the
        arcs not driven yet: the simulated trace, not the matrix, decides whether a window is
        met. A client's matrix is driven as it says."""
        if self.legs.source == "client":
            return
        reachable = [k for k in range(1, self.n) if k not in self.unreachable]
        sample = reachable[:: max(len(reachable) // _CALIBRATION_STOPS, 1)][:_CALIBRATION_STOPS]
        arcs = []
        for k in sample:
            arcs.append((0, k))
            onward = np.where(self.finite[k], self.duration_s[k], np.inf)
            onward[[0, k]] = np.inf
            if np.isfinite(onward).any():
                arcs.append((k, int(np.argmin(onward))))
        ratios = []
        for i, j in arcs:
            road = (
                self.router.route(self.places[i], self.places[j])
                if self.router is not None and self.legs.source == "osrm"
                else None
            )
            seconds = drive_time_s(self.base, self.legs, i, j, road)
            self.traced_s[(i, j)] = math.ceil(seconds)
            if self.duration_s[i, j] > 0:
                ratios.append(seconds / self.duration_s[i, j])
        if ratios:
            self.time_ratio = max(ratios)

    def _travel_s(self) -> np.ndarray:
        travel = np.rint(self.duration_s * self.time_ratio)
        for (i, j), seconds in self.traced_s.items():
            travel[i, j] = seconds
        travel[~self.finite] = self.horizon_s + 1
        return travel.astype(np.int64)

    def _input(self, minimize_vehicles: bool) -> RoutingInput:
        specs = []
        cost_bound = 0
        for kind in self.kinds.values():
            largest = kind.arc_cost.max(axis=1)
            cost_bound = max(cost_bound, int(largest.sum() + largest[0] * len(self.shifts)))
        fixed = cost_bound + 1 if minimize_vehicles else 0
        for v, shift in enumerate(self.shifts):
            kind = self.kinds[self.kind_of[v]]
            start_s, end_s = self.shift_s[v]
            specs.append(
                VehicleSpec(
                    arc_cost=kind.arc_cost,
                    energy=(
                        np.ceil(kind.energy_j * _TENTH_WH_PER_J).astype(np.int64)
                        if self.energy_budget
                        else None
                    ),
                    energy_capacity=int(kind.budget_j * self.budget_scale[v] * _TENTH_WH_PER_J),
                    payload_capacity_g=(
                        math.floor(shift.problem.van.payload_kg * 1000)
                        if self.energy_budget
                        else int(self.demand_g.sum())
                    ),
                    shift_s=(math.ceil(start_s), math.floor(end_s)),
                    fixed_cost=fixed + v,  # the vans listed first drive first
                    wait_cost_per_s=kind.wait_cost_per_s,
                )
            )
        # Windows within the day's horizon; a stop with none left (or no road) is never served:
        # its only window lies just past the horizon.
        never = [(self.horizon_s + 1, self.horizon_s + 1)]
        windows = []
        for node, place in enumerate(self.windows_s):
            inside = [(max(math.ceil(a), 0), min(math.floor(b), self.horizon_s)) for a, b in place]
            kept = [(a, b) for a, b in inside if a <= b]
            hopeless = node > 0 and all(self._alone(v, node) for v in range(len(self.shifts)))
            windows.append(
                never if (place and not kept) or node in self.unreachable or hopeless else kept
            )
        # A stop heavier than every van stays out by its window alone: a demand above every
        # capacity keeps the routing library's search busy until its time limit.
        demand = np.where([w is never for w in windows], 0, self.demand_g)
        return RoutingInput(
            travel_s=self.travel,
            service_s=self.service_s.astype(np.int64),
            windows_s=windows,
            demand_g=demand.astype(np.int64),
            vehicles=specs,
            horizon_s=self.horizon_s,
            drop_penalty=(cost_bound + 1) * (len(self.shifts) + 2),
        )

    # --- one pass ------------------------------------------------------------------------

    def run(self, minimize_vehicles: bool) -> Routed:
        """Solve and verify until every route holds or the time limit; ``minimize_vehicles``:
        fewer vans first, then the objective."""
        routes: list[list[int]] = [[] for _ in self.shifts]
        results: dict[int, PlanResult] = {}
        failures: dict[int, _Failure] = {}
        rounds = 0
        initial: list[list[int]] | None = None
        while True:
            remaining = self.deadline - time.perf_counter()
            if rounds and remaining < _MIN_SOLVE_S:
                break
            budget = max(remaining * _SOLVE_SHARE, _MIN_SOLVE_S)
            outcome = solve_routes(self._input(minimize_vehicles), budget, initial)
            rounds += 1
            routes = outcome.routes if outcome is not None else [[] for _ in self.shifts]
            results, failures = self._verify(routes)
            if not failures:
                break
            for v, failure in failures.items():
                self._tighten(v, failure, results[v])
            initial = [
                self._fitting(v, route) if v in failures else route
                for v, route in enumerate(routes)
            ]
        left_out: dict[int, _Failure] = {}
        for v in list(failures):
            routes[v], results_v, removed = self._repair(v, routes[v], failures[v])
            left_out |= removed
            if results_v is None:
                results.pop(v, None)
            else:
                results[v] = results_v
        served = {node for route in routes for node in route}
        unassigned = [
            self._unassigned(node, left_out.get(node), routes)
            for node in range(1, self.n)
            if node not in served
        ]
        unassigned.sort(key=lambda u: [s.id for s in self.stops].index(u.id))
        fleet = [
            FleetRoute(self.shifts[v].id, results[v])
            for v in range(len(self.shifts))
            if routes[v] and v in results
        ]
        objective_value = sum(
            self._route_cost(v, routes[v]) for v in range(len(self.shifts)) if routes[v]
        )
        runtime = time.perf_counter() - self.started
        fleet = [replace(r, plan=replace(r.plan, solver_runtime_s=runtime)) for r in fleet]
        return Routed(fleet, unassigned, rounds, runtime, objective_value)

    def _route_cost(self, v: int, route: list[int]) -> float:
        kind = self.kinds[self.kind_of[v]]
        order = [0, *route, 0]
        arcs = kind.arc_cost[order[:-1], order[1:]]
        return float(arcs.sum()) * kind.unit_value + kind.offset * (len(order) - 1)

    # --- verification --------------------------------------------------------------------

    def _simulate(self, v: int, route: list[int]) -> PlanResult:
        shift = self.shifts[v]
        order = [0, *route, 0]
        origin = self.reference.timestamp() - shift.start.timestamp()
        windows = [[(a + origin, b + origin) for a, b in place] for place in self.windows_s]
        roads = (
            leg_routes(self.router, self.places, order)
            if self.router is not None and self.legs.source == "osrm"
            else None
        )
        return simulate_round(
            shift.problem,
            self.places,
            self.legs,
            order,
            shift.start,
            self.timezone_name,
            roads,
            self.weather_for,
            Solved("feasible", self._route_cost(v, route), 0.0),
            windows,
            None if shift.end is None else shift.end.timestamp() - shift.start.timestamp(),
        )

    def _verify(self, routes: list[list[int]]) -> tuple[dict[int, PlanResult], dict[int, _Failure]]:
        results, failures = {}, {}
        for v, route in enumerate(routes):
            if not route:
                continue
            result = self._simulate(v, route)
            results[v] = result
            self._learn_times(route, result)
            self.travel = self._travel_s()
            failure = self._failure(v, route, result)
            if failure is not None:
                failures[v] = failure
        return results, failures

    def _learn_times(self, route: list[int], result: PlanResult) -> None:
        order = [0, *route, 0]
        ratios = []
        for (i, j), leg in zip(itertools.pairwise(order), result.legs, strict=True):
            self.traced_s[(i, j)] = math.ceil(leg.duration_s)
            if self.duration_s[i, j] > 0:
                ratios.append(leg.duration_s / self.duration_s[i, j])
        if ratios:
            self.time_ratio = max(self.time_ratio, float(np.quantile(ratios, 0.9)))

    def _failure(self, v: int, route: list[int], result: PlanResult) -> _Failure | None:
        ids = {self.places[node].id: node for node in route}
        if result.late_stops:
            node = ids[result.late_stops[0]]
            return _Failure(
                "time_window",
                node,
                f"{self.shifts[v].id} would reach it after its last window closes",
            )
        end = self.shifts[v].end
        back = result.legs[-1].arrive
        if end is not None and back > end:
            return _Failure(
                "shift",
                None,
                f"{self.shifts[v].id} would be back at {back:%H:%M}, after its shift ends at "
                f"{end:%H:%M}",
            )
        if self.energy_budget and not result.battery.feasible:
            return _Failure(
                "battery",
                None,
                f"the simulated day of {self.shifts[v].id} would take its battery to "
                f"{result.battery.min_soc:.0%}, below its reserve of "
                f"{self.shifts[v].problem.van.battery.min_soc:.0%}",
            )
        return None

    def _tighten(self, v: int, failure: _Failure, result: PlanResult) -> None:
        if failure.reason == "battery":
            battery = result.battery
            need = max(battery.required_capacity_kwh, 1e-9)
            self.budget_scale[v] *= min(battery.usable_capacity_kwh / need, 1.0) * _TIGHTEN_MARGIN

    def _violations(self, v: int, route: list[int]) -> list[UnassignedReason]:
        """The rules the solver's current estimates say van v breaks on this route."""
        kind = self.kinds[self.kind_of[v]]
        order = [0, *route, 0]
        broken: list[UnassignedReason] = []
        if self.energy_budget:
            payload = self.shifts[v].problem.van.payload_kg * 1000
            if float(self.demand_g[route].sum()) > payload:
                broken.append("capacity")
            energy = float(kind.energy_j[order[:-1], order[1:]].sum())
            if energy > kind.budget_j * self.budget_scale[v]:
                broken.append("battery")
        travel = self.travel
        clock, end = self.shift_s[v]
        for i, j in itertools.pairwise(order):
            clock += self.service_s[i] + travel[i, j]
            windows = self.windows_s[j]
            if j != 0 and windows:
                opens = next((a for a, b in windows if clock <= b), None)
                if opens is None:
                    broken.append("time_window")
                    break
                clock = max(clock, opens)
        else:
            if clock > end:
                broken.append("shift")
        return broken

    def _fitting(self, v: int, route: list[int]) -> list[int]:
        """The route less its last stops until the estimates accept it."""
        route = list(route)
        while route and self._violations(v, route):
            route.pop()
        return route

    def _repair(
        self, v: int, route: list[int], failure: _Failure
    ) -> tuple[list[int], PlanResult | None, dict[int, _Failure]]:
        """Drop stops from a route the simulation rejects until it holds."""
        removed: dict[int, _Failure] = {}
        route = list(route)
        result: PlanResult | None = None
        current: _Failure | None = failure
        while route and current is not None:
            node = current.node if current.node is not None else self._costliest(v, route)
            route.remove(node)
            removed[node] = current
            if not route:
                return route, None, removed
            result = self._simulate(v, route)
            current = self._failure(v, route, result)
        return route, result, removed

    def _costliest(self, v: int, route: list[int]) -> int:
        """The stop whose removal saves the most estimated energy."""
        energy = self.kinds[self.kind_of[v]].energy_j
        order = [0, *route, 0]
        savings = [
            energy[order[k - 1], order[k]]
            + energy[order[k], order[k + 1]]
            - energy[order[k - 1], order[k + 1]]
            for k in range(1, len(order) - 1)
        ]
        return route[int(np.argmax(savings))]

    # --- why a stop is left out ----------------------------------------------------------

    def _unassigned(
        self,
        node: int,
        failure: _Failure | None,
        routes: list[list[int]],
    ) -> Unassigned:
        stop = self.places[node]
        if node in self.unreachable:
            return Unassigned(
                stop.id, "unreachable", f"no road links it with the depot '{self.places[0].id}'"
            )
        alone = [self._alone(v, node) for v in range(len(self.shifts))]
        if all(why is not None for why in alone):
            # Each van has its own reason; the one most vans share (ties: the first listed).
            counts = Counter(why.reason for why in alone if why is not None)
            reason = max(_REASON_ORDER, key=lambda r: (counts[r], -_REASON_ORDER.index(r)))
            detail = next(why.detail for why in alone if why is not None and why.reason == reason)
            return Unassigned(stop.id, reason, detail)
        if failure is not None:
            return Unassigned(
                stop.id, failure.reason, f"left out after simulation: {failure.detail}"
            )
        return Unassigned(stop.id, *self._full(node, routes))

    def _alone(self, v: int, node: int) -> _Failure | None:
        """Why van v could not serve the stop even on a round of its own, if it could not."""
        shift, kind = self.shifts[v], self.kinds[self.kind_of[v]]
        stop = self.stops[node - 1]
        payload = shift.problem.van.payload_kg
        if self.energy_budget and stop.delivery_kg > payload:
            return _Failure(
                "capacity",
                node,
                f"it takes {stop.delivery_kg:g} kg; no van carries that much (largest payload "
                f"{max(s.problem.van.payload_kg for s in self.shifts):g} kg)",
            )
        travel = self.travel
        start_s, end_s = self.shift_s[v]
        arrive = start_s + travel[0, node]
        windows = self.windows_s[node]
        serve = arrive
        if windows:
            opens = next((a for a, b in windows if arrive <= b), None)
            if opens is None:
                latest = at(self.reference, windows[-1][1])
                return _Failure(
                    "time_window",
                    node,
                    f"the earliest any van gets there is {self._clock(self._earliest(node))}, "
                    f"after its last window closes at {latest:%H:%M}",
                )
            serve = max(arrive, opens)
        back = serve + self.service_s[node] + travel[node, 0]
        if back > end_s:
            return _Failure(
                "shift",
                node,
                "even on a round of its own no van would be back before its shift ends "
                f"(earliest return {self._clock(self._earliest_back(node))})",
            )
        if self.energy_budget:
            need_j = kind.energy_j[0, node] + kind.energy_j[node, 0]
            if need_j > kind.budget_j * self.budget_scale[v]:
                most_j = max(
                    self.kinds[self.kind_of[w]].budget_j * self.budget_scale[w]
                    for w in range(len(self.shifts))
                )
                return _Failure(
                    "battery",
                    node,
                    f"a round to it alone needs about {need_j / JOULES_PER_KWH:.1f} kWh; the "
                    f"most any van has above its reserve is about {most_j / JOULES_PER_KWH:.1f} "
                    "kWh",
                )
        return None

    def _earliest(self, node: int) -> float:
        travel = self.travel
        return min(start + travel[0, node] for start, _ in self.shift_s)

    def _earliest_back(self, node: int) -> float:
        travel = self.travel
        best = math.inf
        for start_s, _ in self.shift_s:
            serve = start_s + travel[0, node]
            windows = self.windows_s[node]
            if windows:
                opens = next((a for a, b in windows if serve <= b), None)
                if opens is None:
                    continue
                serve = max(serve, opens)
            best = min(best, serve + self.service_s[node] + travel[node, 0])
        return best

    def _clock(self, seconds: float) -> str:
        if not math.isfinite(seconds):
            return "never"
        return f"{at(self.reference, seconds):%H:%M}"

    def _full(self, node: int, routes: list[list[int]]) -> tuple[UnassignedReason, str]:
        """A stop some van could serve on a round of its own, left out because the fleet is
        full: the rule that stops it from joining any van's route at its best place, the one
        most vans share."""
        refusals: Counter[UnassignedReason] = Counter()
        for v, route in enumerate(routes):
            options = [
                self._violations(v, [*route[:k], node, *route[k:]]) for k in range(len(route) + 1)
            ]
            fewest = min(options, key=len)
            refusals.update(fewest[:1])
        if not refusals:
            return "shift", "the search ended (time limit) before it found a route for it"
        reason = max(_REASON_ORDER, key=lambda r: (refusals[r], -_REASON_ORDER.index(r)))
        return reason, {
            "capacity": "the fleet is full: no van has payload left for it",
            "battery": "the fleet's batteries are spent: on any van's route it would take the "
            "charge below the reserve",
            "time_window": "no van can reach it inside its windows alongside its other stops",
            "shift": "no van's shift has time left for it alongside its other stops",
        }[reason]
