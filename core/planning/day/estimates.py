"""What the solvers are given: each arc's cost in the objective's unit and its estimated energy,
each stop's energy, the battery budget of a kind of van (:class:`VanEstimates`, frozen), and
the driving times (:class:`LearnedTimes`), the one estimate that the simulation corrects while
a search runs.
"""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from core.arrays import FloatArray
from core.params import STREET_TYPES, Interval, Location, Stop
from core.physics.battery import JOULES_PER_KWH, capacity_factor, energy_factor
from core.physics.cargo import door_heat_w, refrigeration_cop
from core.physics.cycles import generate_leg
from core.physics.simulate import CONSUMERS, Along, SimulationResult, simulate
from core.physics.vehicle import step_traction_power_w
from core.planning.model import PLAN_DT_S, PlanProblem
from core.routing.geo import MAX_LEG_GRADE, STREET_TYPE_NAMES, Legs
from core.routing.units import ENERGY_UNIT_J

#: Length of the flat reference leg that calibrates the energy objective per street type [m].
_REFERENCE_LEG_M = 10_000.0
#: Quantile of the simulated over the matrix's driving times that scales the arcs not driven
#: yet: high, so windows planned on them hold, but not the slowest short hop.
LEARNED_RATIO_QUANTILE = 0.9


def standing(problem: PlanProblem, start: dt.datetime, parked: bool = False) -> SimulationResult:
    """The van standing at the depot at ``start``, pre-conditioned: its loads at departure,
    with the engine running (``parked`` False) or parked at a stop (the cab's duty at stops)."""
    return simulate(
        np.zeros(2),
        PLAN_DT_S,
        start,
        Location(lat=problem.depot.lat, lon=problem.depot.lon),
        problem.van.model_copy(update={"precondition_at_depot": True}),
        weather=problem.weather,
        along=Along(parked=[Interval(start_s=0.0, duration_s=2 * PLAN_DT_S)] if parked else []),
    )


def standing_power_w(still: SimulationResult) -> float:
    """Auxiliaries + cab + box power of a van standing still [W]."""
    return float(sum(still.power_w[name][0] for name in CONSUMERS if name != "traction"))


def energy_matrix_j(problem: PlanProblem, legs: Legs, start: dt.datetime) -> FloatArray:
    """Estimated electric energy of every leg [J]: the energy objective's arc costs.

    Traction per metre is simulated once per street type on a 10 km reference trace (same
    driver, traffic and departure mass) at every grade of a table from −25 % to +25 % in one
    broadcast call, and read for each leg by interpolation in its grade: climbs cost over the
    drive-train efficiency, descents first replace motoring and only then regenerate, and the
    matrix is asymmetric. Auxiliaries, cab and box add their power at departure (the request's
    weather or the climatology) times the leg's duration. The chosen tour is then simulated in
    full.
    """
    vehicle = problem.van.vehicle
    mass = vehicle.mass_kg + problem.van.payload_kg
    grades = np.linspace(-MAX_LEG_GRADE, MAX_LEG_GRADE, 51)
    traction = np.zeros_like(legs.distance_m)
    for index, name in enumerate(STREET_TYPE_NAMES):
        trace = generate_leg(
            _REFERENCE_LEG_M,
            STREET_TYPES[name],
            problem.driver_aggressiveness,
            vehicle.max_acceleration_mps2,
            problem.traffic_density,
            PLAN_DT_S,
        )
        power = step_traction_power_w(vehicle, trace, PLAN_DT_S, mass, grades[:, None])
        per_metre = power.sum(axis=1) * PLAN_DT_S / _REFERENCE_LEG_M
        on_type = legs.street_type == index
        traction[on_type] = np.interp(legs.grade[on_type], grades, per_metre)
    traction *= legs.distance_m
    return traction + standing_power_w(standing(problem, start)) * legs.duration_s


def cost_matrix(
    problem: PlanProblem, legs: Legs, start: dt.datetime
) -> tuple[NDArray[np.int64], float, float]:
    """Integer arc costs for the solver, the value of one cost unit and a per-arc offset, both in
    the objective's unit (m, s or Wh).

    Distance in metres and duration in seconds, rounded to the nearest integer; energy in
    tenths of a watt-hour, shifted so the cheapest arc costs 0 (every tour has the same number
    of arcs, so the shift does not change the best tour; the offset adds it back).
    """
    if problem.objective == "distance":
        return np.rint(legs.distance_m).astype(np.int64), 1.0, 0.0
    if problem.objective == "duration":
        return np.rint(legs.duration_s).astype(np.int64), 1.0, 0.0
    units = energy_matrix_j(problem, legs, start) / ENERGY_UNIT_J
    off_diagonal = ~np.eye(units.shape[0], dtype=bool)
    lowest = float(units[off_diagonal].min()) if off_diagonal.any() else 0.0
    shifted = np.where(off_diagonal, units - lowest, 0.0)
    wh_per_unit = ENERGY_UNIT_J / 3600.0
    return np.rint(shifted).astype(np.int64), wh_per_unit, lowest * wh_per_unit


