"""Routing with recharging stations (core/routing/evrp.py): a route on a line whose charges
and times are worked by hand, a window that charging makes unreachable (and one the way
alone does, screened before the labels), a small instance against every split and order,
and the benchmark command on a shared instance, its answer checked by the rules alone
(testbed/evrptw.py)."""

from __future__ import annotations

import itertools
import json
import math
import subprocess
import sys
from dataclasses import replace
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from core.routing.effort import Effort
from core.routing.evrp import (
    EvrpInstance,
    VehicleKind,
    _Priced,
    _Search,
    _Solution,
    solve_evrptw,
)
from core.routing.stations import (
    NO_ROUTE,
    keeps_windows,
    quickest_durations,
    route_with_stations,
    station_candidates,
)
from testbed.evrptw import FOLDER, check, read

ROOT = Path(__file__).resolve().parents[3]


def instance(
    xy: list[tuple[float, float]],
    kinds: str,
    due: float | np.ndarray = 1000.0,
    capacity: float = 100.0,
    battery: float = 50.0,
    time_per_energy: float = 2.0,
    **changes,
) -> EvrpInstance:
    """Places at ``xy`` (``kinds``: d depot, c customer, f station), unit speed and energy,
    as many vehicles as places."""
    points = np.array(xy, dtype=float)
    distance = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
    n = len(xy)
    vehicles = VehicleKind(
        count=n, energy=distance.copy(), battery=battery, initial=battery, capacity=capacity
    )
    fields = {
        "distance": distance,
        "duration": distance.copy(),
        "ready": np.zeros(n),
        "due": np.full(n, due),
        "service": np.zeros(n),
        "demand": np.array([1.0 if k == "c" else 0.0 for k in kinds]),
        "customers": [i for i, k in enumerate(kinds) if k == "c"],
        "stations": [i for i, k in enumerate(kinds) if k == "f"],
        "charge_time": np.full(n, time_per_energy),
        "kinds": [vehicles],
    }
    return EvrpInstance(**(fields | changes))


def on_a_line(**changes) -> EvrpInstance:
    # depot at 0, customer at 40, station at 20; battery 50: 80 there and back needs charging
    return instance([(0, 0), (40, 0), (20, 0)], "dcf", **changes)


def charged(inst: EvrpInstance, route: list[int]):
    return _Priced(inst).charged(0, route)


def test_a_route_on_a_line_charges_what_the_way_to_the_next_charge_takes():
    # D→S: 20 (30 left); S→C→S takes 40: charge 10; C→S leaves 0; S→D takes 20: charge 20.
    # Charging only before the customer cannot do (S→C→D takes 60 > 50); nor only after.
    result = charged(on_a_line(), [1])
    assert result.distance == pytest.approx(80.0)
    assert [(v.place, v.charge) for v in result.visits] == [
        (0, 0.0),
        (2, pytest.approx(10.0)),
        (1, 0.0),
        (2, pytest.approx(20.0)),
        (0, 0.0),
    ]


def test_the_labels_work_is_counted_by_the_stations_looked_at_and_the_places_walked():
    # From the start (battery 50) the customer (40) is reached and its station is looked at
    # (60 > 50: no label); the station before the customer (30 left) reaches the customer, looks
    # at the station after it (a label: the customer walked) and cannot reach the depot (60);
    # from the station after the customer the depot is walked to. Two looks, two places walked.
    priced = _Priced(on_a_line())
    assert priced.charged(0, [1]).distance == pytest.approx(80.0)
    assert priced.steps.tolist() == [2, 2]


