"""Classes of hostile input the audit of issue #21 found examples of — every member of each
class, on every endpoint that takes it, synchronously and as a job: a 422 naming a field the
client sent (or a correct answer), never a 5xx, never a silently wrong number."""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path
from typing import Any

import httpx
import pytest
import tzdata

from app.examples import (
    FLEET_PLAN_EXAMPLE,
    PLAN_EXAMPLE,
    SCENARIOS_EXAMPLE,
    SIMULATE_EXAMPLE,
    SPEED_SWEEP_EXAMPLE,
)
from app.main import app as default_app
from tests.app.apps import app_client

PROBLEM = "application/problem+json"
SCHEMAS = default_app.openapi()["components"]["schemas"]


def sent(body: Any, field: str) -> Any:
    """The value at a field's JSON path (``stops[1].id``) in what was sent; KeyError or
    IndexError when the request has no such field."""
    for name, index in re.findall(r"([^.\[\]]+)|\[(\d+)\]", field):
        body = body[name] if name else body[int(index)]
    return body


def named(response: httpx.Response, body: Any) -> list[str]:
    """The fields a 422 names, each checked to be one the request has."""
    assert response.status_code == 422, response.text[:500]
    assert response.headers["content-type"] == PROBLEM
    found = [error["field"] for error in response.json()["errors"]]
    for field in found:
        sent(body, field)  # a field of the request, not of the service's insides
    return found


def with_date(body: dict[str, Any], **change: Any) -> dict[str, Any]:
    return copy.deepcopy(body) | change


# Every endpoint that takes a time zone and a date, and where they sit in its body.
DAY_BODIES = {
    "/v1/plans": (PLAN_EXAMPLE, ""),
    "/v1/fleet-plans": (FLEET_PLAN_EXAMPLE, ""),
    "/v1/studies/speed-sweep": (SPEED_SWEEP_EXAMPLE, ""),
    "/v1/studies/scenarios": (SCENARIOS_EXAMPLE, "plan."),
}
JOB_KINDS = {
    "/v1/plans": "plan",
    "/v1/fleet-plans": "fleet-plan",
    "/v1/studies/speed-sweep": "speed-sweep",
    "/v1/studies/scenarios": "scenarios",
}


def day_body(path: str, **change: Any) -> dict[str, Any]:
    body, prefix = DAY_BODIES[path]
    body = copy.deepcopy(body)
    (body["plan"] if prefix else body).update(change)
    return body


def post_both_ways(client, path: str, body: dict[str, Any]) -> list[list[str]]:
    """The fields named by the endpoint and by ``POST /v1/jobs`` with the same request (the
    job's under ``request.``)."""
    direct = named(client.post(path, json=body), body)
    job = {"type": JOB_KINDS[path], "request": body}
    as_job = named(client.post("/v1/jobs", json=job), job)
    assert as_job == [f"request.{field}" for field in direct]
    return [direct, as_job]


# --- time zones: a zone of the database, nothing else ------------------------------------------


def _zone_folders() -> list[str]:
    """Every folder of the time-zone databases here (tzdata's and the system's): names that
    open as directories, not zones."""
    roots = [Path(tzdata.__file__).parent / "zoneinfo", Path("/usr/share/zoneinfo")]
    return sorted(
        {
            str(path.relative_to(root))
            for root in roots
            if root.is_dir()
            for path in root.rglob("*")
            if path.is_dir()
        }
    )


NOT_ZONES = [
    *_zone_folders(),
    "zone.tab",
    "tzdata.zi",
    "leapseconds",
    "localtime",  # the server's own zone, not the client's
    "/etc/localtime",
    "../../../../etc/passwd",
    "Europe/../Europe/Vienna",
    "Europe/Vienna\x00",
    "",
    "europe/vienna",
]


def test_the_folders_are_many_and_include_the_audits():
    assert {"Europe", "America", "Etc", "Australia"} <= set(NOT_ZONES)


@pytest.mark.parametrize("path", DAY_BODIES)
@pytest.mark.slow
def test_a_name_that_is_not_a_zone_is_a_422_naming_the_timezone(client, path):
    prefix = DAY_BODIES[path][1]
    for name in NOT_ZONES:
        direct, _ = post_both_ways(client, path, day_body(path, timezone=name))
        assert direct == [f"{prefix}timezone"], name


