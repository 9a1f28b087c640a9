"""The electrification study: each route-day is the product's own plan of that day (the same
figures as /v1/plans driving the stops in the order given), the days a battery covers follow
from the capacity each day needs, the worst days and their reasons, the fleet's recharge, and
the dates checked."""

from __future__ import annotations

import datetime as dt
from dataclasses import replace

import numpy as np
import pytest

from core.exceptions import CoreError
from core.params import PRESETS, Depot, Stop
from core.planning.electrification.model import (
    Candidate,
    ChargeOption,
    DrivenDay,
    DrivenRoute,
    ElectrificationProblem,
    Weekdays,
)
from core.planning.electrification.study import (
    carrying,
    merged,
    parts_of,
    route_dates,
    route_year,
    study,
    study_part,
    topped_up,
    year_weather,
)
from core.planning.model import PlanProblem
from core.planning.round.planner import plan
from testbed.reference import vienna_stops

DEPOT = Depot(id="depot", lat=48.21, lon=16.37)
VAN = PRESETS["ev-van-3.5t-reefer"].van()
MONTHS = [dt.date(2026, m, 15) for m in range(1, 13)]
LUNCH = ChargeOption(where="depot", power_kw=22, minutes=30)


def stops(count: int, seed: int = 3) -> list[Stop]:
    rng = np.random.default_rng(seed)
    return [Stop.model_validate(s) for s in vienna_stops(rng, count, 300, 120, 10)]


def frozen_van(capacity_kwh: float | None = None):
    """Frozen goods at −22 °C and no cab HVAC: the refrigeration sets the day's weather part,
    and the hottest days need the most."""
    box = VAN.cargo_box.model_copy(update={"product": "frozen", "setpoint_c": -22.0})
    vehicle = VAN.vehicle.model_copy(update={"cabin_hvac_enabled": False})
    van = VAN.model_copy(update={"cargo_box": box, "vehicle": vehicle})
    if capacity_kwh is not None:
        battery = van.battery.model_copy(update={"usable_capacity_kwh": capacity_kwh})
        van = van.model_copy(update={"battery": battery})
    return van


def problem(route: DrivenRoute, *vans, chargers=()) -> ElectrificationProblem:
    return ElectrificationProblem(
        year=2026,
        timezone="Europe/Vienna",
        routes=[route],
        candidates=[Candidate(id=f"c{k}", van=van) for k, van in enumerate(vans)],
        chargers=list(chargers),
    )


def days_of(p: ElectrificationProblem, r: DrivenRoute, van, dates):
    """The route's days for one van, as the study simulates them."""
    return route_year(p, r, {"van": van}, dates)["van"]


def route(days=MONTHS, count: int = 20, route_id: str = "r1") -> DrivenRoute:
    return DrivenRoute(id=route_id, depot=DEPOT, stops=stops(count), start_time="10:00", days=days)


def test_each_route_day_is_the_plan_of_that_day_in_the_order_driven():
    """The study's day is what POST /v1/plans answers for the same stops, kept in order, on
    that date: the same energy per consumer and the same lowest charge."""
    r = route()
    for date in (MONTHS[0], MONTHS[6]):
        (day,) = days_of(problem(r, VAN), r, VAN, [date])
        planned = plan(
            PlanProblem(
                date=date,
                timezone="Europe/Vienna",
                depot=DEPOT,
                stops=r.stops,
                start_time=r.start_time,
                keep_order=True,
                van=VAN,
            )
        )
        for name in ("traction", "auxiliaries", "cabin", "refrigeration"):
            assert day.energy_kwh[name] == pytest.approx(planned.energy_kwh[name], rel=1e-9)
        assert day.battery.min_soc == pytest.approx(planned.battery.min_soc, rel=1e-9)
        assert day.distance_m == pytest.approx(planned.distance_m, rel=1e-9)


def test_a_battery_covers_the_days_that_need_no_more_than_it_holds():
    """Each day's required capacity decides it: a candidate with the year's largest covers
    every day, one with its 95th percentile at least 95 % of them, and one just below the
    smallest none."""
    r = route()
    (outcome,) = study(problem(r, frozen_van())).routes[0].candidates
    required = sorted(
        d.battery.required_capacity_kwh for d in days_of(problem(r, VAN), r, frozen_van(), MONTHS)
    )
    assert outcome.required_kwh_max == pytest.approx(required[-1])
    # 12 days: 95 % of them is 11.4, so the 12th smallest (nearest rank)
    assert outcome.required_kwh_p95 == pytest.approx(required[11])
    for capacity, feasible in ((required[-1] + 0.01, 12), (required[0] - 0.01, 0)):
        result = study(problem(r, frozen_van(capacity)))
        assert result.routes[0].candidates[0].days_feasible == feasible
        assert result.fleet[0].routes_all_year == (feasible == 12)