def test_a_vehicle_leaving_with_less_charges_more_at_the_first_station():
    # leaving with 30 of 50: D→S leaves 10; S→C→S takes 40: charge 30 (40 ≤ 50 on leaving);
    # S→D takes 20: charge 20. The start charges nothing (no station there).
    inst = on_a_line()
    kind = replace(inst.kinds[0], initial=30.0)
    result = charged(replace(inst, kinds=[kind]), [1])
    assert [(v.place, v.charge) for v in result.visits] == [
        (0, 0.0),
        (2, pytest.approx(30.0)),
        (1, 0.0),
        (2, pytest.approx(20.0)),
        (0, 0.0),
    ]
    # leaving with 15: D→S leaves no room to reach S (20 > 15): no route
    low = replace(inst, kinds=[replace(kind, initial=15.0)])
    assert charged(low, [1]) is NO_ROUTE


def test_a_fleet_too_small_serves_what_it_can_and_says_what_it_left_out():
    # two customers 40 out on either side, a station halfway to each; one vehicle carrying
    # one: it serves one (80 with two charges) and leaves the other out
    inst = instance([(0, 0), (40, 0), (-40, 0), (20, 0), (-20, 0)], "dccff", capacity=1.0)
    one = replace(inst, kinds=[replace(inst.kinds[0], count=1)])
    solution = solve_evrptw(one, Effort.starting_now(0.5, 60.0))
    assert solution.vehicles == 1 and len(solution.left_out) == 1
    assert solution.distance == pytest.approx(80.0)
    both = solve_evrptw(inst, Effort.starting_now(0.5, 60.0))
    assert both.vehicles == 2 and not both.left_out
    assert both.distance == pytest.approx(160.0)


def test_the_same_work_gives_the_same_routes():
    inst = small()
    first, again = (solve_evrptw(inst, Effort(0.3, math.inf, seed=3)) for _ in range(2))
    assert first == again and first.ended == "work"


def test_a_window_that_charging_makes_unreachable_is_no_route():
    # the customer is reached at 20 + 2·10 (charging) + 20 = 60 at the earliest
    due = np.array([1000.0, 60.0, 1000.0])
    assert charged(on_a_line(due=due), [1]).distance == pytest.approx(80.0)
    late = np.array([1000.0, 50.0, 1000.0])
    priced = _Priced(on_a_line(due=late))
    assert priced.charged(0, [1]) is NO_ROUTE
    # the way alone (40) keeps this window: the labels found that charging breaks it
    assert (priced.screened, priced.evaluations) == (1, 1)


def test_a_window_the_way_alone_cannot_keep_is_screened_without_labels():
    # the customer 40 out cannot be reached by 30 however the vehicle charges
    priced = _Priced(on_a_line(due=np.array([1000.0, 30.0, 1000.0])))
    assert priced.charged(0, [1]) is NO_ROUTE
    assert (priced.screened, priced.evaluations) == (1, 0)


def test_the_quickest_way_between_two_places_may_pass_a_station():
    # depot, customer, station: the road straight takes 10, through the station 3 + 4
    duration = np.array([[0.0, 10.0, 3.0], [10.0, 0.0, 4.0], [3.0, 4.0, 0.0]])
    candidates = station_candidates(duration, np.array([2]))
    quickest = quickest_durations(duration, candidates)
    assert quickest[0, 1] == quickest[1, 0] == 7.0
    assert quickest[0, 2] == 3.0 and quickest[2, 1] == 4.0
    # a window closing at 8 is kept through the station, not on the road straight
    due, ready, service = np.array([100.0, 8.0, 100.0]), np.zeros(3), np.zeros(3)
    seq = np.array([0, 1, 0])
    assert keeps_windows(seq, quickest, ready, due, service, 0.0)
    assert not keeps_windows(seq, duration, ready, due, service, 0.0)
    # waiting for a window to open and serving count: ready 6, service 2, back by 14
    assert keeps_windows(seq, quickest, np.array([0, 6.0, 0]), due, np.array([0, 2.0, 0]), 0.0)
    late = np.array([14.0, 8.0, 100.0])
    assert not keeps_windows(seq, quickest, np.array([0, 6.0, 0]), late, np.array([0, 2, 0]), 0.0)


