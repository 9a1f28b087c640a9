"""Charging in a fleet: the summer day's 40 stops (tests/core/planning/day/test_recharge.py) that
one 40 kWh van leaves half of for its battery are all served with a charger on the way, the
EU break kept; vans that charge at one charge point never charge at once; the bookings say
when a charger is full."""

from __future__ import annotations

import datetime as dt
import itertools
import math
from dataclasses import replace

import numpy as np
import pytest

from core.params import BatteryParams, ChargePoint, Charger, Depot, Stop, TimeWindow
from core.planning.day.timeline import MAX_DRIVING_S
from core.planning.day.verify import Failure
from core.planning.fleet.planner import plan_fleet
from core.planning.model import FleetProblem, FleetVehicle, RoundFields, fields_of
from core.planning.search.charging.fleet_charging import (
    BATTERY_MARGIN,
    MIN_BATTERY_MARGIN,
    MIN_TIGHTEN_S,
    MIN_TIGHTEN_SHARE,
    TIGHTEN_MARGIN,
    Bookings,
    Short,
    _tightened,
    battery_margin,
    charging_instance,
)
from core.planning.search.feasibility import Feasibility
from core.planning.search.fleet import _failure, _given_to_idle
from core.routing.effort import Effort
from core.routing.evrp import solve_evrptw
from tests.core.planning.day.test_breaks import driving_between_breaks_s
from tests.core.planning.day.test_recharge import summer_day
from tests.utils.fleets import DEPOT
from tests.utils.fleets import day_of as cluster_day
from tests.utils.fleets import fleet as cluster_fleet
from tests.utils.fleets import two_clusters as clusters
from tests.utils.fleets import van as cluster_van

FAST = Charger(id="hpc-prater", lat=48.215, lon=16.40, power_kw=150, price_per_kwh=0.59)


def fleet(problem, vans, work_s=1.6, shift_end="21:00", **fields) -> FleetProblem:
    """The fleet of ``vans`` on ``problem``'s day with ``work_s`` of search and the time to do
    it on a busy machine (a search the clock cut would give another answer)."""
    return FleetProblem(
        **fields_of(problem, RoundFields) | fields,
        vehicles=[
            FleetVehicle(id=f"van-{k}", shift_start="07:00", shift_end=shift_end, van=van)
            for k, van in enumerate(vans)
        ],
        time_limit_s=60 * work_s,
        work_s=work_s,
    )


@pytest.fixture(scope="module")
def one_van():
    day = summer_day(None)
    # 5 s of work tries the stops left out with charging 50 times
    charged = fleet(day, [day.van], chargers=[FAST], work_s=5)
    return plan_fleet(fleet(day, [day.van])), plan_fleet(charged)


@pytest.mark.slow
def test_the_stops_a_battery_left_out_are_served_with_a_charger(one_van):
    without, charged = one_van
    left = [u for u in without.unassigned if u.reason == "battery"]
    assert len(left) >= 10
    served = {s.id for r in charged.routes for s in r.plan.stops}
    assert len(served) >= 40 - len(without.unassigned) + 10
    assert {u.id for u in left} & served
    (route,) = charged.routes
    plan = route.plan
    assert plan.charges and {c.charger_id for c in plan.charges} == {"hpc-prater"}
    # the simulation with the charges in it holds: reserve, shift, the EU break rule
    assert plan.battery.feasible and plan.battery.min_soc >= 0.1
    assert plan.legs[-1].arrive.time() <= dt.time(21, 0)
    # the EU break rule: a break wherever the driving would exceed 4 h 30 without one
    assert max(driving_between_breaks_s(plan)) <= MAX_DRIVING_S + 1
    assert not any("not used" in w for w in charged.warnings)
    for u in charged.unassigned:
        if u.reason == "battery":
            assert "charging did not let a van serve it" in u.detail


