"""One van's day: when service starts, the later departure that saves waiting, and the marks
of a timeline, by hand."""

from __future__ import annotations

import datetime as dt
import math
from zoneinfo import ZoneInfo

import pytest

from core.params import Stop, TimeWindow
from core.planning.day.timeline import build_timeline, later_departure_s, next_window, windows_after
from core.planning.itinerary import Itinerary
from tests.utils.fleets import DEPOT, day_of, fleet, two_clusters, van


def test_next_window_is_the_first_that_has_not_closed():
    windows = [(100.0, 200.0), (400.0, 500.0)]
    assert next_window(50.0, windows) == (100.0, 200.0)  # early: wait for it
    assert next_window(150.0, windows) == (100.0, 200.0)  # inside
    assert next_window(300.0, windows) == (400.0, 500.0)  # between: the next
    assert next_window(501.0, windows) is None  # every window has closed
    assert next_window(1e9, []) == (-math.inf, math.inf)  # no windows: any time


def test_windows_are_elapsed_seconds_across_a_daylight_saving_change():
    # 29 March 2026 in Vienna: 02:00 → 03:00. From 01:00 to 04:00 is two hours, not three.
    zone = ZoneInfo("Europe/Vienna")
    reference = dt.datetime(2026, 3, 29, 1, 0, tzinfo=zone)
    stop = Stop(id="s", lat=48.2, lon=16.4, time_windows=[TimeWindow(start="04:00", end="05:00")])
    assert windows_after([stop], reference.date(), reference) == [[], [(7200.0, 10800.0)]]


def test_the_marks_of_a_day_on_the_client_matrix():
    stops, matrix = two_clusters()
    day = day_of(fleet(stops, [van("a")], matrix=matrix))
    problem = day.shifts[0].problem
    timeline = build_timeline(
        problem, [DEPOT, *stops], day.scene.legs, Itinerary.of([0, 1, 2, 0]), None
    )
    # 10 min out, 5 min service, 2 min on, 5 min service, 10 min back (the client's times).
    assert timeline.depart.tolist() == [0, 900, 1320]
    assert timeline.arrive.tolist() == [600, 1020, 1920]
    assert timeline.serve.tolist() == [600, 1020, 1920]
    assert timeline.leave.tolist() == [900, 1320, 1920]
    assert timeline.duration_s == 1920
    assert [d.start_s for d in timeline.doors] == [600.0, 1020.0]


def test_the_van_leaves_later_by_what_it_would_wait():
    stops, matrix = two_clusters()
    stops[0] = stops[0].model_copy(
        update={"time_windows": [TimeWindow(start="09:00", end="09:10")]}
    )
    day = day_of(fleet(stops, [van("a")], matrix=matrix))
    problem = day.shifts[0].problem
    windows = day.windows_s  # seconds after 08:00, the van's departure
    timeline = build_timeline(
        problem, [DEPOT, *stops], day.scene.legs, Itinerary.of([0, 1, 0]), None, windows
    )
    # Arrives 08:10, waits 50 min for 09:00: leaving 50 min later costs nothing.
    assert timeline.serve.tolist()[0] - timeline.arrive.tolist()[0] == 3000
    assert later_departure_s(timeline, [0, 1, 0], windows, None) == pytest.approx(3000)
    # Back at 09:15 either way: a shift that ends then does not keep the van waiting at the
    # stop; one that ended at 09:05 would leave only what the waits absorb beyond it.
    back_s = timeline.leave.tolist()[-1]
    assert back_s == 4500
    assert later_departure_s(timeline, [0, 1, 0], windows, back_s) == pytest.approx(3000)
    assert later_departure_s(timeline, [0, 1, 0], windows, back_s - 600) == pytest.approx(2400)
