"""POST /v1/studies/electrification/from-csv: a telematics export (one row per stop visited)
as the days of an electrification study, each bad cell named by its line and column."""

from __future__ import annotations

import json

import pytest

from tests.app.apps import app_client

PATH = "/v1/studies/electrification/from-csv"
DEPOT = {"id": "depot", "lat": 48.17, "lon": 16.42}
STUDY = {
    "year": 2026,
    "timezone": "Europe/Vienna",
    "routes": [{"id": "tour-1", "depot": DEPOT}, {"id": "tour-2", "depot": DEPOT}],
    "candidates": [{"id": "reefer", "vehicle": {"preset": "ev-van-3.5t-reefer"}}],
}
HEADER = "route_id,date,stop_id,lat,lon,arrival,departure,delivery_kg,door_minutes"
ROWS = [
    "tour-1,2026-07-14,depot,48.17,16.42,,07:00,,",
    "tour-1,2026-07-14,billa,48.2006,16.3862,07:20,07:29,30,4",
    "tour-1,2026-07-14,spar,48.1925,16.3671,07:41,07:48:30,25,",
    "tour-1,2026-07-14,depot,48.17,16.42,08:10,,,",
    "tour-1,2026-07-15,depot,48.17,16.42,,06:30,,",
    "tour-1,2026-07-15,hofer,48.2036,16.3489,06:55,07:02,35,3.5",
    "tour-2,2026-07-14,depot,48.17,16.42,,08:00,,",
    "tour-2,2026-07-14,bio,48.2108,16.3485,08:30,08:36,20,2",
]


def send(rows: list[str], study: dict = STUDY, header: str = HEADER):
    csv_text = "\r\n".join([header, *rows]) + "\r\n"
    return app_client().post(
        PATH,
        data={"study": json.dumps(study)},
        files={"history": ("export.csv", csv_text.encode(), "text/csv")},
    )


def test_an_export_becomes_the_routes_days_and_the_study_runs_on_them():
    response = send(ROWS)
    assert response.status_code == 200, response.text
    study = response.json()
    first, second = study["routes"]
    assert [d["date"] for d in first["days"]] == ["2026-07-14", "2026-07-15"]
    day = first["days"][0]
    assert day["start_time"] == "07:00"
    billa, spar = day["stops"]
    # service from arrival to departure; the door as the export says, else a minute
    assert billa["service_time_s"] == 540 and billa["door_open_s"] == 240
    assert spar["service_time_s"] == 450 and spar["door_open_s"] == 60
    assert billa["delivery_kg"] == 30 and second["days"][0]["stops"][0]["id"] == "bio"
    answer = app_client().post("/v1/studies/electrification", json=study)
    assert answer.status_code == 200, answer.text
    totals = [r["candidates"][0]["days_total"] for r in answer.json()["routes"]]
    assert totals == [2, 1]


@pytest.mark.parametrize(
    ("rows", "field", "words"),
    [
        ([ROWS[1], *ROWS[2:4]], "history[2].stop_id", "begins with the departure"),
        ([ROWS[0], ROWS[2], ROWS[1]], "history[4].arrival", "is before"),
        ([ROWS[0], ROWS[1].replace("07:29", "07:10")], "history[3].departure", "before arrival"),
        ([ROWS[0], ROWS[1].replace("07:20", "7h20")], "history[3].arrival", "not a time"),
        ([ROWS[0], ROWS[1].replace("48.2006", "91")], "history[3].lat", "within -90..90"),
        ([ROWS[0], ROWS[1].replace(",30,", ",lots,")], "history[3].delivery_kg", "not a number"),
        ([ROWS[0], ROWS[1].replace(",4", ",20")], "history[3].door_minutes", "within 0..9"),
        ([ROWS[0], ROWS[1].replace("tour-1", "tour-9")], "history[3].route_id", "no route"),
        ([ROWS[0], ROWS[1].replace("2026-07-14", "14.7.2026")], "history[3].date", "not a date"),
        # an audit's: what Python reads as dates, a date of another year, an id cut at 64,
        # a start the clocks skip — each accepted here and refused by the study later
        ([r.replace("2026-07-14", "20260714") for r in ROWS[:4]], "history[2].date", "not a"),
        ([r.replace("2026-07-14", "2026-W29-2") for r in ROWS[:4]], "history[2].date", "not a"),
        ([r.replace("2026-07-14", "2025-07-14") for r in ROWS[:4]], "history[2].date", "year"),
        ([ROWS[0], ROWS[1].replace("billa", "b" * 65)], "history[3].stop_id", "at most 64"),
        (
            [r.replace("2026-07-14", "2026-03-29").replace("07:00", "02:30") for r in ROWS[:4]],
            "history[2].departure",
            "the clocks skip it",
        ),
        ([*ROWS[4:6], *ROWS[0:2]], "history[4].date", "after a later day"),
        ([*ROWS[0:2], *ROWS[6:8], ROWS[1]], "history[6].date", "not together"),
        (
            [*ROWS[0:4], ROWS[1].replace("billa", "penny")],
            "history[5].departure",
            "needs its departure",
        ),
        (
            [ROWS[0], ROWS[1], ROWS[1].replace("07:20", "07:40").replace("07:29", "07:45")],
            "history[4].stop_id",
            "twice",
        ),
        ([ROWS[0]], "history[2].stop_id", "without a stop"),
        (ROWS[:4], "routes[1]", "no day of this route"),
    ],
)
def test_a_bad_export_names_the_line_and_the_column(rows, field, words):
    response = send(rows)
    assert response.status_code == 422, response.text
    error = response.json()["errors"][0]
    assert error["field"] == field and words in error["message"], error