def test_a_stop_charging_cannot_save_says_charging_was_tried():
    """A charger 140 km away: the stops the battery leaves out stay out, and each says that
    charging was tried (a dispatcher would otherwise add chargers in vain)."""
    day = summer_day(None)
    far = Charger(id="far-away", lat=49.47, lon=16.40, power_kw=150, price_per_kwh=0.59)
    result = plan_fleet(fleet(day, [day.van], chargers=[far], work_s=1))
    left = [u for u in result.unassigned if u.reason == "battery"]
    assert len(left) >= 10
    assert all("charging did not let a van serve it" in u.detail for u in left)
    assert not any(r.plan.charges for r in result.routes)


def two_clusters() -> FleetProblem:
    """Two vans of 10 kWh until 14:00, 12 stops 10 km out east and 12 west (8 min each):
    one van cannot serve them all in its shift, and each needs charges at the depot's
    one-point charger."""
    rng = np.random.default_rng(5)
    stops = [
        Stop(
            id=f"{side}{k}",
            lat=48.21 + rng.uniform(-0.02, 0.02),
            lon=16.37 + sign * (0.135 + rng.uniform(-0.02, 0.02)),
            service_time_s=480,
            door_open_s=120,
        )
        for side, sign in (("E", 1), ("W", -1))
        for k in range(12)
    ]
    day = summer_day(None)
    van = day.van.model_copy(update={"battery": BatteryParams(usable_capacity_kwh=10.0)})
    depot = Depot(id="depot", lat=48.21, lon=16.37, charger=ChargePoint(power_kw=22, points=1))
    base = day.model_copy(update={"stops": stops, "depot": depot})
    return fleet(base, [van, van], work_s=5, shift_end="14:00", minimize_vehicles=False)


@pytest.mark.slow
def test_vans_at_a_one_point_charger_never_charge_at_once():
    result = plan_fleet(two_clusters())
    plug = dt.timedelta(minutes=2)  # the default plug_minutes
    charging = [
        (c.depart - dt.timedelta(minutes=c.minutes) - plug, c.depart)  # plugged in
        for r in result.routes
        for c in r.plan.charges
    ]
    assert len({r.vehicle_id for r in result.routes if r.plan.charges}) == 2
    charging.sort()
    for (_, ends), (begins, _) in itertools.pairwise(charging):
        # the second waits (or charges later) while the first is plugged in
        assert begins >= ends - dt.timedelta(seconds=1)


def test_bookings_say_when_every_point_is_taken():
    moment = dt.datetime(2026, 7, 15, 9, tzinfo=dt.UTC)

    def at(minutes: float) -> dt.datetime:
        return moment + dt.timedelta(minutes=minutes)

    one, two = ChargePoint(power_kw=50, points=1), ChargePoint(power_kw=50, points=2)
    bookings = Bookings({0: one, 5: two})
    bookings.spans = {
        0: [(at(0), at(30), "a"), (at(60), at(90), "b")],
        5: [(at(0), at(30), "a"), (at(10), at(50), "b"), (at(40), at(70), "c")],
    }
    busy = bookings.busy("z")
    assert busy[0] == [(at(0), at(30)), (at(60), at(90))]
    assert busy[5] == [(at(10), at(30)), (at(40), at(50))]  # both points taken
    # a van's own charges do not block it
    assert bookings.busy("a")[0] == [(at(60), at(90))]
    assert bookings.busy("b")[5] == []