def test_every_zone_of_the_database_is_taken(client):
    # A sample across the whole list: the check refuses folders, not zones.
    from zoneinfo import available_timezones

    zones = sorted(available_timezones() - {"localtime"})
    for zone in [*zones[:: max(1, len(zones) // 25)], "Etc/GMT-14", "Pacific/Kiritimati"]:
        response = client.post(
            "/v1/studies/speed-sweep",
            json=day_body("/v1/studies/speed-sweep", timezone=zone, speeds_kmh=[50]),
        )
        assert response.status_code == 200, (zone, response.text[:300])


# --- the first and the last days of the calendar, in every offset ------------------------------

ZONES = ["Asia/Tokyo", "Europe/Vienna", "Etc/GMT-14", "America/New_York", "Etc/GMT+12", None]


@pytest.mark.parametrize("path", DAY_BODIES)
@pytest.mark.parametrize("zone", ZONES)
def test_the_start_of_the_calendar_is_a_422_naming_the_date(client, path, zone):
    prefix = DAY_BODIES[path][1]
    if path == "/v1/fleet-plans":  # each van has its shift
        body = day_body(path, date="0001-01-01", timezone=zone)
        body["vehicles"] = [v | {"shift_start": "00:00"} for v in body["vehicles"]]
    elif path == "/v1/studies/scenarios":  # the season's date is the day planned
        body = day_body(path, start_time="00:00", timezone=zone)
        body["seasons"] = [{"name": "first", "date": "0001-01-01"}]
    else:
        body = day_body(path, date="0001-01-01", start_time="00:00", timezone=zone)
    expected = ["seasons[0].date"] if path == "/v1/studies/scenarios" else [f"{prefix}date"]
    direct, _ = post_both_ways(client, path, body)
    assert direct == expected
    message = client.post(path, json=body).json()["errors"][0]["message"]
    assert "year 1" in message and "0001-01-03" in message


def test_a_season_whose_clock_skips_the_start_is_refused_at_submission(client):
    # It was accepted as a job and failed later; synchronously it was found after the solve.
    body = day_body("/v1/studies/scenarios", start_time="02:30")
    body["seasons"] = [
        {"name": "winter", "date": "2026-01-15"},
        {"name": "spring forward", "date": "2026-03-29"},  # Vienna skips 02:00–03:00
    ]
    direct, _ = post_both_ways(client, "/v1/studies/scenarios", body)
    assert direct == ["seasons[1].date"]


@pytest.mark.parametrize("zone", ZONES)
def test_the_first_day_the_message_offers_is_planned(client, zone):
    body = with_date(PLAN_EXAMPLE, date="0001-01-03", start_time="00:00", timezone=zone)
    answer = client.post("/v1/plans", json=body)
    assert answer.status_code == 200, answer.text[:300]
    assert answer.json()["legs"][0]["depart"].startswith("0001-01-03T00:00:00")


@pytest.mark.parametrize("offset", ["+14:00", "+01:00", "Z", "-12:00"])
def test_a_simulation_at_the_start_of_the_calendar_names_start(client, offset):
    body = SIMULATE_EXAMPLE | {"start": f"0001-01-01T00:00:00{offset}"}
    assert named(client.post("/v1/simulate", json=body), body) == ["start"]


# --- dates, instants and clock times: strict ISO, ASCII digits ---------------------------------

ARABIC_INDIC_NINE, FULLWIDTH_ONE = "\u0669", "\uff11"


@pytest.mark.parametrize(
    ("path", "change", "field"),
    [
        ("/v1/plans", {"date": "2026-07-15T00:00:00"}, "date"),
        ("/v1/plans", {"date": "2026-07-15 00:00"}, "date"),
        ("/v1/plans", {"date": "20260715"}, "date"),
        ("/v1/plans", {"date": "2026-W29-3"}, "date"),
        ("/v1/plans", {"date": f"2026-07-{FULLWIDTH_ONE}5"}, "date"),
        ("/v1/plans", {"start_time": f"1{ARABIC_INDIC_NINE}:00"}, "start_time"),
        ("/v1/plans", {"start_time": f"{FULLWIDTH_ONE}9:00"}, "start_time"),
        ("/v1/plans", {"start_time": "9:00"}, "start_time"),
        ("/v1/plans", {"start_time": "19:00:00"}, "start_time"),
        ("/v1/fleet-plans", {"date": "2026-07-15T00:00:00"}, "date"),
        ("/v1/studies/speed-sweep", {"start_time": f"1{ARABIC_INDIC_NINE}:00"}, "start_time"),
        ("/v1/simulate", {"start": f"2026-07-15T1{ARABIC_INDIC_NINE}:00:00+02:00"}, "start"),
        ("/v1/simulate", {"start": "2026-07-15"}, "start"),
    ],
)
def test_a_date_or_time_not_in_strict_iso_is_a_422(client, path, change, field):
    base = {**DAY_BODIES, "/v1/simulate": (SIMULATE_EXAMPLE, "")}[path][0]
    body = copy.deepcopy(base) | change
    assert named(client.post(path, json=body), body) == [field]


def test_a_fleet_shift_in_other_digits_names_the_vehicle(client):
    body = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    body["vehicles"][1]["shift_end"] = f"1{ARABIC_INDIC_NINE}:00"
    assert named(client.post("/v1/fleet-plans", json=body), body) == ["vehicles[1].shift_end"]


def test_the_date_patterns_are_in_the_schema():
    date = SCHEMAS["PlanRequest"]["properties"]["date"]
    assert date["pattern"] == r"^[0-9]{4}-[0-9]{2}-[0-9]{2}$"
    assert "[0-9]" in SCHEMAS["PlanRequest"]["properties"]["start_time"]["pattern"]


# --- numbers: every field with a physical minimum refuses what is below it, subnormals too ----


def _bounded_fields(schema_name: str) -> list[tuple[str, float]]:
    """The number fields of a request section whose schema states a positive minimum."""
    found = []
    for name, spec in SCHEMAS[schema_name]["properties"].items():
        for option in [spec, *spec.get("anyOf", [])]:
            if option.get("type") == "number" and option.get("minimum", 0) > 0:
                found.append((name, float(option["minimum"])))
    return found


SECTIONS = ["VehicleRequest", "CargoBoxRequest", "BatteryRequest"]
SECTION_KEY = {
    "VehicleRequest": "vehicle",
    "CargoBoxRequest": "cargo_box",
    "BatteryRequest": "battery",
}
BOUNDED = [
    (SECTION_KEY[section], name, minimum)
    for section in SECTIONS
    for name, minimum in _bounded_fields(section)
]
SUBNORMALS = [5e-324, 1e-320, 1e-310]


def test_the_bounded_fields_include_the_audits():
    fields = {(section, name) for section, name, _ in BOUNDED}
    assert {("cargo_box", "wall_area_m2"), ("cargo_box", "wall_heat_transfer_w_m2k")} <= fields
    assert ("vehicle", "max_motor_power_w") in fields and len(fields) >= 30


def van_section(section: str, name: str, value: float) -> dict[str, Any]:
    base = {"preset": "paper-generic"} if section == "vehicle" else {}
    if section == "cargo_box":
        base = {"mode": "dynamic"}
    return base | {name: value}


@pytest.mark.parametrize(("section", "name", "minimum"), BOUNDED)
@pytest.mark.slow
def test_below_a_physical_minimum_is_a_422_on_every_endpoint(client, section, name, minimum):
    for value in [*SUBNORMALS, minimum * 0.999]:
        part = van_section(section, name, value)
        simulate = SIMULATE_EXAMPLE | {section: part}
        assert named(client.post("/v1/simulate", json=simulate), simulate) == [f"{section}.{name}"]
        plan = PLAN_EXAMPLE | {section: part}
        assert post_both_ways(client, "/v1/plans", plan)[0] == [f"{section}.{name}"]
        fleet = copy.deepcopy(FLEET_PLAN_EXAMPLE)
        fleet["vehicles"][1][section] = fleet["vehicles"][1].get(section, {}) | part
        assert post_both_ways(client, "/v1/fleet-plans", fleet)[0] == [
            f"vehicles[1].{section}.{name}"
        ]


def _exclusive_minimums(node: Any, path: str = "") -> list[str]:
    if isinstance(node, dict):
        here = [path] if "exclusiveMinimum" in node else []
        return here + [m for k, v in node.items() for m in _exclusive_minimums(v, f"{path}.{k}")]
    if isinstance(node, list):
        return [m for i, v in enumerate(node) for m in _exclusive_minimums(v, f"{path}[{i}]")]
    return []


def test_no_number_is_bounded_only_by_being_positive():
    # "> 0" admits 5e-324, which the physics divides by: every positive quantity states the
    # least value that means something (schemathesis found speeds_kmh: [5e-324] this way).
    assert _exclusive_minimums(SCHEMAS) == []


@pytest.mark.parametrize(
    ("path", "body", "field"),
    [
        (
            "/v1/studies/speed-sweep",
            SPEED_SWEEP_EXAMPLE | {"speeds_kmh": [40, 5e-324]},
            "speeds_kmh[1]",
        ),
        ("/v1/plans", PLAN_EXAMPLE | {"time_limit_s": 5e-324}, "time_limit_s"),
        ("/v1/fleet-plans", FLEET_PLAN_EXAMPLE | {"time_limit_s": 1e-310}, "time_limit_s"),
        (
            "/v1/simulate",
            SIMULATE_EXAMPLE | {"cycle": {"street_type": "urban", "distance_m": 1e-320}},
            "cycle.distance_m",
        ),
    ],
)
def test_subnormal_speeds_budgets_and_distances_are_a_422(client, path, body, field):
    assert named(client.post(path, json=body), body) == [field]


@pytest.mark.parametrize(("section", "name", "minimum"), BOUNDED)
def test_at_a_physical_minimum_the_answer_is_finite(client, section, name, minimum):
    body = SIMULATE_EXAMPLE | {section: van_section(section, name, minimum)}
    if section == "battery":  # the least battery still holds the reserve it is asked to
        body["battery"] |= {"min_soc": 0.0}
    if name == "gross_mass_kg":  # the lightest rating rates the lightest van, empty
        body["vehicle"] |= {"mass_kg": minimum}
        body["payload_kg"] = 0.0
    answer = client.post("/v1/simulate", json=body)
    assert answer.status_code == 200, answer.text[:300]
    result = answer.json()
    assert all(math.isfinite(v) and v >= 0 for v in result["energy_kwh"].values())
    assert result["distance_m"] == pytest.approx(8000, rel=1e-6)


# --- a client's matrix: the distance it gives is driven ---------------------------------------


def matrix_plan(distance_m: float, duration_s: float, n_stops: int = 3) -> dict[str, Any]:
    n = n_stops + 1
    return PLAN_EXAMPLE | {
        "stops": PLAN_EXAMPLE["stops"][:n_stops],
        "keep_order": True,
        "matrix": {
            "distances_m": [[0.0 if i == j else distance_m for j in range(n)] for i in range(n)],
            "durations_s": [[0.0 if i == j else duration_s for j in range(n)] for i in range(n)],
        },
    }


@pytest.mark.parametrize(
    ("distance_m", "duration_s", "accel_mps2"),
    [
        (10, 1, None),
        (10, 1, 5.0),
        (10, 1, 0.3),
        (30, 1, None),
        (1000, 20, None),
        (5e4, 1, None),
        (1e5, 1000, None),
    ],
)
@pytest.mark.slow
def test_a_leg_faster_than_any_van_keeps_its_distance_and_says_so(
    client, distance_m, duration_s, accel_mps2
):
    """Also beyond 250 km/h (100 km in 1,000 s): the audit's 422 named ``speed_mps[35]``,
    a field the client never sent."""
    body = matrix_plan(distance_m, duration_s)
    if accel_mps2 is not None:
        body["vehicle"] = {"preset": "paper-generic", "max_acceleration_mps2": accel_mps2}
    if distance_m > 1e4:
        body["battery"] = {"usable_capacity_kwh": 1000}
    answer = client.post("/v1/plans", json=body)
    assert answer.status_code == 200, answer.text[:300]
    result = answer.json()
    assert [leg["distance_m"] for leg in result["legs"]] == pytest.approx([distance_m] * 4)
    assert result["totals"]["energy_kwh"]["traction"] > 0
    warning = next(w for w in result["warnings"] if "faster than a van can drive" in w)
    assert warning.startswith("matrix.durations_s[0][1]")
    # The van takes the time it needs, at least the client's.
    for leg in result["legs"]:
        assert leg["duration_s"] >= duration_s


@pytest.mark.slow
def test_a_fleet_on_a_matrix_faster_than_any_van_keeps_its_distances(client):
    body = FLEET_PLAN_EXAMPLE | {
        "stops": PLAN_EXAMPLE["stops"][:3],
        "matrix": matrix_plan(1e5, 1000)["matrix"],
        "vehicles": [
            vehicle | {"battery": {"usable_capacity_kwh": 1000}, "shift_end": "23:00"}
            for vehicle in FLEET_PLAN_EXAMPLE["vehicles"]
        ],
    }
    answer = client.post("/v1/fleet-plans", json=body)
    assert answer.status_code == 200, answer.text[:300]
    legs = [leg for route in answer.json()["routes"] for leg in route["legs"]]
    assert [leg["distance_m"] for leg in legs] == pytest.approx([1e5] * len(legs))


def test_a_leg_a_van_can_drive_in_its_time_has_no_warning(client):
    result = client.post("/v1/plans", json=matrix_plan(1000, 120)).json()
    assert not any("faster than a van" in w for w in result["warnings"])
    assert [leg["duration_s"] for leg in result["legs"]] == pytest.approx([120] * 4)


def test_a_sweep_at_its_top_speed_with_the_most_aggressive_driver_is_answered(client):
    # Inside the documented ranges, so answered — it named speed_mps[35] before.
    body = SPEED_SWEEP_EXAMPLE | {"speeds_kmh": [50, 200], "driver_aggressiveness": 1}
    answer = client.post("/v1/studies/speed-sweep", json=body)
    assert answer.status_code == 200, answer.text[:300]
    assert [p["speed_kmh"] for p in answer.json()["points"]] == [50, 200]
    faster = body | {"speeds_kmh": [50, 200.5]}
    assert named(client.post("/v1/studies/speed-sweep", json=faster), faster) == ["speeds_kmh[1]"]


# --- a motor power cap: the van drives slower, the energy is not lost --------------------------


def rolling_bounds(client, payload_kg: float, distance_m: float, cap_w: float):
    """Hand calculation on the paper's van: the wheels need at least the rolling force
    m·g·c_rr·f at every speed, so a van capped at P drives no faster than P / (m·g·c_rr·f) —
    a least duration [s] — and its battery gives at least that force times the distance over
    the drivetrain efficiency — a least traction energy [kWh] (acceleration and a closed
    round's climbs give back at most what they took; drag only adds)."""
    presets = client.get("/v1/presets").json()["presets"]
    van = next(p for p in presets if p["name"] == "paper-generic")["vehicle"]
    force_n = (
        (van["mass_kg"] + payload_kg)
        * 9.81
        * van["rolling_resistance_coefficient"]
        * van["rolling_resistance_factor"]
    )
    return distance_m * force_n / cap_w, distance_m * force_n / van["drivetrain_efficiency"] / 3.6e6


@pytest.mark.parametrize("cap_w", [20_000, 10_000, 3_000, 1_000])
def test_a_capped_van_drives_the_trace_slower_and_the_energy_stays(client, cap_w):
    # Issue #21: 0.522 kWh uncapped, 0.114 kWh at 1 kW in the same 348 s.
    trace = SIMULATE_EXAMPLE | {"cycle": {"street_type": "urban", "distance_m": 3000}}
    free = client.post("/v1/simulate", json=trace).json()
    body = trace | {"vehicle": {"preset": "paper-generic", "max_motor_power_w": cap_w}}
    capped = client.post("/v1/simulate", json=body).json()
    least_s, least_kwh = rolling_bounds(client, 0.0, 3000.0, cap_w)
    assert capped["distance_m"] == pytest.approx(free["distance_m"], rel=1e-6)
    assert capped["duration_s"] > free["duration_s"] and capped["duration_s"] >= least_s
    # Slower is less drag and less braking: no more than uncapped, and never below rolling.
    assert least_kwh < capped["energy_kwh"]["traction"] <= free["energy_kwh"]["traction"] * 1.01
    assert any("motor's" in w and "cap" in w for w in capped["warnings"])
    # The cab, the box and the auxiliaries run for the longer trip.
    assert capped["energy_kwh"]["auxiliaries"] > free["energy_kwh"]["auxiliaries"]


def test_a_capped_van_in_a_plan_drives_longer_legs(client):
    # Issue #21: at 1 W, 0.0006 kWh instead of 3.758 and the same 1835 s.
    free = client.post("/v1/plans", json=PLAN_EXAMPLE | {"keep_order": True}).json()
    body = PLAN_EXAMPLE | {
        "keep_order": True,
        "vehicle": {"preset": "paper-generic", "max_motor_power_w": 1000},
    }
    capped = client.post("/v1/plans", json=body).json()
    distance_m = free["totals"]["distance_m"]
    least_s, least_kwh = rolling_bounds(client, 0.0, distance_m, 1000.0)  # the empty van
    assert capped["tour"] == free["tour"]
    assert capped["totals"]["distance_m"] == pytest.approx(distance_m, rel=1e-6)
    driving = [leg["duration_s"] for leg in capped["legs"]]
    assert sum(driving) >= least_s
    assert all(
        c > f for c, f in zip(driving, [leg["duration_s"] for leg in free["legs"]], strict=True)
    )
    assert capped["totals"]["duration_s"] > free["totals"]["duration_s"]
    traction = capped["totals"]["energy_kwh"]["traction"]
    assert least_kwh < traction <= free["totals"]["energy_kwh"]["traction"] * 1.01
    assert any("motor's" in w and "cap" in w for w in capped["warnings"])


def test_a_cap_no_van_can_climb_with_is_a_422(client):
    body = {k: v for k, v in SIMULATE_EXAMPLE.items() if k != "cycle"} | {
        "speed_mps": [5.0] * 60,
        "dt_s": 1,
        "grade": 0.3,
        "door_openings": [],
        "vehicle": {"preset": "paper-generic", "max_motor_power_w": 1000},
    }
    assert named(client.post("/v1/simulate", json=body), body) == ["vehicle.max_motor_power_w"]


# --- how much a synchronous study may simulate -------------------------------------------------

FAR_STOP = {"id": "far-south", "lat": PLAN_EXAMPLE["depot"]["lat"] - 40.0, "lon": 16.4}


def far_study(drivers: int = 10, traffic: int = 10) -> dict[str, Any]:
    """The audit's study: one stop 4,450 km from the depot, 3 seasons × drivers × traffic."""
    return {
        "plan": PLAN_EXAMPLE | {"stops": [FAR_STOP]},
        "seasons": [
            {"name": name, "date": date}
            for name, date in [
                ("winter", "2026-01-15"),
                ("spring", "2026-04-15"),
                ("summer", "2026-07-15"),
            ]
        ],
        "driver_aggressiveness": [round(0.1 * i, 1) for i in range(drivers)],
        "traffic_density": [round(0.05 + 0.09 * i, 2) for i in range(traffic)],
    }


def test_a_study_that_would_run_for_minutes_is_a_413_pointing_to_jobs(client):
    response = client.post("/v1/studies/scenarios", json=far_study())
    assert response.status_code == 413, response.text[:300]
    assert response.headers["content-type"] == PROBLEM
    assert "POST /v1/jobs" in response.json()["detail"]
    job = client.post("/v1/jobs", json={"type": "scenarios", "request": far_study()})
    assert job.status_code == 202
    client.delete(f"/v1/jobs/{job.json()['id']}")


@pytest.mark.slow
def test_a_sweep_that_would_run_for_minutes_is_a_413_pointing_to_jobs(client):
    # With the default bound (a year of driving) a sweep within its other limits fits; a server
    # told to answer at most a day synchronously refuses eleven 20 km trips at 1 km/h.
    body = SPEED_SWEEP_EXAMPLE | {"speeds_kmh": [1] * 11}
    strict = app_client(max_sync_simulated_s=86_400)
    response = strict.post("/v1/studies/speed-sweep", json=body)
    assert response.status_code == 413 and "type speed-sweep" in response.json()["detail"]
    job = strict.post("/v1/jobs", json={"type": "speed-sweep", "request": body})
    assert job.status_code == 202
    strict.delete(f"/v1/jobs/{job.json()['id']}")


def test_the_same_study_smaller_is_answered(client):
    small = far_study(drivers=1, traffic=1)
    answer = client.post("/v1/studies/scenarios", json=small)
    assert answer.status_code == 200, answer.text[:300]
    assert len(answer.json()["cells"]) == 3