def test_a_route_that_fails_only_on_the_hottest_days_is_named_with_them():
    """Frozen goods, no cab HVAC: July needs the most. A battery between July's need and every
    other month's covers 11 of the 12 days; July is the worst day, for the heat."""
    r = route()
    days = days_of(problem(r, VAN), r, frozen_van(), MONTHS)
    need = {d.date: d.battery.required_capacity_kwh for d in days}
    hottest = max(days, key=lambda d: d.t_max_c).date
    assert max(need, key=need.__getitem__) == hottest == dt.date(2026, 7, 15)
    second = sorted(need.values())[-2]
    capacity = (second + need[hottest]) / 2
    (outcome,) = study(problem(r, frozen_van(capacity))).routes[0].candidates
    assert outcome.days_feasible == 11 and outcome.share_feasible == pytest.approx(11 / 12)
    worst = outcome.worst_days[0]
    assert worst.date == hottest and worst.reason == "heat" and worst.min_soc < 0.1
    assert "refrigeration" in worst.detail and "-0 " not in worst.detail


def test_a_charge_covers_the_days_whose_lack_it_stores():
    """22 kW for 30 min at lunch stores 22 × 0.5 × efficiency; a day lacking less is covered
    with it, one lacking more is not (the van's own power cap applies); two charges add up."""
    van = frozen_van()
    stored_kwh = 22 * 0.5 * van.battery.charging_efficiency
    r = route()
    (day,) = days_of(problem(r, van), r, van, [MONTHS[6]])
    short = van.model_copy(
        update={
            "battery": van.battery.model_copy(
                update={"usable_capacity_kwh": day.battery.required_capacity_kwh - 1.0}
            )
        }
    )
    (lacking,) = days_of(problem(r, short), r, short, [MONTHS[6]])
    assert not lacking.battery.feasible and 0 < -lacking.battery.margin_kwh < stored_kwh
    assert topped_up(lacking.battery, short, [LUNCH])
    assert not topped_up(
        lacking.battery, short, [ChargeOption(where="depot", power_kw=22, minutes=1)]
    )
    capped = short.model_copy(
        update={"battery": short.battery.model_copy(update={"max_charge_power_kw": 1.0})}
    )
    assert not topped_up(lacking.battery, capped, [LUNCH])
    assert not topped_up(lacking.battery, short, [])
    halves = [LUNCH.model_copy(update={"minutes": 15}), LUNCH.model_copy(update={"minutes": 15})]
    assert topped_up(lacking.battery, short, halves)
    result = study(problem(r, short, chargers=[LUNCH]))
    outcome = result.routes[0].candidates[0]
    assert outcome.days_feasible_with_charging >= outcome.days_feasible + 1


def test_a_charge_stores_along_the_vans_charging_curve():
    """The same 30 min at a 22 kW charger store half as much for a van whose curve takes
    11 kW (its own curve, not the charger's power: the model the planners use): a day lacking
    three quarters of 22 × 0.5 × efficiency is covered by the van that takes 22 kW only."""
    van = frozen_van()
    r = route()
    (day,) = days_of(problem(r, van), r, van, [MONTHS[6]])
    eff = van.battery.charging_efficiency
    lacking = replace(day.battery, feasible=False, margin_kwh=-0.75 * 22 * 0.5 * eff)
    flat = [{"soc": 0.0, "power_kw": 11.0}, {"soc": 1.0, "power_kw": 11.0}]
    curved = type(van.battery).model_validate(van.battery.model_dump() | {"charging_curve": flat})
    slow = van.model_copy(update={"battery": curved})
    assert van.battery.max_charge_power_kw >= 22
    assert topped_up(lacking, van, [LUNCH])
    assert not topped_up(lacking, slow, [LUNCH])