def test_a_stop_the_charging_verification_left_out_goes_to_an_idle_van(monkeypatch):
    """The charging search's verification takes a stop out of a route (here: made to): a van
    with no route serves it on a round of its own, as it would without charging, and the
    fleet serves every stop rather than fall back on the routes found without charging (vans
    of 5 kWh: a cluster of three takes 3.3 kWh, all six 7.8 kWh; the second van's shift,
    08:00–08:30, leaves it time for one stop — without charging the two serve four)."""
    import core.planning.search.fleet as planner

    searched = planner.charging_routes
    dropped: list[str] = []

    def dropping(day, *args, **kwargs):
        found = searched(day, *args, **kwargs)
        v = max((v for v, r in enumerate(found.routes) if r), key=lambda v: len(found.routes[v]))
        node = found.routes[v][-1]
        dropped.append(day.scene.places[node].id)
        routes = [list(r) for r in found.routes]
        routes[v] = routes[v][:-1]
        kept = found.results[v].itinerary.keeping(set(routes[v]))  # its charges where they were
        results = dict(found.results) | {v: day.charged(v, kept, {})}
        removed = {node: Failure("battery", node, "made to fail")}
        return replace(found, routes=routes, results=results, removed=removed)

    monkeypatch.setattr(planner, "charging_routes", dropping)
    stops, matrix = clusters()
    depot = DEPOT.model_copy(update={"charger": ChargePoint(power_kw=22, points=2)})
    small = BatteryParams(usable_capacity_kwh=5.0)
    problem = cluster_fleet(
        stops,
        [cluster_van("van-0", battery=small), cluster_van("van-1", end="08:30", battery=small)],
        matrix=matrix,
        minimize_vehicles=True,
        time_limit_s=120,  # the work, not a busy machine's clock, ends the search
        work_s=2,
    )
    result = plan_fleet(problem.model_copy(update={"depot": depot}))
    (stop,) = dropped
    assert not result.unassigned
    charged, alone = result.routes
    assert [s.id for s in alone.plan.stops] == [stop] and alone.vehicle_id == "van-1"
    assert len(charged.plan.stops) == 5 and charged.plan.charges
    assert all(r.plan.battery.feasible for r in result.routes)


def test_each_kind_of_van_charges_along_its_own_curve_in_the_search():
    """A van that takes 11 kW and one that takes 150 kW at the same 150 kW charger: the
    search charges each joule in its own time — 150 / 11 as long for the slow one, from
    the reserve to 80 % where both curves are flat (the charging curve's constant part)."""
    stops, matrix = clusters()
    depot = DEPOT.model_copy(update={"charger": ChargePoint(power_kw=150, points=2)})
    slow = BatteryParams(usable_capacity_kwh=40.0, max_charge_power_kw=11.0)
    fast = BatteryParams(usable_capacity_kwh=40.0, max_charge_power_kw=150.0)
    problem = cluster_fleet(
        stops,
        [cluster_van("slow", battery=slow), cluster_van("fast", battery=fast)],
        matrix=matrix,
    ).model_copy(update={"depot": depot})
    instance = charging_instance(cluster_day(problem), cluster_day(problem).duration_s, True)
    (station,) = instance.instance.stations
    kinds = {
        problem.vehicles[vans[0]].id: instance.instance.charge_time_of(k)[station]
        for k, vans in enumerate(instance.vans_of)
    }
    assert kinds["slow"] / kinds["fast"] == pytest.approx(150 / 11, rel=1e-6)
    # a joule at 150 kW takes 1 / 150,000 s (stored at the charging efficiency)
    assert kinds["fast"] == pytest.approx(1 / 150_000 / fast.charging_efficiency, rel=1e-6)


def test_the_search_plans_with_the_share_of_the_battery_the_estimates_earned():
    """The routes found without charging, simulated, say how far the estimates fall short:
    the charging search plans with their estimated over their drawn energy, together (not the
    worst route's share), at most the whole battery, at least MIN_BATTERY_MARGIN;
    BATTERY_MARGIN when no route says."""
    stops, matrix = clusters()
    day = cluster_day(cluster_fleet(stops, [cluster_van("a"), cluster_van("b")], matrix=matrix))
    routes = [[1, 2, 3], [4, 5, 6]]
    results = {v: day.simulate(v, route) for v, route in enumerate(routes)}
    estimated_kwh = drawn_kwh = 0.0
    for v, route in enumerate(routes):
        result = results[v]
        drawn_kwh += (result.legs[0].soc_start - result.battery.final_soc) * (
            result.battery.usable_capacity_kwh
        )
        estimated_kwh += day.estimates[v].route_energy_j(route) / 3.6e6
    assert battery_margin(day, routes, results) == pytest.approx(
        min(max(estimated_kwh / drawn_kwh, MIN_BATTERY_MARGIN), 1.0)
    )
    # the summer day's standing loads drawn while parked: the estimates fall a little short
    assert MIN_BATTERY_MARGIN < battery_margin(day, routes, results) < 1.0
    assert battery_margin(day, [[], []], {}) == BATTERY_MARGIN
    # a route that reloads says nothing of one trip's estimate
    assert battery_margin(day, [[1, 0, 2], []], {0: results[0]}) == BATTERY_MARGIN