@pytest.mark.parametrize("twice", ["lat", "stop_id"])
def test_a_column_named_twice_is_named_not_read_twice(twice):
    # an audit's export had lat twice: the last copy won and every stop was at latitude 0.0
    rows = [f"{row},{row.split(',')[HEADER.split(',').index(twice)]}" for row in ROWS]
    response = send(rows, header=f"{HEADER},{twice}")
    assert response.status_code == 422, response.text
    error = response.json()["errors"][0]
    assert error["field"] == "history" and f"'{twice}' is named twice" in error["message"]


def test_a_header_without_a_column_and_a_study_with_days_of_its_own_are_named():
    missing = send(ROWS, header=HEADER.replace("arrival,", ""))
    assert missing.status_code == 422
    assert missing.json()["errors"][0]["field"] == "history"
    assert "'arrival'" in missing.json()["detail"]
    own = {**STUDY, "routes": [{**STUDY["routes"][0], "days": ["2026-07-14"]}]}
    refused = send(ROWS, study=own)
    assert refused.status_code == 422
    assert refused.json()["errors"][0]["field"] == "routes[0].days"


# GPS traces: a fix every 30 s. The van leaves the depot at 07:00, stops at Billa 07:20–07:29
# and at Spar 07:41–07:48:30, halts a minute at a light on the way back (not a stop), and is
# back at 08:10, then parked.
BILLA, SPAR = (48.2006, 16.3862), (48.1925, 16.3671)
LIGHT = (48.1800, 16.3900)


def _clock(seconds: float) -> str:
    seconds = int(seconds)
    return f"{seconds // 3600:02d}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