def test_the_depot_recharges_the_days_driven_on_one_charge():
    """Two routes on the same dates: the depot's energy on a date is both vans' recharge, its
    peak power each one's over the hours it stands until the next day's departure."""
    first, second = route(MONTHS[6:8], 12, "a"), route(MONTHS[6:8], 16, "b")
    p = problem(first, VAN).model_copy(update={"routes": [first, second]})
    result = study(p)
    years = [days_of(p, r, VAN, r.days) for r in (first, second)]
    by_date = [sum(y[k].battery.recharge_kwh for y in years) for k in range(2)]
    power = [
        sum(y[k].battery.recharge_kwh / ((86_400 - y[k].duration_s) / 3600) for y in years)
        for k in range(2)
    ]
    assert result.fleet[0].depot_kwh_max_day == pytest.approx(max(by_date))
    assert result.fleet[0].depot_kw_peak == pytest.approx(max(power))
    assert result.route_days == 4 and result.weather_source == "climatology"


def test_weekdays_are_every_such_date_of_the_year():
    weekdays = route(Weekdays(weekdays=["mon", "tue", "wed", "thu", "fri"]))
    dates = route_dates(weekdays, 2026, "days")
    assert len(dates) == 261 and dates[0] == dt.date(2026, 1, 1)  # a Thursday
    assert {d.weekday() for d in dates} == {0, 1, 2, 3, 4}
    sundays = route_dates(route(Weekdays(weekdays=["sun"])), 2024, "days")  # a leap year
    assert len(sundays) == 52 and sundays[-1] == dt.date(2024, 12, 29)


@pytest.mark.parametrize(
    ("change", "field", "words"),
    [
        (lambda r, p: p.model_copy(update={"year": 2025}), "routes[0].days[0]", "not in"),
        (
            lambda r, p: p.model_copy(update={"routes": [r, r]}),
            "routes[1].id",
            "used twice",
        ),
        (
            lambda r, p: p.model_copy(update={"candidates": p.candidates * 2}),
            "candidates[1].id",
            "used twice",
        ),
        (
            lambda r, p: p.model_copy(
                update={
                    "routes": [
                        r.model_copy(
                            update={"stops": [r.stops[0].model_copy(update={"delivery_kg": 5000})]}
                        )
                    ]
                }
            ),
            "routes[0].stops",
            "with candidate 'c0': ",
        ),
    ],
)
def test_a_study_that_cannot_run_names_the_field(change, field, words):
    r = route(MONTHS[:2])
    with pytest.raises(CoreError) as caught:
        study(change(r, problem(r, VAN)))
    assert caught.value.field == field and words in caught.value.message


def test_dates_out_of_order_are_refused_with_their_place():
    with pytest.raises(ValueError, match=r"days\[1\]"):
        route([MONTHS[1], MONTHS[0]])


def test_a_routes_goods_go_into_each_candidates_box():
    """Frozen goods on a route: the reefer's box (set to 4 °C) runs at the frozen band's middle,
    −24 °C, and holds them; chilled dairy keeps its 4 °C (inside 0–6 °C)."""
    frozen = route(MONTHS[6:7]).model_copy(update={"product": "frozen"})
    dairy = frozen.model_copy(update={"product": "chilled-dairy"})
    assert carrying(VAN, frozen).cargo_box.setpoint_c == -24.0
    assert carrying(VAN, dairy).cargo_box.setpoint_c == VAN.cargo_box.setpoint_c == 4.0
    plain = route(MONTHS[6:7])
    cold = study(problem(frozen, VAN)).routes[0].candidates[0]
    warm = study(problem(plain, VAN)).routes[0].candidates[0]
    assert cold.energy_kwh_mean["refrigeration"] > warm.energy_kwh_mean["refrigeration"]
    assert cold.cold_chain_days_broken == 0


def test_batteries_alone_apart_share_one_simulation_and_get_their_own_verdicts():
    """Three batteries of one van (capacities, reserve, departure charge): the study simulates
    the day once and gives each battery the verdict and loss its own simulation gives."""
    r = route(MONTHS[:1])
    batteries = [
        VAN.battery.model_copy(update=changes)
        for changes in (
            {"usable_capacity_kwh": 40.0},
            {"usable_capacity_kwh": 70.0, "min_soc": 0.2},
            {"usable_capacity_kwh": 55.0, "initial_soc": 0.8},
        )
    ]
    vans = {f"b{k}": VAN.model_copy(update={"battery": b}) for k, b in enumerate(batteries)}
    shared = route_year(problem(r, VAN), r, vans, MONTHS[:1])
    for name, van in vans.items():
        (alone,) = days_of(problem(r, van), r, van, MONTHS[:1])
        (day,) = shared[name]
        assert day.battery == alone.battery
        assert day.energy_kwh == pytest.approx(alone.energy_kwh, rel=1e-12)