def test_a_route_short_of_energy_or_late_tightens_its_kind_for_the_next_search():
    """What the simulation says a route fell short by goes back to the search, with margin:
    1.2 × a shortfall of 2 kWh off the battery and the charge at departure; a rounding below
    the reserve (1 J) or a minute late still moves the search (1 % of the battery, 5 min)."""
    stops, matrix = clusters()
    problem = cluster_fleet(stops, [cluster_van("a"), cluster_van("b")], matrix=matrix)
    problem = problem.model_copy(
        update={"depot": DEPOT.model_copy(update={"charger": ChargePoint(power_kw=22)})}
    )
    day = cluster_day(problem)
    instance = charging_instance(day, day.duration_s, True).instance
    (kind,) = instance.kinds  # two vans alike: one kind
    two_kwh = 2 * 3.6e6
    less = _tightened(instance, Short(energy_j={0: two_kwh})).kinds[0]
    assert kind.battery - less.battery == pytest.approx(TIGHTEN_MARGIN * two_kwh)
    assert kind.initial - less.initial == pytest.approx(TIGHTEN_MARGIN * two_kwh)
    assert less.due == kind.due
    rounding = _tightened(instance, Short(energy_j={0: 1.0}, late_s={0: 60.0})).kinds[0]
    assert kind.battery - rounding.battery == pytest.approx(MIN_TIGHTEN_SHARE * kind.battery)
    assert kind.due - rounding.due == pytest.approx(MIN_TIGHTEN_S)
    late = _tightened(instance, Short(late_s={0: 1200.0})).kinds[0]
    assert kind.due - late.due == pytest.approx(TIGHTEN_MARGIN * 1200.0)
    assert late.battery == kind.battery
    assert not Short() and Short(late_s={0: 1.0})


def test_the_search_knows_each_chargers_points_and_opening_hours():
    """Two vans, the depot's charger of one point and a charger on the way of two, open
    10:00–12:00 and 14:00–16:00: the search shares the depot's one point (the way's two are
    as many as the vans: never short) and takes no charge on the way outside its hours, in
    seconds after the first departure (08:00)."""
    stops, _ = clusters()
    hours = [TimeWindow(start="10:00", end="12:00"), TimeWindow(start="14:00", end="16:00")]
    way = Charger(id="way", lat=48.2, lon=16.45, power_kw=50, points=2, opening_hours=hours)
    depot = DEPOT.model_copy(update={"charger": ChargePoint(power_kw=22, points=1)})
    problem = cluster_fleet(stops, [cluster_van("a"), cluster_van("b")], chargers=[way])
    day = cluster_day(problem.model_copy(update={"depot": depot}))
    charging = charging_instance(day, day.duration_s, True)
    (at_depot,) = [q for q in charging.instance.stations if charging.place_of[q] == 0]
    (on_way,) = [q for q in charging.instance.stations if charging.place_of[q] != 0]
    assert charging.instance.points == {at_depot: 1}
    h = 3600.0
    assert charging.instance.closed == {
        on_way: [(-math.inf, 2 * h), (4 * h, 6 * h), (8 * h, math.inf)]
    }


def test_stops_left_out_share_one_idle_van_where_its_round_holds():
    """Two stops of the east cluster left out beside a route of the rest: the first goes
    to an idle van, the second joins its round (a van each would be a van more for nothing);
    the third van stays idle."""
    stops, matrix = clusters()
    problem = cluster_fleet(stops, [cluster_van(f"van-{k}") for k in range(3)], matrix=matrix)
    day = cluster_day(problem)
    routes: list[list[int]] = [[4, 5, 6, 2], [], []]  # the west cluster and one of the east
    results = {0: day.simulate(0, routes[0])}
    budgets = [day.estimates[v].budget_j for v in day.vans]
    rules = Feasibility(day, day.duration_s.astype(np.int64), budgets)
    plenty = Effort.starting_now(1.0, 60.0)
    refused, cut = _given_to_idle(day, rules, routes, results, plenty)  # 1 and 3 left out
    assert not refused and not cut
    assert sorted(routes[1]) == [1, 3] and routes[2] == []
    assert _failure(day, 1, results[1]) is None  # its simulation holds
    # past the search's deadline nothing more is tried, and it says the time limit cut it
    routes = [[4, 5, 6, 2], [], []]
    over = Effort.starting_now(1.0, 0.0)
    refused, cut = _given_to_idle(day, rules, routes, {0: results[0]}, over)
    assert cut and not refused and routes[1] == routes[2] == []