def _drive(a, b, t0: float, t1: float) -> list[tuple[float, float, float]]:
    """Fixes every 30 s strictly between leaving ``a`` at ``t0`` and reaching ``b`` at ``t1``."""
    steps = int((t1 - t0) // 30)
    return [
        (t0 + 30 * k, a[0] + (b[0] - a[0]) * k / steps, a[1] + (b[1] - a[1]) * k / steps)
        for k in range(1, steps)
    ]


def _stay(place, t0: float, t1: float, jitter_deg: float = 0.00004):
    """Fixes every 30 s from ``t0`` to ``t1`` at ``place``, a few metres of GPS noise."""
    n = int((t1 - t0) // 30)
    return [
        (t0 + 30 * k, place[0] + jitter_deg * (-1) ** k, place[1] - jitter_deg * (-1) ** k)
        for k in range(n + 1)
    ]


def _h(hours: int, minutes: float) -> float:
    return hours * 3600 + minutes * 60


DEPOT_AT = (DEPOT["lat"], DEPOT["lon"])
FIXES = [
    *_stay(DEPOT_AT, _h(6, 50), _h(7, 0)),
    *_drive(DEPOT_AT, BILLA, _h(7, 0), _h(7, 20)),
    *_stay(BILLA, _h(7, 20), _h(7, 29)),
    *_drive(BILLA, SPAR, _h(7, 29), _h(7, 41)),
    *_stay(SPAR, _h(7, 41), _h(7, 48.5)),
    *_drive(SPAR, LIGHT, _h(7, 48.5), _h(7, 58)),
    *_stay(LIGHT, _h(7, 58), _h(7, 59)),
    *_drive(LIGHT, DEPOT_AT, _h(7, 59), _h(8, 10)),
    *_stay(DEPOT_AT, _h(8, 10), _h(8, 30)),
]
TRACE_HEADER = "route_id,date,time,lat,lon"
TRACE = [f"tour-1,2026-07-14,{_clock(t)},{lat:.6f},{lon:.6f}" for t, lat, lon in FIXES] + [
    f"tour-2,2026-07-14,{_clock(t + 3600)},{lat:.6f},{lon:.6f}" for t, lat, lon in FIXES
]


def test_gps_traces_become_the_days_stops_where_the_van_dwelt():
    response = send(TRACE, header=TRACE_HEADER)
    assert response.status_code == 200, response.text
    first, second = response.json()["routes"]
    (day,) = first["days"]
    assert day["start_time"] == "07:00"  # the last fix at the depot
    billa, spar = day["stops"]  # the minute at the light is no stop
    # the dwell from its first fix to its last within 50 m (hand count: 07:20–07:29, …)
    assert billa["service_time_s"] == 540 and spar["service_time_s"] == 450
    for stop, place in ((billa, BILLA), (spar, SPAR)):
        assert abs(stop["lat"] - place[0]) < 1e-4 and abs(stop["lon"] - place[1]) < 1e-4
    assert billa["id"] == "tour-1-2026-07-14-1" and billa["door_open_s"] == 60
    assert second["days"][0]["start_time"] == "08:00"
    answer = app_client().post("/v1/studies/electrification", json=response.json())
    assert answer.status_code == 200, answer.text


@pytest.mark.parametrize(
    ("rows", "field", "words"),
    [
        ([TRACE[0], TRACE[2], TRACE[1]], "history[4].time", "not after the fix before"),
        (TRACE[25 : len(FIXES)], "history[2].lat", "begins at the depot"),
        (TRACE[:50], "history[2].time", "has no stop"),  # it leaves, never stops
        ([TRACE[0], "tour-1,2026-07-14,06:51:00,95.0,16.42"], "history[3].lat", "within -90..90"),
        ([TRACE[0], TRACE[1].replace(":", "h", 1)], "history[3].time", "not a time"),
    ],
)
def test_a_bad_trace_names_the_line_and_the_column(rows, field, words):
    response = send(rows, study={**STUDY, "routes": STUDY["routes"][:1]}, header=TRACE_HEADER)
    assert response.status_code == 422, response.text
    error = response.json()["errors"][0]
    assert error["field"] == field and words in error["message"], error


def test_traces_need_their_depot_and_their_columns():
    study = {**STUDY, "routes": [{"id": "tour-1", "depot": {"id": "depot", "lat": 123}}]}
    response = send(TRACE[: len(FIXES)], study=study, header=TRACE_HEADER)
    assert response.status_code == 422
    assert response.json()["errors"][0]["field"] == "routes[0].depot"
    missing = send(TRACE, header="route_id,date,time,lat")
    assert missing.status_code == 422 and "GPS traces" in missing.json()["detail"]


def test_a_second_tour_after_lunch_is_one_day_with_a_stop_at_the_depot():
    # an audit's export: back at the depot for lunch, out again; the GPS reader lost the
    # afternoon (a 200 with half the day), the stop rows refused it
    lunch = "tour-1,2026-07-14,depot,48.17,16.42,08:10,12:30,,"
    afternoon = [
        "tour-1,2026-07-14,hofer,48.2036,16.3489,12:55,13:02,35,3.5",
        "tour-1,2026-07-14,depot,48.17,16.42,13:30,,,",
    ]
    rows = [*ROWS[0:3], lunch, *afternoon, *ROWS[6:8]]
    response = send(rows)
    assert response.status_code == 200, response.text
    day = response.json()["routes"][0]["days"][0]
    assert [stop["id"] for stop in day["stops"]] == ["billa", "spar", "depot (08:10)", "hofer"]
    assert day["stops"][2]["service_time_s"] == 4 * 3600 + 20 * 60


def _trace(fixes) -> list[str]:
    return [f"tour-1,2026-07-14,{_clock(t)},{lat:.6f},{lon:.6f}" for t, lat, lon in fixes]


EAST = (48.17, 16.4400)  # 1.5 km east of the depot: the way to it passes the depot


def test_a_trace_that_passes_its_depot_or_comes_back_for_lunch_keeps_the_whole_day():
    passing = [
        *FIXES[: FIXES.index(next(f for f in FIXES if f[0] >= _h(8, 10)))],  # to the depot…
        *_drive(DEPOT_AT, EAST, _h(8, 10), _h(8, 20)),  # … through it, not stopping
        *_stay(EAST, _h(8, 20), _h(8, 30)),
        *_drive(EAST, DEPOT_AT, _h(8, 30), _h(8, 40)),
        *_stay(DEPOT_AT, _h(8, 40), _h(9, 0)),
    ]
    lunch = [
        *FIXES,  # back 08:10, parked until 08:30
        *_drive(DEPOT_AT, EAST, _h(8, 30), _h(8, 40)),
        *_stay(EAST, _h(8, 40), _h(8, 50)),
        *_drive(EAST, DEPOT_AT, _h(8, 50), _h(9, 0)),
        *_stay(DEPOT_AT, _h(9, 0), _h(9, 20)),
    ]
    one = {**STUDY, "routes": STUDY["routes"][:1]}
    for fixes, at_depot in ((passing, 0), (lunch, 1)):
        response = send(_trace(fixes), study=one, header=TRACE_HEADER)
        assert response.status_code == 200, response.text
        stops = response.json()["routes"][0]["days"][0]["stops"]
        places = [(round(s["lat"], 3), round(s["lon"], 3)) for s in stops]
        depot = (round(DEPOT_AT[0], 3), round(DEPOT_AT[1], 3))
        assert places.count(depot) == at_depot and places[-1] == (48.17, 16.44), places
        assert len(stops) == 3 + at_depot  # Billa, Spar, east (and the depot at lunch)