@dataclass(frozen=True)
class VanEstimates:
    """The solver's estimates for one kind of van (the same parameters and departure).

    Attributes
    ----------
    arc_cost
        Objective cost of each arc, in the solver's integer unit.
    unit_value, offset
        Value of one cost unit and a per-arc offset, in the objective's unit (m, s or Wh).
    energy_j
        Each arc's energy with the service at its origin [J].
    budget_j
        Usable battery energy between the departure charge and the reserve on the day [J].
    wait_cost_per_s
        The objective's cost of a second spent waiting for a window (integer units per s):
        time, and energy, for the van stands with its loads on.
    start
        The place the van sets off from: the depot (0), or its position when under way.
    standing_w
        What the van draws standing with its loads on (auxiliaries, cab, box) [W].
    """

    arc_cost: NDArray[np.int64]
    unit_value: float
    offset: float
    energy_j: FloatArray
    budget_j: float
    wait_cost_per_s: int
    start: int = 0
    standing_w: float = 0.0

    def route_cost(self, route: Sequence[int]) -> float:
        """The objective's value of a route of stops (from the start, back to the depot), in
        its unit."""
        order = [self.start, *route, 0]
        arcs = self.arc_cost[order[:-1], order[1:]]
        return float(arcs.sum()) * self.unit_value + self.offset * (len(order) - 1)

    def route_energy_j(self, route: Sequence[int]) -> float:
        """The estimated energy of a route of stops (from the start, back to the depot) [J]."""
        order = [self.start, *route, 0]
        return float(self.energy_j[order[:-1], order[1:]].sum())


def van_estimates(
    problem: PlanProblem,
    legs: Legs,
    start: dt.datetime,
    stops: Sequence[Stop],
    service_s: FloatArray,
) -> VanEstimates:
    """The estimates of the van of ``problem`` departing at ``start``.

    Parameters
    ----------
    legs
        Every ordered pair's leg, arcs without a road made long.
    stops, service_s
        The stops, and each place's service time [s] (the depot's 0).
    """
    arc_cost, unit_value, offset = cost_matrix(problem, legs, start)
    still = standing(problem, start, parked=True)
    ambient_c = float(still.ambient_c[0])
    parked_w = standing_power_w(still)
    box = problem.van.cargo_box
    door_w = abs(float(door_heat_w(box, ambient_c, box.setpoint_c))) / float(
        refrigeration_cop(box, ambient_c, box.setpoint_c)
    )
    door_j = np.zeros(len(service_s))  # the depot's and the vans' positions: none
    door_j[1 : len(stops) + 1] = [door_w * stop.door_open_s for stop in stops]
    stop_j = parked_w * service_s + door_j
    battery = problem.van.battery
    budget_j = (
        (battery.initial_soc - battery.min_soc)
        * battery.usable_capacity_kwh
        * JOULES_PER_KWH
        * capacity_factor(battery, ambient_c)
        / float(energy_factor(battery, ambient_c))
    )
    wait_cost = {"distance": 0, "duration": 1}.get(
        problem.objective, max(round(parked_w / ENERGY_UNIT_J), 1)
    )
    return VanEstimates(
        arc_cost=arc_cost,
        unit_value=unit_value,
        offset=offset,
        energy_j=energy_matrix_j(problem, legs, start) + stop_j[:, None],
        budget_j=budget_j,
        wait_cost_per_s=wait_cost,
        standing_w=parked_w,
    )


class LearnedTimes:
    """The driving times the solver is given: the matrix's scaled by what the simulation
    showed, and exactly what it drove on each arc driven so far — the one estimate that changes
    during a search.

    The simulated trace, not the matrix, decides whether a window is met: a generated trace
    ramps up and down, a road profile brakes for each bend. The ratio of simulated to matrix
    time is learned with one rule: its :data:`LEARNED_RATIO_QUANTILE` over the arcs driven at a
    time, and it never falls once learned (1 until then).

    Parameters
    ----------
    duration_s
        The matrix's driving time of each arc [s] (finite; 0 where no road leads).
    finite
        Which arcs exist.
    horizon_s
        The day's last moment [s]: an arc that does not exist takes longer.
    """

    def __init__(self, duration_s: FloatArray, finite: NDArray[np.bool_], horizon_s: int) -> None:
        self.duration_s = duration_s
        self.finite = finite
        self.horizon_s = horizon_s
        self.traced_s: dict[tuple[int, int], int] = {}
        self.ratio: float | None = None
        self._matrix: NDArray[np.int64] | None = None

    def learn(self, driven: Iterable[tuple[tuple[int, int], float]]) -> None:
        """Take the simulated driving time of some arcs [s]."""
        ratios = []
        for (i, j), seconds in driven:
            self.traced_s[(i, j)] = math.ceil(seconds)
            if self.duration_s[i, j] > 0:
                ratios.append(seconds / self.duration_s[i, j])
        if ratios:
            seen = float(np.quantile(ratios, LEARNED_RATIO_QUANTILE))
            self.ratio = seen if self.ratio is None else max(self.ratio, seen)
        self._matrix = None

    def matrix(self) -> NDArray[np.int64]:
        """The driving time of every arc for the solver [s]."""
        if self._matrix is None:
            travel = np.rint(self.duration_s * (self.ratio or 1.0))
            for (i, j), seconds in self.traced_s.items():
                travel[i, j] = seconds
            travel[~self.finite] = self.horizon_s + 1
            self._matrix = travel.astype(np.int64)
        return self._matrix