def test_the_screen_never_refuses_a_route_the_labels_find():
    # a day whose roads are quicker through its stations (not metric in time), tight
    # windows: every route of up to five customers the labels find keeps the screen; the
    # screen refuses a good share of the others (else it would test nothing)
    rng = np.random.default_rng(2)
    xy = rng.uniform(-30, 30, (12, 2))
    xy[0] = 0.0
    inst = instance([tuple(p) for p in xy], "dccccccccfff", battery=60.0, time_per_energy=0.5)
    duration = inst.duration.copy()
    duration[:, 9:] *= 0.3  # the ways to and from the stations are fast roads
    duration[9:, :] *= 0.3
    ready = rng.uniform(0, 60, 12)
    inst = replace(inst, duration=duration, ready=ready, due=ready + rng.uniform(10, 60, 12))
    inst.due[0] = 300.0
    priced = _Priced(inst)
    facts = priced.facts[0]
    found = refused = 0
    for _ in range(3000):
        route = [int(c) for c in rng.permutation(inst.customers)[: rng.integers(1, 6)]]
        seq = np.array([0, *route, 0])
        cost, *_ = route_with_stations(facts, seq, priced.candidates, priced.closed)
        kept = keeps_windows(seq, priced.quickest, inst.ready, facts.due, inst.service, 0.0)
        found += math.isfinite(cost)
        refused += not kept
        assert kept or not math.isfinite(cost), route
    assert found > 100 and refused > 1000


def test_each_kind_charges_at_its_own_time_per_energy():
    # the customer at 20 + t·10 + 20: 60 with the instance's 2 per unit, 70 with a kind's 3
    due = np.array([1000.0, 60.0, 1000.0])
    inst = on_a_line(due=due)
    slow = replace(inst.kinds[0], charge_time=np.full(3, 3.0))
    assert charged(inst, [1]).distance == pytest.approx(80.0)
    assert charged(replace(inst, kinds=[slow]), [1]) is NO_ROUTE
    fast = replace(inst.kinds[0], charge_time=np.full(3, 1.0))
    assert charged(
        replace(inst, due=np.array([1000.0, 50.0, 1000.0]), kinds=[fast]), [1]
    ).distance == pytest.approx(80.0)


def test_a_station_closed_when_the_charge_would_start_makes_the_vehicle_wait():
    # open: plugged in 20–40 (10 units at 2 per unit), the customer at 60, again 80–120.
    # Closed 15–35: the charge cannot be done before 35 → 35–55, the customer at 75, again
    # 95–135 (the second charge fits after the closing).
    assert charged(on_a_line(), [1]).plugged_at({2: 1}) == [(2, 20.0, 40.0), (2, 80.0, 120.0)]
    shut = on_a_line(closed={2: [(15.0, 35.0)]})
    assert charged(shut, [1]).plugged_at({2: 1}) == [(2, 35.0, 55.0), (2, 95.0, 135.0)]
    # the customer's window closing at 70 is kept when open, not when closed 15–35
    due = np.array([1000.0, 70.0, 1000.0])
    assert charged(on_a_line(due=due), [1]).distance == pytest.approx(80.0)
    assert charged(on_a_line(due=due, closed={2: [(15.0, 35.0)]}), [1]) is NO_ROUTE
    # closed for good from 100: the second charge (95–135) has no room
    assert charged(on_a_line(closed={2: [(100.0, math.inf)]}), [1]) is NO_ROUTE


def two_at_one_point(due: float, points: int) -> EvrpInstance:
    """Two customers 40 out (one vehicle each: capacity 1), the only station halfway with
    ``points`` points, each customer's window closing at ``due``."""
    inst = instance([(0, 0), (40, 0), (20, 0), (40, 0)], "dcfc", capacity=1.0)
    return replace(
        inst, due=np.array([1000.0, due, 1000.0, due]), points={2: points} if points < 4 else {}
    )


