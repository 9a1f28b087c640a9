"""Drivers' breaks in the simulated day: the EU rule (Regulation (EC) No 561/2006, art. 7: at
most 4 h 30 min of driving, then at least 45 min) on a long day, and a fixed lunch break."""

from __future__ import annotations

import datetime as dt

import pytest

from core.exceptions import InvalidParameterError
from core.planning.day.timeline import EU_BREAK_S, MAX_DRIVING_S
from core.planning.model import FixedBreak, FleetVehicle
from core.planning.round.planner import plan
from tests.core.planning.day.test_recharge import summer_day

HOUR = dt.timedelta(hours=1)


def long_day(breaks):
    """The 40-stop summer day (about six hours at the wheel) on a battery that lasts."""
    problem = summer_day(None)
    van = problem.van.model_copy(
        update={"battery": problem.van.battery.model_copy(update={"usable_capacity_kwh": 120})}
    )
    return problem.model_copy(update={"van": van, "breaks": breaks, "keep_order": True})


@pytest.fixture(scope="module")
def without():
    return plan(long_day("none"))


@pytest.fixture(scope="module")
def with_eu():
    return plan(long_day("eu-561"))


def driving_between_breaks_s(result) -> list[float]:
    """Seconds at the wheel between one break and the next."""
    stretches, driving = [], 0.0
    rests = list(result.breaks)
    for leg in result.legs:
        while rests and rests[0].end <= leg.depart:
            stretches.append(driving)
            driving = 0.0
            rests.pop(0)
        driving += leg.duration_s
    return [*stretches, driving]


def test_a_day_of_six_hours_driving_gets_a_45_minute_break_before_4h30(without, with_eu):
    assert sum(leg.duration_s for leg in without.legs) > MAX_DRIVING_S
    assert without.breaks == []
    assert len(with_eu.breaks) >= 1
    assert max(driving_between_breaks_s(with_eu)) <= MAX_DRIVING_S
    for rest in with_eu.breaks:
        assert rest.kind == "eu-561"
        assert (rest.end - rest.start).total_seconds() >= EU_BREAK_S
    # the break is taken between stops: a stop is left at its start, the next leg leaves at
    # its end
    departures = {stop.departure for stop in with_eu.stops}
    assert all(rest.start in departures for rest in with_eu.breaks)
    assert all(any(leg.depart == rest.end for leg in with_eu.legs) for rest in with_eu.breaks)
    # the same stops, 45 min later per break, and the refrigeration ran meanwhile
    extra_s = with_eu.duration_s - without.duration_s
    assert extra_s == pytest.approx(EU_BREAK_S * len(with_eu.breaks), abs=2 * len(with_eu.breaks))
    assert with_eu.energy_kwh["refrigeration"] > without.energy_kwh["refrigeration"]


def test_a_fixed_lunch_break_starts_in_its_span_and_lasts_its_minutes(without):
    lunch = FixedBreak(earliest="12:00", latest="13:00", minutes=30)
    result = plan(long_day([lunch]))
    assert len(result.breaks) == 1
    rest = result.breaks[0]
    assert rest.kind == "fixed"
    noon = dt.datetime(2026, 7, 15, 12, 0, tzinfo=rest.start.tzinfo)
    assert noon <= rest.start <= noon + HOUR
    assert (rest.end - rest.start).total_seconds() == pytest.approx(30 * 60, abs=1)
    # taken at the first stop the van leaves after 12:00
    first_after = min(s.departure for s in result.stops if s.departure >= noon)
    assert rest.start == first_after


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (lambda: FixedBreak(earliest="13:00", latest="12:00", minutes=30), "latest"),
        (lambda: FixedBreak(earliest="12:00", latest="13:00", minutes=0), "minutes"),
        (
            lambda: FleetVehicle(
                id="v",
                shift_start="08:00",
                shift_end="09:00",
                breaks=[FixedBreak(earliest="08:00", latest="08:30", minutes=90)],
            ),
            "breaks",
        ),
    ],
)
def test_impossible_breaks_are_refused_naming_the_field(make, field):
    with pytest.raises(InvalidParameterError) as raised:
        make()
    assert raised.value.field == field