@pytest.mark.parametrize(
    ("breaks", "kept_off_s"),
    [
        ("eu-561", 45 * 60.0),  # a 9 h shift: room for one 4 h 30 of driving and its break
        ("none", 0.0),
        ([{"earliest": "11:00", "latest": "13:00", "minutes": 30}], 30 * 60.0),
    ],
)
def test_the_search_keeps_the_drivers_breaks_off_its_latest_return(breaks, kept_off_s):
    """The search does not place breaks (the simulation does): a route it plans to the end of
    the shift would come back late for them, so its latest return leaves them room."""
    stops, matrix = clusters()
    van = FleetVehicle.model_validate(cluster_van("a").model_dump() | {"breaks": breaks})
    problem = cluster_fleet(stops, [van], matrix=matrix)
    day = cluster_day(problem)
    (kind,) = charging_instance(day, day.duration_s, True).instance.kinds
    assert kind.due == pytest.approx(day.shift_s[0][1] - kept_off_s)
    assert day.shift_s[0][1] - day.shift_s[0][0] == 9 * 3600.0


@pytest.mark.parametrize("minimize_vehicles", [True, False])
def test_with_fewer_vans_first_the_charging_search_starts_before_idle_vans_take_stops(
    monkeypatch, minimize_vehicles
):
    """With fewer vans first, the charging search plans every stop again: the stops the routes
    found without charging left out are not first given an idle van each (on E-VRPTW's r107,
    28 stops took 5 s of the 60 and left the charging search none to give its last stop to an
    idle van); they are, after it, if its routes do no better. Distance first: idle vans take
    them first, and charging follows only for stops still out for their battery."""
    import core.planning.search.fleet as planner

    events: list[str] = []

    def spied(real, event):
        def call(*args, **kwargs):
            events.append(event)
            return real(*args, **kwargs)

        return call

    for name, event in (("charging_routes", "charging"), ("_given_to_idle", "idle")):
        monkeypatch.setattr(planner, name, spied(getattr(planner, name), event))
    day = summer_day(None)
    problem = fleet(
        day, [day.van, day.van], chargers=[FAST], work_s=1, minimize_vehicles=minimize_vehicles
    )
    result = plan_fleet(problem)
    if minimize_vehicles:
        assert events[:2] == ["charging", "idle"]
    else:
        assert events[0] == "idle"
    assert all(r.plan.battery.feasible for r in result.routes)


def test_when_the_first_charging_search_holds_its_rounds_work_searches_on_from_it(monkeypatch):
    """The work kept for searching again with a smaller battery is not left unspent when the
    first search's routes hold: a second search starts from those routes alone (not from
    PyVRP's again) with that work, and the answer is the better verified."""
    import core.planning.search.charging.fleet_charging as charging

    calls = []

    def spied(instance, effort, initial=None, own=True):
        solution = solve_evrptw(instance, effort, initial, own)
        calls.append((effort.work_s, initial, own, solution))
        return solution

    monkeypatch.setattr(charging, "solve_evrptw", spied)
    day = summer_day(None)
    result = plan_fleet(fleet(day, [day.van], chargers=[FAST], work_s=1))
    (first_s, _, first_own, first), (rest_s, start, own, _) = calls
    assert first_own and not own
    assert start == first.searched and start
    whole_s = first_s / charging.FIRST_SHARE
    assert rest_s == pytest.approx(whole_s * (1 - charging.FIRST_SHARE))
    assert all(r.plan.battery.feasible for r in result.routes)