def test_vehicles_at_a_one_point_station_take_turns_in_the_search():
    # each plugged in at 20 for 20 alone; at one point the second waits for the first: 40–60,
    # its customer at 80 — and again on the way back, after the first
    priced = _Priced(two_at_one_point(1000.0, 1))
    first, second = priced.booked([(0, [1]), (0, [3])])
    assert first.plugged_at({2: 1}) == [(2, 20.0, 40.0), (2, 80.0, 120.0)]
    assert second.plugged_at({2: 1}) == [(2, 40.0, 60.0), (2, 120.0, 160.0)]
    # two points: no waiting
    free = _Priced(two_at_one_point(1000.0, 2)).booked([(0, [1]), (0, [3])])
    assert [c.plugged_at({2: 2}) for c in free] == [first.plugged_at({2: 1})] * 2
    # windows closing at 70: one point serves one customer (the second would be there at
    # 80), two serve both
    effort = Effort.starting_now(0.5, 60.0)
    one = solve_evrptw(two_at_one_point(70.0, 1), effort)
    assert one.vehicles == 1 and len(one.left_out) == 1
    two = solve_evrptw(two_at_one_point(70.0, 2), effort)
    assert two.vehicles == 2 and not two.left_out


def test_no_station_within_reach_and_too_much_load_are_no_route():
    far = instance([(0, 0), (40, 0), (0, 60)], "dcf")  # the station is farther than the way
    assert charged(far, [1]) is NO_ROUTE
    assert charged(on_a_line(capacity=0.5), [1]) is NO_ROUTE
    # a route the battery covers needs no station
    near = instance([(0, 0), (20, 0), (10, 0)], "dcf")
    assert [v.place for v in charged(near, [1]).visits] == [0, 1, 0]


SMALL_XY = [(0, 0), (30, 5), (28, -8), (-25, 10), (-30, -12), (5, 32), (15, 0), (-15, 0), (0, 20)]


@cache
def small() -> EvrpInstance:
    """Five customers around a depot, three stations between, windows, load 3 per vehicle."""
    due = np.array([400.0, 120.0, 200.0, 150.0, 260.0, 300.0, 400.0, 400.0, 400.0])
    ready = np.array([0.0, 40.0, 0.0, 0.0, 80.0, 0.0, 0.0, 0.0, 0.0])
    return instance(
        SMALL_XY,
        "dcccccfff",
        due=due,
        ready=ready,
        service=np.array([0.0, 10, 10, 10, 10, 10, 0, 0, 0]),
        capacity=3.0,
        battery=70.0,
        time_per_energy=1.0,
    )


def every_split_and_order(inst: EvrpInstance) -> tuple[int, float]:
    """Fewest vehicles, then least distance, over every split of the customers into routes
    and every order of each route."""
    customers = inst.customers
    best_route: dict[frozenset[int], float] = {}
    for size in range(1, len(customers) + 1):
        for group in itertools.combinations(customers, size):
            best_route[frozenset(group)] = min(
                charged(inst, list(order)).distance for order in itertools.permutations(group)
            )

    @cache
    def best(left: frozenset[int]) -> tuple[int, float]:
        if not left:
            return (0, 0.0)
        first = min(left)
        out = (10**6, math.inf)
        rest = sorted(left - {first})
        for size in range(len(rest) + 1):
            for others in itertools.combinations(rest, size):
                group = frozenset({first, *others})
                if math.isfinite(best_route[group]):
                    vans, distance = best(left - group)
                    out = min(out, (vans + 1, distance + best_route[group]))
        return out

    return best(frozenset(customers))


def test_a_small_instance_is_solved_as_well_as_every_split_and_order_allows():
    inst = small()
    vans, distance = every_split_and_order(inst)
    assert vans < 10**6
    solution = solve_evrptw(inst, Effort.starting_now(2.0, 60.0))
    assert solution.vehicles == vans and solution.ended == "work"
    assert solution.distance == pytest.approx(distance, rel=1e-6)
    routes = [[(v.place, v.charge) for v in route.visits] for route in solution.routes]
    assert check(inst, routes) is None


