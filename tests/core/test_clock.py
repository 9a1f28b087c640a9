import datetime as dt
from zoneinfo import ZoneInfo

import numpy as np
import pytest

from core.clock import at, departure, local_clock
from core.exceptions import InvalidParameterError
from core.params import Location, VanParams, Weather
from core.physics.simulate import simulate, sun

VIENNA = ZoneInfo("Europe/Vienna")


def test_spring_forward_keeps_elapsed_time():
    # 29 March 2026: 02:00 CET → 03:00 CEST. 01:00 CET + 5 h 36 min of real time is 07:36 CEST
    # (wall-clock arithmetic would say 06:36).
    start, _ = departure(dt.date(2026, 3, 29), dt.time(1, 0), "Europe/Vienna", 16.4)
    arrival = at(start, 5 * 3600 + 36 * 60)
    assert arrival.isoformat() == "2026-03-29T07:36:00+02:00"
    # (Python subtracts two times of the same zone on the wall clock; compare in UTC.)
    elapsed = arrival.astimezone(dt.UTC) - start.astimezone(dt.UTC)
    assert elapsed.total_seconds() == 5 * 3600 + 36 * 60


def test_fall_back_keeps_elapsed_time():
    # 25 October 2026: 03:00 CEST → 02:00 CET. 01:00 CEST + 5 h 36 min is 05:36 CET.
    start, _ = departure(dt.date(2026, 10, 25), dt.time(1, 0), "Europe/Vienna", 16.4)
    assert at(start, 5 * 3600 + 36 * 60).isoformat() == "2026-10-25T05:36:00+01:00"


def test_a_start_the_clocks_skip_is_refused():
    with pytest.raises(InvalidParameterError) as caught:
        departure(dt.date(2026, 3, 29), dt.time(2, 30), "Europe/Vienna", 16.4)
    assert caught.value.field == "start_time" and "does not exist" in caught.value.message


def test_an_ambiguous_start_is_the_first_one():
    start, _ = departure(dt.date(2026, 10, 25), dt.time(2, 30), "Europe/Vienna", 16.4)
    assert start.utcoffset() == dt.timedelta(hours=2)


def test_local_clock_follows_the_offset_in_force():
    start = dt.datetime(2026, 3, 29, 1, 0, tzinfo=VIENNA)
    clock = local_clock(start, np.array([0.0, 3600.0, 2 * 3600.0]))
    # 01:00 CET, then 03:00 CEST (02:00 never happens), then 04:00 CEST
    assert clock.hour == pytest.approx([1.0, 3.0, 4.0])


def test_days_of_a_round_past_midnight():
    start = dt.datetime(2026, 7, 15, 22, 0, tzinfo=VIENNA)
    clock = local_clock(start, np.array([0.0, 3 * 3600.0]))
    assert list(clock.day_index) == [0, 1]
    assert clock.dates == [dt.date(2026, 7, 15), dt.date(2026, 7, 16)]
    assert clock.hour == pytest.approx([22.0, 1.0])


def test_sun_ignores_the_local_clock():
    # The same instants seen from Vienna and from UTC have the same sun.
    vienna = dt.datetime(2026, 3, 29, 1, 0, tzinfo=VIENNA)
    utc = vienna.astimezone(dt.UTC)
    offsets = np.arange(0, 12 * 3600.0, 600.0)
    where = Location(lat=48.21, lon=16.37)
    a, _ = sun(local_clock(vienna, offsets).utc_s, where)
    b, _ = sun(local_clock(utc, offsets).utc_s, where)
    assert a == pytest.approx(b)
    # solar noon in Vienna (16.37° E) on 29 March is near 11:53 UTC (+ equation of time 5 min)
    noon = offsets[np.argmax(a)]
    assert (utc + dt.timedelta(seconds=float(noon))).hour == 11


def test_temperature_uses_the_true_local_hour_after_the_change():
    # A trace from 01:00 CET on 29 March: at 13:00 CEST (11 h later) the daily sine is at
    # 13:00, not at 12:00 as a fixed start offset would have it.
    start = dt.datetime(2026, 3, 29, 1, 0, tzinfo=VIENNA)
    n = 11 * 3600 + 2
    result = simulate(
        np.zeros(n),
        1.0,
        start,
        Location(lat=48.21, lon=16.37),
        VanParams(),
        weather=Weather(t_min_c=0, t_max_c=20),
    )
    # step ending at 11 h: local 13:00 CEST → 10 + 10·sin(5π/12) = 19.659 °C
    assert result.ambient_c[11 * 3600 - 1] == pytest.approx(19.659, abs=0.01)


def test_year_9999_is_the_end():
    with pytest.raises(InvalidParameterError) as caught:
        simulate(
            np.zeros(3600),
            1.0,
            dt.datetime(9999, 12, 31, 23, 59, tzinfo=dt.UTC),
            Location(lat=0, lon=0),
            VanParams(),
        )
    assert caught.value.field == "start"