def test_a_route_longer_than_a_day_is_named():
    """120 stops of an hour each: more than 24 h in the order given."""
    long = route(MONTHS[:1], 120).model_copy(
        update={
            "stops": [
                s.model_copy(update={"service_time_s": 3600.0, "delivery_kg": 0.0})
                for s in stops(120)
            ]
        }
    )
    with pytest.raises(CoreError) as caught:
        study(problem(long, VAN))
    assert caught.value.field == "routes[0].stops" and "longer than a day" in caught.value.message


@pytest.mark.parametrize("count", [1, 2, 3, 5])
def test_a_study_split_into_parts_answers_what_it_answers_whole(count):
    """Routes of 1, 3 and 2 days in parts (in any process): the parts cover every route once,
    in order, and merged they give the whole study's figures exactly (its clock aside)."""
    routes = [
        route(MONTHS[:1], 8, "a"),
        route(MONTHS[3:6], 10, "b"),
        route(MONTHS[6:8], 12, "c"),
    ]
    p = problem(routes[0], VAN, frozen_van()).model_copy(update={"routes": routes})
    whole = study(p)
    ranges = parts_of(p, count)
    assert [i for r in ranges for i in r] == [0, 1, 2] and len(ranges) <= count
    weather = year_weather(p, None)
    parts = [study_part(p, r, weather) for r in reversed(ranges)]  # finished in any order
    split = merged(p, parts, weather, whole.runtime_s)
    timing = {"runtime_s", "route_days_per_s"}
    assert split.model_dump(exclude=timing) == whole.model_dump(exclude=timing)
    assert split.route_days == 6


def test_days_driven_with_their_own_stops_are_each_their_own_day():
    """A telematics year: the route drove 10 stops on one day and 30 the next (same weather,
    a day apart): each day is the plan of its own stops, and the long day is the worst, for
    its distance."""
    short, long = stops(10, seed=5), stops(30, seed=6)
    days = [
        DrivenDay(date=dt.date(2026, 7, 14), start_time="08:00", stops=short),
        DrivenDay(date=dt.date(2026, 7, 15), start_time="07:00", stops=long),
    ]
    r = DrivenRoute(id="r1", depot=DEPOT, days=days)
    (outcome,) = study(problem(r, VAN)).routes[0].candidates
    assert outcome.days_total == 2
    worst = outcome.worst_days[0]
    assert worst.date == dt.date(2026, 7, 15) and worst.reason == "distance"
    year = days_of(problem(r, VAN), r, VAN, [d.date for d in days])
    planned = plan(
        PlanProblem(
            date=dt.date(2026, 7, 14),
            timezone="Europe/Vienna",
            depot=DEPOT,
            stops=short,
            start_time="08:00",
            keep_order=True,
            van=VAN,
        )
    )
    assert year[0].distance_m == pytest.approx(planned.distance_m, rel=1e-9)
    assert year[0].battery.min_soc == pytest.approx(planned.battery.min_soc, rel=1e-9)
    assert year[1].distance_m > 2 * year[0].distance_m


def test_a_route_without_its_stops_needs_days_that_have_theirs():
    with pytest.raises(ValueError, match="needed unless each day gives its own"):
        DrivenRoute(id="r1", depot=DEPOT, days=MONTHS[:1])
    other_year = DrivenRoute(
        id="r1",
        depot=DEPOT,
        days=[DrivenDay(date=dt.date(2025, 7, 14), start_time="08:00", stops=stops(3))],
    )
    with pytest.raises(CoreError) as caught:
        study(problem(other_year, VAN))
    assert caught.value.field == "routes[0].days[0].date"


def test_a_bad_day_as_driven_is_named_in_its_place():
    twice = [stops(2)[0], stops(2)[0]]
    r = DrivenRoute(
        id="r1",
        depot=DEPOT,
        days=[
            DrivenDay(date=dt.date(2026, 7, 14), start_time="08:00", stops=stops(3)),
            DrivenDay(date=dt.date(2026, 7, 15), start_time="08:00", stops=twice),
        ],
    )
    with pytest.raises(CoreError) as caught:
        study(problem(r, VAN))
    assert caught.value.field == "routes[0].days[1].stops[1].id"