def test_the_search_starts_from_the_better_of_the_given_routes_and_its_own():
    """Routes found without charging may be poor with it: one customer per vehicle is worse
    than PyVRP's start, so the search starts from PyVRP's and ends where it ends alone."""
    inst = small()
    alone = [(0, [c]) for c in inst.customers]
    effort = Effort(1e-4, math.inf, seed=1)  # no work left after the start
    from_poor = solve_evrptw(inst, effort, alone)
    assert from_poor == solve_evrptw(inst, effort)
    assert from_poor.vehicles < len(alone)


def test_a_search_on_from_given_routes_alone_spends_nothing_on_pyvrp(monkeypatch):
    """``own=False``: the given routes are the only start (no PyVRP, whose share of the work
    goes to the search), and the answer is no worse than them; searched on from its own
    answer, the search keeps what it had."""
    import core.routing.evrp as evrp

    inst = small()
    alone = [(0, [c]) for c in inst.customers]
    first = solve_evrptw(inst, Effort.starting_now(0.05, 60.0), alone, own=False)
    assert first.vehicles < len(alone)
    monkeypatch.setattr(evrp, "_customer_routes", None)  # called: a TypeError
    on = solve_evrptw(inst, Effort.starting_now(0.05, 60.0), first.searched, own=False)
    assert (on.vehicles, on.distance) <= (first.vehicles, first.distance + 1e-9)


def test_a_vehicle_that_may_reload_serves_more_than_one_load():
    """One vehicle of 3 for the five customers of the small instance without windows: with
    a return to reload (a place of the depot's, 5 to reload) and two trips it serves them all,
    no trip over 3; without, one load of three."""
    reload = len(SMALL_XY)
    inst = instance(
        [*SMALL_XY, SMALL_XY[0]],
        "dcccccfffr",
        service=np.array([0.0, 10, 10, 10, 10, 10, 0, 0, 0, 5]),
        capacity=3.0,
        battery=70.0,
        time_per_energy=1.0,
    )
    one = replace(inst.kinds[0], count=1)
    alone = solve_evrptw(replace(inst, kinds=[one]), Effort(0.3, math.inf, seed=1))
    assert len(alone.left_out) == 2
    trips = replace(one, reload=reload, max_trips=2)
    solution = solve_evrptw(replace(inst, kinds=[trips]), Effort(0.3, math.inf, seed=1))
    assert solution.left_out == [] and solution.vehicles == 1
    places = [visit.place for visit in solution.routes[0].visits]
    assert places.count(reload) == 1
    cut = places.index(reload)
    assert max(sum(inst.demand[places[:cut]]), sum(inst.demand[places[cut:]])) <= 3.0


def test_the_independent_check_names_what_a_route_breaks():
    inst = on_a_line()
    assert check(inst, [[(0, 0.0), (1, 0.0), (0, 0.0)]]) == "route 0 runs empty before place 0"
    overcharged = [[(0, 0.0), (2, 30.0), (1, 0.0), (2, 20.0), (0, 0.0)]]
    assert "beyond the battery" in (check(inst, overcharged) or "")
    assert check(inst, [[(0, 0.0), (2, 10.0), (1, 0.0), (2, 20.0), (0, 0.0)]]) is None


