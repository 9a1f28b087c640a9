"""The fleet's search: the day's stops split across its vans and ordered on the estimates,
every route verified by the full simulation of its day (the steps of
:mod:`core.planning.fleet.planner`: solve, verify, learn and tighten, re-solve; repair; stops
left out given to idle vans; with chargers, planned again with charges between stops by
:mod:`core.planning.search.charging.fleet_charging`). The fleet planner checks the request
and answers around it; the round planner uses it with one van when stops have windows.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from core.planning.day.estimates import LearnedTimes
from core.planning.day.timeline import drive_time_s
from core.planning.day.verify import Failure, route_failure, traced_seconds
from core.planning.model import (
    FleetRoute,
    PlanResult,
    Unassigned,
)
from core.planning.search.charging.fleet_charging import charging_routes, measure
from core.planning.search.day import FleetDay, leg_roads
from core.planning.search.explain import explain
from core.planning.search.feasibility import Feasibility
from core.planning.search.repair import Repaired, fitting, repair
from core.planning.search.solver_input import routing_input
from core.routing.effort import Effort, SearchEnd, combined
from core.routing.vrp import solve_routes

#: Share of the work the first solve has; each re-solve after a failed verification has
#: :data:`RESOLVE_SHARE`, at most :data:`MAX_RESOLVES` times (a re-solve starts from the
#: routes that held: a little work goes far; work kept for re-solves a day never needs is
#: time its limit leaves unused).
FIRST_SOLVE_SHARE = 0.9
RESOLVE_SHARE = 0.025
MAX_RESOLVES = 4
#: With chargers: the first solve's share, and the charging search's (0.1 / 0.75 brought r201
#: and rc201 0.4 % and 0.1 % nearer the best known, rc101 0.3 %, but the Vienna probe from 2
#: vans to 3: its first solve is also the start the charging search falls back on); 0.6 of
#: the charging search's answers on E-VRPTW came after half the limit (0.7: 40–50 s of 60).
#: 0.25 / 0.7 left a twentieth of the work to nothing; 0.2 / 0.8: the Vienna day still 2
#: vans at 30, 45 and 60 s (452.1, 433.9, 444.4 km against 438.1, 451.7, 445.0: within its
#: swing with the start).
CHARGING_FIRST_SHARE = 0.2
CHARGING_SHARE = 0.8

#: A tightened energy budget is cut this much below the simulated need, so the next
#: solution does not land on the edge again.
TIGHTEN_MARGIN = 0.98
#: Stops whose arcs are driven before the first solve to learn the simulation's driving times.
CALIBRATION_STOPS = 12
#: Time each solve leaves before the deadline for simulating its routes, per stop, at least
#: [s]: the verification of 1,000 stops on 118 routes took 5.1 s on the reference machine
#: (R1_10_1); more when a sample route simulated before the search says this machine, under
#: its present load, is slower (:func:`verification_reserve_s`).
VERIFY_RESERVE_S_PER_STOP = 0.008
#: Time kept before the deadline, per stop, for what follows the search: the answer built
#: from the routes (1,000 stops' JSON took 0.5–0.8 s) [s].
ANSWER_RESERVE_S_PER_STOP = 0.002
#: Time past the deadline a stop left out may still be given to an idle van [s] (a
#: simulation of a round of one stop takes milliseconds): on a slow machine the charging
#: search and its verification end a few tenths of a second late, and an answer that much
#: late beats one that leaves a stop out with vans standing idle (E-VRPTW's r107: 99 of 100
#: stops, 13 of 25 vans idle).
IDLE_GRACE_S = 0.5
#: Stops of that sample route, and how often it is timed (the quickest counts: a pause of
#: the process — its garbage collector, another process — once made a 25-stop day's reserve
#: three times its due and cut its search at 60 % of its limit).
SAMPLE_STOPS = 8
SAMPLE_RUNS = 2
#: The reserve per stop as a multiple of the sample's time per stop (routes differ).
VERIFY_RESERVE_FACTOR = 1.5


@dataclass(frozen=True)
class Routed:
    """What a search found: the verified routes, the stops left out, the rounds of
    verification, the objective's estimated value over the routes, and what the answer must
    say of them (a van under way that cannot reach the depot with its reserve)."""

    routes: list[FleetRoute]
    unassigned: list[Unassigned]
    verification_rounds: int
    objective_value: float
    warnings: list[str] = field(default_factory=list)
    ended: SearchEnd = "work"

    def stamped(self, runtime_s: float) -> list[FleetRoute]:
        """The routes with the search's whole run time [s] and how it stopped on each plan
        (a fleet's search proves nothing: feasible)."""
        return [
            replace(
                r,
                plan=replace(
                    r.plan,
                    solved=r.plan.solved.model_copy(
                        update={"runtime_s": runtime_s, "stopped_by": self.ended, "proven": ()}
                    ),
                ),
            )
            for r in self.routes
        ]


def calibrate(day: FleetDay, times: LearnedTimes) -> None:
    """Drive a sample of arcs as the simulation will (out of the depot, and on to each
    sampled stop's nearest neighbour) and learn their times before the first solve. A client's
    matrix is driven as it says."""
    if day.scene.legs.source == "client":
        return
    reachable = [k for k in day.stop_nodes if k not in day.unreachable]
    sample = reachable[:: max(len(reachable) // CALIBRATION_STOPS, 1)][:CALIBRATION_STOPS]
    arcs = []
    for k in sample:
        arcs.append((0, k))
        onward = np.where(day.finite[k], day.duration_s[k], np.inf)
        onward[[0, k]] = np.inf
        if np.isfinite(onward).any():
            arcs.append((k, int(np.argmin(onward))))
    problem, places = day.shifts[0].problem, day.scene.places
    driven = []
    for i, j in arcs:
        road = (
            leg_roads(day.router, places, [i, j])[0]
            if day.router is not None and day.scene.legs.source == "osrm"
            else None
        )
        driven.append(((i, j), drive_time_s(problem, day.scene.legs, i, j, road)))
    times.learn(driven)


def verification_reserve_s(day: FleetDay) -> float:
    """Time to keep before the deadline for simulating the routes a solve finds [s]: every
    stop of the day at :data:`VERIFY_RESERVE_FACTOR` times the time per stop of a sample
    route's simulation, timed now — so a slower or busier machine keeps more."""
    sample = [k for k in day.stop_nodes if k not in day.unreachable][:SAMPLE_STOPS]
    if not sample:
        return 0.0
    timed = []
    for _ in range(SAMPLE_RUNS):  # the quicker: one run may meet a pause of the process
        started = time.perf_counter()
        day.simulate(day.vans[0], sample)
        timed.append(time.perf_counter() - started)
    per_stop_s = min(timed) / len(sample) * VERIFY_RESERVE_FACTOR
    return max(per_stop_s, VERIFY_RESERVE_S_PER_STOP) * len(day.stop_nodes)


def _failure(day: FleetDay, v: int, result: PlanResult) -> Failure | None:
    shift = day.shifts[v]
    return route_failure(
        shift.id, shift.problem, day.scene.places, result, shift.end, shift.battery_enforced
    )


def _tightened(budget_j: float | None, result: PlanResult) -> float | None:
    """A van's energy budget after its simulation ran below the reserve: cut by the share of
    the capacity it would have needed."""
    if budget_j is None:
        return None
    battery = result.battery
    need = max(battery.required_capacity_kwh, 1e-9)
    return budget_j * min(battery.usable_capacity_kwh / need, 1.0) * TIGHTEN_MARGIN


def _repair(day: FleetDay, v: int, route: list[int], failure: Failure) -> Repaired:
    """Van ``v``'s route stripped of stops until its simulation holds."""

    def simulate(stops: list[int]) -> PlanResult:
        return day.simulate(v, stops)

    def check(_stops: list[int], result: PlanResult) -> Failure | None:
        return _failure(day, v, result)

    return repair(route, failure, simulate, check, day.estimates[v])


def _short_home(day: FleetDay, v: int, results: dict[int, PlanResult]) -> bool:
    """Whether van ``v`` is under way and runs below its reserve even on its way home (the
    one route a fleet reports below its reserve: the van is where it is)."""
    return bool(day.starts[v]) and v in results and not results[v].battery.feasible


def _stranded(day: FleetDay, v: int, result: PlanResult) -> str:
    shift = day.shifts[v]
    served = f"with its {len(result.stops)} stops" if result.stops else "with no stop"
    return (
        f"{shift.id} is under way with too little charge: {served}, its drive back to the depot "
        f"takes the battery to {result.battery.min_soc:.0%}, below its reserve of "
        f"{shift.problem.van.battery.min_soc:.0%} (it needs a charge on the way)"
    )


def _idle_given(
    day: FleetDay,
    rules: Feasibility,
    routes: list[list[int]],
    results: dict[int, PlanResult],
    effort: Effort,
    ends: list[SearchEnd],
) -> dict[int, Failure]:
    """:func:`_given_to_idle` until ``effort``'s deadline less the answer's reserve and
    :data:`IDLE_GRACE_S` more, a cut said in ``ends``: the stops it refused."""
    answer_s = ANSWER_RESERVE_S_PER_STOP * len(day.stop_nodes)
    refused, cut = _given_to_idle(
        day, rules, routes, results, effort.keeping(answer_s - IDLE_GRACE_S)
    )
    if cut:
        ends.append("time_limit")
    return refused


def _given_to_idle(
    day: FleetDay,
    rules: Feasibility,
    routes: list[list[int]],
    results: dict[int, PlanResult],
    effort: Effort,
) -> tuple[dict[int, Failure], bool]:
    """Each stop left out that a van without a route serves on a round of its own goes to
    that van, or joins a round given to an idle van here where it holds (a few stops the
    charging verification took out make one round, not a van each); ``routes`` and
    ``results`` change in place. First by the estimates, then by the simulation. No stop
    stays out for a window or the fleet's being full while an idle van could take it; where
    the simulation refuses the round of its own, its failure is why (returned by stop). One
    simulation per stop and kind of idle van, and one per round it may join; none once
    ``effort``'s deadline has passed (then also returned true: the time limit cut it short)."""
    kinds = [_kind(day, v) for v in day.vans]
    served = {node for route in routes for node in route}
    refused: dict[int, Failure] = {}
    given: list[int] = []  # the idle vans given stops here: the next stop joins one if it can
    watch = effort.watch()
    for k, node in enumerate(day.stop_nodes):
        if node in served or node in day.unreachable:
            continue
        if watch.passed(k):
            return refused, True
        if any(_joined(day, v, node, routes, results) for v in given if day.may_serve(v, node)):
            refused.pop(node, None)
            continue
        tried: set[str] = set()
        for v in day.vans_for(node):
            if routes[v] or kinds[v] in tried or rules.alone(v, node) is not None:
                continue
            tried.add(kinds[v])
            result = day.simulate(v, [node])
            failure = _failure(day, v, result)
            if failure is None:
                routes[v], results[v] = [node], result
                given.append(v)
                refused.pop(node, None)
                break
            refused[node] = replace(failure, node=node)
    return refused, False


def _joined(
    day: FleetDay, v: int, node: int, routes: list[list[int]], results: dict[int, PlanResult]
) -> bool:
    """``node`` added to van ``v``'s route where it lengthens the driving least (by the
    matrix's times), kept when the simulation holds (``routes`` and ``results`` changed in
    place)."""
    order = day.order(v, routes[v])
    times = day.duration_s
    added = [
        times[order[k], node] + times[node, order[k + 1]] - times[order[k], order[k + 1]]
        for k in range(len(order) - 1)
    ]
    k = int(np.argmin(added))
    route = [*routes[v][:k], node, *routes[v][k:]]
    result = day.simulate(v, route)
    if _failure(day, v, result) is not None:
        return False
    routes[v], results[v] = route, result
    return True


def _kind(day: FleetDay, v: int) -> str:
    """What makes van ``v``'s round of its own what it is: the van, its shift, its start."""
    shift = day.shifts[v]
    problem = shift.problem
    rules = (problem.breaks, problem.max_trips, problem.reload_minutes, problem.start_state)
    return f"{problem.van.model_dump_json()}|{shift.start}|{shift.end}|{day.starts[v]}|{rules}"


def _simulated(
    day: FleetDay,
    routes: list[list[int]],
    before: dict[int, tuple[list[int], PlanResult]],
    times: LearnedTimes,
) -> dict[int, tuple[list[int], PlanResult]]:
    """Each van's route and its simulated day: a route as it was ``before`` keeps its day
    (the simulation depends on the route alone), a new one is simulated and teaches ``times``
    the times it drove — so verification scales with the routes that changed."""
    out: dict[int, tuple[list[int], PlanResult]] = {}
    for v, route in enumerate(routes):
        if not route:
            continue
        if v in before and before[v][0] == route:
            out[v] = before[v]
            continue
        result = day.simulate(v, route)
        times.learn(traced_seconds(day.order(v, route), result))
        out[v] = (list(route), result)
    return out


def _unassigned(
    rules: Feasibility, routes: list[list[int]], left_out: dict[int, Failure]
) -> list[Unassigned]:
    """Each stop no route serves, with why (:func:`core.planning.search.explain.explain`)."""
    served = {node for route in routes for node in route}
    return [
        explain(rules, node, left_out.get(node), routes)
        for node in rules.day.stop_nodes
        if node not in served
    ]


def search(
    day: FleetDay, minimize_vehicles: bool, effort: Effort, charging: bool = False
) -> Routed:
    """Solve and verify until every route holds or :data:`MAX_RESOLVES` re-solves are spent,
    each solve its share of ``effort``'s work; ``minimize_vehicles``: fewer vans first, then
    the objective. With ``charging`` and stops then left out for their battery (or fewer vans
    first), the fleet is planned again with charges between stops
    (:mod:`core.planning.search.charging.fleet_charging`)."""
    times = LearnedTimes(day.duration_s, day.finite, day.horizon_s)
    calibrate(day, times)
    # a limit too short for the verification's reserve still leaves the search half of it
    reserve_s = min(verification_reserve_s(day), effort.left_s() / 2)
    share = CHARGING_FIRST_SHARE if charging else FIRST_SOLVE_SHARE
    solved = _solved(day, times, minimize_vehicles, (effort, share), reserve_s, not charging)
    routes, results, ends = solved.routes, solved.results, solved.ends
    left_out: dict[int, Failure] = {}
    for v, failure in solved.failures.items():
        repaired = _repair(day, v, routes[v], failure)
        routes[v] = repaired.route
        left_out |= repaired.removed
        if repaired.result is None:
            results.pop(v, None)
        else:
            results[v] = repaired.result
    rules = Feasibility(day, times.matrix(), solved.budgets)
    if charging and minimize_vehicles:  # charging may let fewer vans serve it all
        routes, results, unassigned = _charged(
            day, rules, (routes, results, left_out), minimize_vehicles, effort, reserve_s, ends
        )
    else:
        left_out |= _idle_given(day, rules, routes, results, effort, ends)
        unassigned = _unassigned(rules, routes, left_out)
        if charging and any(u.reason == "battery" for u in unassigned):
            routes, results, unassigned = _charged(
                day, rules, (routes, results, left_out), minimize_vehicles, effort, reserve_s, ends
            )
    for v in day.vans:  # a van under way with no stop left drives back to the depot
        if day.starts[v] and not routes[v]:
            results[v] = day.simulate(v, [])
    return Routed(
        warnings=[_stranded(day, v, results[v]) for v in day.vans if _short_home(day, v, results)],
        routes=[
            FleetRoute(day.shifts[v].id, results[v])
            for v in day.vans
            if (routes[v] or day.starts[v]) and v in results
        ],
        unassigned=unassigned,
        verification_rounds=solved.rounds,
        objective_value=sum(day.estimates[v].route_cost(r) for v, r in enumerate(routes) if r),
        ended=combined(ends),
    )


@dataclass
class _Solved:
    """The routes of the solves and their simulated days, the rules they still break, the
    energy budgets they were searched with, how many solves and how each stopped."""

    routes: list[list[int]]
    results: dict[int, PlanResult]
    failures: dict[int, Failure]
    budgets: list[float | None]
    rounds: int
    ends: list[SearchEnd]


def _solved(
    day: FleetDay,
    times: LearnedTimes,
    minimize_vehicles: bool,
    effort: tuple[Effort, float],
    reserve_s: float,
    polish: bool = True,
) -> _Solved:
    """Solve (the first with its share of ``effort``'s work, re-solves
    :data:`RESOLVE_SHARE`), simulate
    each route, and solve again from the routes that held with the budgets of those that ran
    short made smaller, until every route holds or :data:`MAX_RESOLVES` re-solves are spent.
    ``polish``: routes over an energy budget go to OR-Tools (not where charging follows: the
    charging search plans them again, and OR-Tools, counted by its solutions, once took the
    whole limit there)."""
    whole, first_share = effort
    budgets = [
        e.budget_j if shift.battery_enforced else None
        for shift, e in zip(day.shifts, day.estimates, strict=True)
    ]
    routes: list[list[int]] = [[] for _ in day.vans]
    failures: dict[int, Failure] = {}
    initial: list[list[int]] | None = None
    simulated: dict[int, tuple[list[int], PlanResult]] = {}
    ends: list[SearchEnd] = []
    rounds = 0
    watch = whole.keeping(reserve_s).watch()
    while rounds <= MAX_RESOLVES:
        if rounds and watch.passed(rounds):
            ends.append("time_limit")
            break
        rules = Feasibility(day, times.matrix(), budgets)
        share = RESOLVE_SHARE if rounds else first_share
        outcome = solve_routes(
            routing_input(rules, minimize_vehicles),
            whole.share(share).keeping(reserve_s),
            initial,
            polish,
        )
        rounds += 1
        ends.append(outcome.ended if outcome is not None else "work")
        # a re-solve that found nothing (out of time) keeps the routes that held before it
        kept = initial if initial is not None else [[] for _ in day.vans]
        routes = outcome.routes if outcome is not None else kept
        simulated = _simulated(day, routes, simulated, times)
        failures = {
            v: failure
            for v, (_, result) in simulated.items()
            if (failure := _failure(day, v, result)) is not None
        }
        if not failures:
            break
        for v in failures:
            if failures[v].reason == "battery":
                budgets[v] = _tightened(budgets[v], simulated[v][1])
        rules = Feasibility(day, times.matrix(), budgets)
        initial = [fitting(rules, v, r) if v in failures else r for v, r in enumerate(routes)]
    results = {v: result for v, (_, result) in simulated.items()}
    return _Solved(routes, results, failures, budgets, rounds, ends)


def _charged(
    day: FleetDay,
    rules: Feasibility,
    found: tuple[list[list[int]], dict[int, PlanResult], dict[int, Failure]],
    minimize_vehicles: bool,
    effort: Effort,
    reserve_s: float,
    ends: list[SearchEnd],
) -> tuple[list[list[int]], dict[int, PlanResult], list[Unassigned]]:
    """The fleet planned again with charges between stops and returns to reload
    (:mod:`core.planning.search.charging.fleet_charging`) from the routes ``found`` without (and the
    stops they left out, why), a stop its verification left out given to an idle van as
    without charging (:func:`_given_to_idle`); kept when it does better than the routes
    found — those then given the stops they left out where idle vans can take them, if not
    yet (with fewer vans first, a van each for stops charging serves would be time the
    charging search does not have). A stop still left out for its battery says that charging
    was tried."""
    routes, results, left_out = found
    charged = charging_routes(
        day,
        rules.travel_s,
        (routes, results),
        minimize_vehicles,
        effort.share(CHARGING_SHARE).keeping(reserve_s),
    )
    ends.append(charged.ended)
    removed = charged.removed | _idle_given(
        day, rules, charged.routes, charged.results, effort, ends
    )
    if measure(day, charged.routes, charged.results, minimize_vehicles) < measure(
        day, routes, results, minimize_vehicles
    ):
        routes, results, left_out = charged.routes, charged.results, removed
    elif minimize_vehicles:  # not given yet (search)
        left_out = left_out | _idle_given(day, rules, routes, results, effort, ends)
    said = "charging did not let a van serve it either (no charger within reach, or no time for "
    said += "the charge)"
    return (
        routes,
        results,
        [
            u.model_copy(update={"detail": f"{u.detail}; {said}"}) if u.reason == "battery" else u
            for u in _unassigned(rules, routes, left_out)
        ],
    )