@pytest.mark.slow
def test_the_benchmark_command_answers_one_checked_json_line_per_instance():
    path = FOLDER / "c101_21.txt"
    done = subprocess.run(
        [sys.executable, "-m", "benchmarks.evrptw", str(path), "--time-limit", "3"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
        check=True,
    )
    (line,) = done.stdout.splitlines()
    answer = json.loads(line)
    assert answer["instance"] == "c101" and answer["feasible"] is True
    parsed = read(path)
    index = {name: k for k, name in enumerate(parsed.ids)}
    routes = [[(index[v["id"]], v["charge"]) for v in route] for route in answer["routes"]]
    assert check(parsed.problem, routes) is None
    assert answer["vehicles"] == len(routes) >= 12  # the best known is 12
    assert all(route[0]["id"] == "D0" == route[-1]["id"] for route in answer["routes"])
    bad = subprocess.run(
        [sys.executable, "-m", "benchmarks.evrptw", str(path), "--time-limit", "nan"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=60,
    )
    assert bad.returncode == 2 and "--time-limit" in bad.stderr


@pytest.mark.parametrize("pinned", [1, 3, 5])
@pytest.mark.slow
def test_a_customer_pinned_to_a_kind_is_served_by_it_and_the_rest_by_the_others(pinned):
    """The small instance with one more vehicle of a second kind, alike but the only one
    that may serve ``pinned`` (the first kind forbids it): every customer served, ``pinned``
    on the second kind's route, no route of the first kind holding it — and pricing a route
    of the first kind through it is no route."""
    inst = small()
    base = inst.kinds[0]
    kinds = [replace(base, forbidden=frozenset({pinned})), replace(base, count=1)]
    with_pin = replace(inst, kinds=kinds)
    solution = solve_evrptw(with_pin, Effort.starting_now(1.0, 60.0))
    assert solution.left_out == []
    holding = [route.kind for route in solution.routes if pinned in [v.place for v in route.visits]]
    assert holding == [1]
    routes = [[(v.place, v.charge) for v in route.visits] for route in solution.routes]
    assert check(with_pin, routes) is None
    priced = _Priced(with_pin)
    assert priced.charged(0, [pinned]) is NO_ROUTE and priced.charged(1, [pinned]) is not NO_ROUTE


def test_a_route_is_emptied_by_taking_out_a_customer_that_fits_elsewhere():
    """An ejection pool (Nagata & Bräysy 2009) at work, by hand: three vehicles of 3 on a
    line, unit speed. East: 1 and 2 (no window) and 6 (due at 16, so only a route that goes
    east first reaches it); west: 4 and 5 (due at 12 and 14); north: 3 (no window). Routes
    [1, 2, 3], [4, 5], [6]: 6 fits in neither of the others (the east route is full, the west
    one cannot reach it in time), but put in the east route in place of 3, with 3 in the west
    route, two vehicles serve all six."""
    xy = [(0, 0), (10, 0), (12, 0), (0, 10), (-10, 0), (-12, 0), (14, 0)]
    due = np.array([1000.0, 1000, 1000, 1000, 12, 14, 16])
    inst = instance(xy, "dcccccc", due=due, capacity=3.0, battery=1000.0)
    search = _Search(inst, np.random.default_rng(0))
    search.start([(0, [1, 2, 3]), (0, [4, 5]), (0, [6])])
    assert len(search.routes) == 3
    saved = search._saved()
    search.routes.pop()
    assert not search.insert(6, allow_new=False)  # nowhere without taking one out
    search.routes, search.left = saved
    assert search._eliminate(math.inf, 0, Effort(1.0, math.inf))
    routes = sorted(sorted(route) for _, route in search.routes)
    assert routes == [[1, 2, 6], [3, 4, 5]]
    assert search.holds() and search.left == []


def test_a_customer_left_out_may_go_anywhere_the_others_only_near_their_neighbours():
    # the customer at (50, 1) has its 15 nearest in the east route, full (15 of 15); the
    # west route has room but none of them: only a customer left out (anywhere) goes there
    east = [(50.0 + (k % 4) * 0.5, (k // 4) * 0.5 - 1.0) for k in range(15)]
    west = [(-50.0, 0.0), (-50.0, 2.0)]
    inst = instance([(0, 0), *east, *west, (50.0, 1.2)], "d" + "c" * 18, capacity=15.0,
                    battery=1000.0)  # fmt: skip
    solution = _Solution(inst)
    solution.routes = [(0, list(range(1, 16))), (0, [16, 17])]
    assert not solution.insert(18, allow_new=False)
    assert solution.insert(18, allow_new=False, anywhere=True)
    assert 18 in solution.routes[1][1]


def test_a_string_ruin_takes_one_run_of_consecutive_customers_from_each_route_it_ruins():
    """SISR's string removal (Christiaens & Vanden Berghe 2020), by its definition: four
    routes of ten customers, each along its own row (mean length 10, so strings of at most
    :data:`STRING_MOST` and at most 4·10/(1 + 10) − 1 = 2.6, i.e. 3, routes ruined); from each
    ruined route one run of consecutive customers, the seed's own route among them; about
    :data:`STRING_MEAN` customers out on average."""
    from core.routing.evrp import STRING_MEAN, STRING_MOST

    xy = [(0.0, -10.0)] + [(float(x), float(10 * row)) for row in range(4) for x in range(10)]
    inst = instance(xy, "d" + "c" * 40, capacity=100.0, battery=1e6)
    routes = [list(range(1 + 10 * row, 11 + 10 * row)) for row in range(4)]
    most_routes = math.floor(4 * STRING_MEAN / (1 + min(STRING_MOST, 10)) - 1 + 1)
    sizes = []
    search = _Search(inst, np.random.default_rng(0))
    search.routes = [(0, list(r)) for r in routes]
    for seed in range(1000):
        customer = seed % 40
        taken = search._strings(customer)
        ruined = [r for r in routes if taken.intersection(r)]
        assert 1 <= len(ruined) <= most_routes
        assert any(inst.customers[customer] in r for r in ruined)
        for route in ruined:
            at = [k for k, c in enumerate(route) if c in taken]
            assert at == list(range(at[0], at[-1] + 1))  # one run, no gaps
            assert len(at) <= STRING_MOST
        sizes.append(len(taken))
    # on average E[routes] · E[length]: routes ⌊U(1, 3.64)⌋ (1, 2 or 3), lengths 1…10 alike
    routes_max = 4 * STRING_MEAN / (1 + 10) - 1
    mean_routes = (1 + 2 + 3 * (routes_max - 2)) / routes_max
    assert np.mean(sizes) == pytest.approx(mean_routes * 5.5, rel=0.05)  # 10.2 of STRING_MEAN


def test_customers_go_back_at_random_by_demand_or_by_distance_from_the_depot_as_sisr_draws():
    """SISR's recreate orders, drawn 4 : 4 : 2 : 1 — at random, the largest demand first, the
    farthest from the depot first, the nearest first — over five customers whose demands and
    distances from the depot differ."""
    xy = [(0.0, 0.0), (1.0, 0.0), (5.0, 0.0), (2.0, 0.0), (4.0, 0.0), (3.0, 0.0)]
    inst = instance(xy, "dccccc", demand=np.array([0.0, 1, 5, 3, 4, 2]))
    search = _Search(inst, np.random.default_rng(0))
    by_demand, farthest = [2, 4, 3, 5, 1], [2, 4, 5, 3, 1]
    seen = {"demand": 0, "farthest": 0, "nearest": 0, "other": 0}
    draws = 2200
    for _ in range(draws):
        order = search._recreate_order({1, 2, 3, 4, 5})
        assert sorted(order) == [1, 2, 3, 4, 5]
        kind = {tuple(by_demand): "demand", tuple(farthest): "farthest"}.get(tuple(order))
        seen[kind or ("nearest" if order == farthest[::-1] else "other")] += 1
    # a random order is one of these by chance 1/120 of the time each
    assert seen["demand"] / draws == pytest.approx(4 / 11, abs=0.04)
    assert seen["farthest"] / draws == pytest.approx(2 / 11, abs=0.03)
    assert seen["nearest"] / draws == pytest.approx(1 / 11, abs=0.03)
    assert seen["other"] / draws == pytest.approx(4 / 11, abs=0.04)
