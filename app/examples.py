"""Realistic request examples shown in Swagger UI; the tests send them as they are."""

from __future__ import annotations

import math
from typing import Any

# A morning round in Vienna: depot in Simmering, eight grocery and pharmacy stops.
_VIENNA_STOPS = [
    ("billa-landstrasse", 48.2006, 16.3862, 120, 30),
    ("spar-wieden", 48.1925, 16.3671, 60, 25),
    ("apotheke-margareten", 48.1878, 16.3553, 40, 10),
    ("merkur-mariahilf", 48.1967, 16.3446, 80, 45),
    ("hofer-neubau", 48.2036, 16.3489, 60, 35),
    ("bio-josefstadt", 48.2108, 16.3485, 40, 20),
    ("cafe-innere-stadt", 48.2097, 16.3702, 60, 15),
    ("billa-leopoldstadt", 48.2186, 16.3921, 60, 30),
]

PLAN_EXAMPLE: dict[str, Any] = {
    "date": "2026-07-15",
    "start_time": "09:00",
    "timezone": "Europe/Vienna",
    "depot": {"id": "depot-simmering", "lat": 48.1703, "lon": 16.4207, "elevation_m": 160},
    "stops": [
        {
            "id": stop_id,
            "lat": lat,
            "lon": lon,
            "service_time_s": service_s,
            "door_open_s": service_s // 2,
            "delivery_kg": delivery_kg,
        }
        for stop_id, lat, lon, service_s, delivery_kg in (
            (s[0], s[1], s[2], 300 + 2 * s[3], s[4]) for s in _VIENNA_STOPS
        )
    ],
    "vehicle": {"preset": "paper-generic"},
    "payload_kg": 550,
    "battery": {"usable_capacity_kwh": 40, "initial_soc": 0.95, "min_soc": 0.15},
    "weather": {"t_min_c": 18, "t_max_c": 31},
    "driver_aggressiveness": 0.5,
    "objective": "energy",
}

# A long summer day of one van: 40 stops spread over 15 km around the centre (a golden-angle
# spiral), about twice its 40 kWh with the refrigeration at 31 °C. The depot's 22 kW charger
# brings it back to charge what the rest needs (its figures: app/response_examples.json).
_GOLDEN_ANGLE = math.pi * (3 - math.sqrt(5))
CHARGING_PLAN_EXAMPLE: dict[str, Any] = {
    "date": "2026-07-15",
    "start_time": "07:00",
    "timezone": "Europe/Vienna",
    "depot": {
        "id": "depot-centre",
        "lat": 48.21,
        "lon": 16.37,
        "charger": {"power_kw": 22, "points": 1, "price_per_kwh": 0.3, "plug_minutes": 2},
    },
    "stops": [
        {
            "id": f"shop-{k + 1:02d}",
            "lat": round(
                48.21 + 15_000 * math.sqrt((k + 8) / 48) * math.sin(k * _GOLDEN_ANGLE) / 111_000, 5
            ),
            "lon": round(
                16.37 + 15_000 * math.sqrt((k + 8) / 48) * math.cos(k * _GOLDEN_ANGLE) / 74_000, 5
            ),
            "service_time_s": 600,
            "door_open_s": 180,
            "delivery_kg": 8,
        }
        for k in range(40)
    ],
    "vehicle": {"preset": "paper-generic"},
    "payload_kg": 400,
    "battery": {"usable_capacity_kwh": 40, "initial_soc": 1.0, "min_soc": 0.1},
    "weather": {"t_min_c": 21, "t_max_c": 31},
}

# The same day with no charger at the depot and two on the way: a 150 kW one in the Prater
# (open 06:00–22:00) and an 11 kW one beside the depot. The fast one wins: it stops there
# between stops.
EN_ROUTE_CHARGING_EXAMPLE: dict[str, Any] = CHARGING_PLAN_EXAMPLE | {
    "depot": {"id": "depot-centre", "lat": 48.21, "lon": 16.37},
    "chargers": [
        {
            "id": "hpc-prater",
            "lat": 48.215,
            "lon": 16.40,
            "power_kw": 150,
            "points": 4,
            "price_per_kwh": 0.59,
            "plug_minutes": 2,
            "opening_hours": [{"start": "06:00", "end": "22:00"}],
        },
        {"id": "ac-slow", "lat": 48.212, "lon": 16.372, "power_kw": 11, "price_per_kwh": 0.35},
    ],
}

# The same day's stops for a fleet of two, with the shops' receiving windows: the bakery café
# and the pharmacy take goods before they open, the supermarkets in the late morning.
_WINDOWS = {
    "cafe-innere-stadt": [{"start": "07:00", "end": "08:00"}],
    "apotheke-margareten": [{"start": "07:00", "end": "08:30"}],
    "billa-landstrasse": [{"start": "10:00", "end": "12:00"}],
    "billa-leopoldstadt": [{"start": "10:00", "end": "12:00"}],
    "merkur-mariahilf": [{"start": "07:00", "end": "09:00"}, {"start": "13:00", "end": "15:00"}],
}
FLEET_PLAN_EXAMPLE: dict[str, Any] = {
    "date": "2026-07-15",
    "timezone": "Europe/Vienna",
    "depot": PLAN_EXAMPLE["depot"],
    "vehicles": [
        {
            "id": "van-1",
            "vehicle": {"preset": "ev-van-3.5t-reefer"},
            "payload_kg": 500,
            "shift_start": "06:30",
            "shift_end": "14:30",
        },
        {
            "id": "van-2",
            "vehicle": {"preset": "paper-generic"},
            "payload_kg": 400,
            "battery": {"usable_capacity_kwh": 40, "min_soc": 0.15},
            "shift_start": "06:30",
            "shift_end": "14:30",
        },
    ],
    "stops": [
        stop | ({"time_windows": _WINDOWS[stop["id"]]} if stop["id"] in _WINDOWS else {})
        for stop in PLAN_EXAMPLE["stops"]
    ],
    "weather": {"t_min_c": 18, "t_max_c": 31},
    "objective": "energy",
    "minimize_vehicles": True,
    # the work 2 s buys on the reference machine, with room to finish it on a slower one:
    # the example answers the same everywhere (its figures are recorded)
    "time_limit_s": 3,
    "work_s": 1.445,
}

SIMULATE_EXAMPLE: dict[str, Any] = {
    "cycle": {"street_type": "urban", "distance_m": 8000, "driver_aggressiveness": 0.5},
    "start": "2026-07-15T11:00:00+02:00",
    "location": {"lat": 48.21, "lon": 16.37},
    "vehicle": {"preset": "paper-generic"},
    "weather": {"t_min_c": 18, "t_max_c": 31},
    "door_openings": [{"start_s": 300, "duration_s": 90}],
}

SIMULATE_TRACE_EXAMPLE: dict[str, Any] = {
    "speed_mps": [0, 2, 4, 6, 8, 8, 8, 6, 3, 0],
    "dt_s": 1,
    "grade": 0.02,
    "start": "2026-01-20T08:30:00+01:00",
    "location": {"lat": 48.21, "lon": 16.37},
    "vehicle": {"preset": "paper-generic", "mass_kg": 1900},
    "include_series": True,
}

SPEED_SWEEP_EXAMPLE: dict[str, Any] = {
    "speeds_kmh": [20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120],
    "distance_m": 20000,
    "date": "2026-07-15",
    "start_time": "12:00",
    "timezone": "Europe/Vienna",
    "location": {"lat": 48.21, "lon": 16.37},
    "weather": {"t_min_c": 20, "t_max_c": 32},
    "vehicle": {"preset": "paper-generic"},
}

SCENARIOS_EXAMPLE: dict[str, Any] = {
    "plan": PLAN_EXAMPLE,
    "seasons": [
        {"name": "winter", "date": "2026-01-15", "weather": {"t_min_c": -10, "t_max_c": -2}},
        {"name": "summer", "date": "2026-07-15", "weather": {"t_min_c": 18, "t_max_c": 31}},
    ],
    "driver_aggressiveness": [0.2, 0.5, 1.0],
    "traffic_density": [0.2, 0.8],
}


# Two routes as a fleet drives them, over 2026: the inner-city round on Mondays, Wednesdays and
# Fridays, a longer day of 24 stops on Tuesdays and Thursdays, each with frozen goods in its box;
# two batteries of the reefer van, and 45 minutes at the depot's 22 kW at lunch.
_FROZEN_BOX = {"product": "frozen", "setpoint_c": -22}
ELECTRIFICATION_EXAMPLE: dict[str, Any] = {
    "year": 2026,
    "timezone": "Europe/Vienna",
    "routes": [
        {
            "id": "inner-city",
            "depot": PLAN_EXAMPLE["depot"],
            "stops": PLAN_EXAMPLE["stops"],
            "start_time": "09:00",
            "days": {"weekdays": ["mon", "wed", "fri"]},
        },
        {
            "id": "long-day",
            "depot": {k: v for k, v in CHARGING_PLAN_EXAMPLE["depot"].items() if k != "charger"},
            "stops": sorted(  # driven round the centre, as a driver would
                CHARGING_PLAN_EXAMPLE["stops"][:24],
                key=lambda stop: math.atan2(stop["lat"] - 48.21, stop["lon"] - 16.37),
            ),
            "start_time": "07:00",
            "days": {"weekdays": ["tue", "thu"]},
        },
    ],
    "candidates": [
        {
            "id": f"reefer-{kwh}",
            "vehicle": {"preset": "ev-van-3.5t-reefer"},
            "battery": {"usable_capacity_kwh": kwh},
            "cargo_box": _FROZEN_BOX,
        }
        for kwh in (40, 70)
    ],
    "chargers": [{"where": "depot", "power_kw": 22, "minutes": 45}],
}


def _calibration_example() -> dict[str, Any]:
    """Two ten-minute trips at 1 Hz (stop-and-go, then a fast road) of the real reefer van
    with more drag and auxiliaries than its preset, as its telematics would log them: the
    battery power of each second, to the watt, with its sensor's noise, and the outside
    temperature."""
    import datetime as dt

    import numpy as np

    from core.params import PRESETS, Location, Weather
    from core.physics.simulate import CONSUMERS, simulate

    van = PRESETS["ev-van-3.5t-reefer"].van()
    truth = van.model_copy(
        update={
            "vehicle": van.vehicle.model_copy(
                update={"drag_coefficient": 0.38, "auxiliaries_power_w": 520.0}
            )
        }
    )

    def pattern(top_mps: float, cruise_s: int, stand_s: int) -> list[float]:
        ramp = [min(k * 1.0, top_mps) for k in range(int(top_mps) + 1)]
        once = ramp + [top_mps] * cruise_s + ramp[::-1] + [0.0] * stand_s
        return (once * (601 // len(once) + 1))[:601]

    start = dt.datetime(2026, 7, 15, 9, tzinfo=dt.UTC)
    location = Location(lat=48.21, lon=16.37)
    trips = []
    for k, speed in enumerate([pattern(13.0, 30, 15), pattern(25.0, 120, 5)]):
        begins = start + dt.timedelta(hours=k)
        outside_c = 24.0 + k  # the van's own thermometer, logged with the power
        weather = Weather(t_min_c=outside_c, t_max_c=outside_c)
        result = simulate(np.array(speed), 1.0, begins, location, truth, weather=weather)
        power = np.sum([result.power_w[c] for c in CONSUMERS], axis=0)
        # the current sensor's noise: 1 % of the power and 30 W, a fixed seed per trip
        power = power + (0.01 * np.abs(power) + 30.0) * np.random.default_rng(k).normal(
            size=power.size
        )
        logged = np.concatenate([[power[0]], power])
        trips.append(
            {
                "id": ["city", "ring-road"][k],
                "start": begins.isoformat(),
                "location": {"lat": 48.21, "lon": 16.37},
                "time_s": list(range(len(speed))),
                "speed_mps": speed,
                "ambient_c": [outside_c] * len(speed),
                "battery_power_w": [round(float(w)) for w in logged],
            }
        )
    return {
        "vehicle": {"preset": "ev-van-3.5t-reefer"},
        "parameters": ["drag_coefficient", "auxiliaries_power_w"],
        "trips": trips,
    }


CALIBRATION_EXAMPLE: dict[str, Any] = _calibration_example()


#: The morning round carrying chilled dairy (+6 °C at most, ATP Annex 3) loaded at 4 °C, and
#: carrying frozen food (−18 °C, brief rises of 3 K; a unit rated 7 kW at 0 °C, 3.3 kW at
#: the frozen set-point), each box simulated with its unit's capacity and the goods' own
#: temperature.
CHILLED_PLAN_EXAMPLE: dict[str, Any] = PLAN_EXAMPLE | {
    "cargo_box": {"product": "chilled-dairy", "load_temperature_c": 4.0, "mode": "dynamic"}
}
FROZEN_PLAN_EXAMPLE: dict[str, Any] = PLAN_EXAMPLE | {
    "cargo_box": {"product": "frozen", "mode": "dynamic", "refrigeration_capacity_w": 7000.0}
}
#: The chilled round with the unit's optimal strategy: pre-cooled at the depot, the air let
#: float within the band, the battery spared.
OPTIMAL_PLAN_EXAMPLE: dict[str, Any] = CHILLED_PLAN_EXAMPLE | {
    "refrigeration": {"strategy": "optimal", "objective": "energy"}
}


#: The request examples of /v1/plans and /v1/fleet-plans as Swagger shows them: name →
#: (summary, body). Their descriptions are their answers' figures (:func:`describe`), recorded
#: by ``make openapi`` and checked against a fresh run by the tests: they cannot drift.
PLAN_EXAMPLES: dict[str, tuple[str, dict[str, Any]]] = {
    "vienna-8-stops": ("A summer morning round in Vienna", PLAN_EXAMPLE),
    "vienna-40-stops-depot-charger": (
        "A summer day longer than the battery: it charges at the depot",
        CHARGING_PLAN_EXAMPLE,
    ),
    "vienna-40-stops-chargers-on-the-way": (
        "The same day with chargers on the way: it stops at the fast one",
        EN_ROUTE_CHARGING_EXAMPLE,
    ),
    "vienna-8-stops-chilled-dairy": (
        "The morning round with chilled dairy: the goods' temperature and the cold chain",
        CHILLED_PLAN_EXAMPLE,
    ),
    "vienna-8-stops-frozen": ("The morning round with frozen food", FROZEN_PLAN_EXAMPLE),
    "vienna-8-stops-chilled-dairy-optimal": (
        "The chilled round with the refrigeration unit's optimal schedule",
        OPTIMAL_PLAN_EXAMPLE,
    ),
}
FLEET_EXAMPLES: dict[str, tuple[str, dict[str, Any]]] = {
    "vienna-two-vans": (
        "Two vans, shop receiving windows, a summer day in Vienna (its work set)",
        FLEET_PLAN_EXAMPLE,
    ),
}


def describe(answer: dict[str, Any]) -> str:
    """The figures of a plan's or a fleet plan's answer, as its example's description says
    them."""
    if "routes" in answer:
        served = sum(len(route["stops"]) for route in answer["routes"])
        left = len(answer["unassigned"])
        totals = answer["totals"]
        vans = len(answer["routes"])
        return (
            f"{vans} van{'s' * (vans != 1)} serve{'s' * (vans == 1)} {served} of "
            f"{served + left} stops: "
            f"{totals['distance_m'] / 1000:.1f} km and {totals['energy_kwh']['total']:.1f} kWh "
            "in all."
        )
    energy = answer["totals"]["energy_kwh"]
    battery = answer["battery"]
    charges = answer["charges"]
    where = sorted({c["charger_id"] for c in charges})
    charged = (
        "no charge"
        if not charges
        else f"{len(charges)} charge{'s' * (len(charges) > 1)} at "
        + " and ".join("the depot" if w == "depot" else f"'{w}'" for w in where)
        + f" ({sum(c['minutes'] for c in charges):.0f} min)"
    )
    back = answer["legs"][-1]["arrive"][11:16]
    chain = answer.get("cold_chain")
    goods = (
        ""
        if chain is None
        else f" The goods between {chain['product_min_c']:.1f} and {chain['product_max_c']:.1f} "
        f"°C: the cold chain {chain['verdict']}."
    )
    unit = answer.get("refrigeration") or {}
    strategy = (
        f" The unit's optimal schedule: {unit['battery_kwh']:.2f} kWh from the battery against "
        f"the thermostat's {unit['thermostat_battery_kwh']:.2f}, {unit['grid_kwh']:.2f} from "
        "the grid pre-cooling at the depot."
        if unit.get("strategy") == "optimal"
        else ""
    )
    return (
        f"{energy['total']:.1f} kWh in all ({energy['refrigeration']:.1f} of them for the "
        f"refrigeration) on a {battery['usable_capacity_kwh']:g} kWh battery; {charged}; back "
        f"at {back}, its lowest charge {battery['min_soc']:.0%}.{goods}{strategy}"
    )


def record() -> dict[str, Any]:
    """The answers of the examples above from a real run (``python -m app.examples`` writes
    them to app/response_examples.json, which Swagger shows)."""
    import datetime as dt
    import tempfile

    from app.jobs.schemas import JobOut
    from app.operations import calibration, electrification, fleet_plan, plan, simulate, studies
    from app.schemas.calibration import CalibrationRequest
    from app.schemas.fleet import FleetPlanRequest
    from app.schemas.plans import PlanRequest
    from app.schemas.simulate import SimulateRequest
    from app.schemas.studies import ElectrificationRequest, ScenariosRequest, SpeedSweepRequest
    from app.settings import Settings
    from core.routing.tsp import prepare

    prepare()  # as the service's workers: no example pays for loading the compiled searches
    # The calibration's record goes to a database of its own, not to the checkout's.
    database = tempfile.mkdtemp(prefix="coldroute-examples-")
    settings = Settings(database_url=f"sqlite:///{database}/examples.db")
    planned = {
        name: plan.plan_response(plan.run_plan(PlanRequest.model_validate(body), settings))
        for name, (_, body) in PLAN_EXAMPLES.items()
    }
    answers = {name: answer.model_dump(mode="json") for name, answer in planned.items()} | {
        name: fleet_plan.fleet_response(
            fleet_plan.run_fleet_plan(FleetPlanRequest.model_validate(body), settings)
        ).model_dump(mode="json")
        for name, (_, body) in FLEET_EXAMPLES.items()
    }
    plan_json = answers["vienna-8-stops"]
    accepted = dt.datetime(2026, 7, 14, 22, 0, 3, tzinfo=dt.UTC)
    job = JobOut(
        id="6f1c2a9e-4b7d-4e0a-9a51-2f7f3c1d8e20",
        type="plan",
        status="succeeded",
        created_at=accepted,
        started_at=accepted + dt.timedelta(seconds=0.4),
        finished_at=accepted + dt.timedelta(seconds=0.5),
        attempts=1,
        result=planned["vienna-8-stops"],
    )
    return {
        "descriptions": {name: describe(answer) for name, answer in answers.items()},
        # each example's work, sent with it (openapi_doc.request_examples): its figures are
        # these whatever the machine and its load
        "replays": {name: answer["solver"]["replay"] for name, answer in answers.items()},
        "plan": plan_json,
        "fleet_plan": answers["vienna-two-vans"],
        "simulate": simulate.simulate_trace(
            SimulateRequest.model_validate(SIMULATE_EXAMPLE), settings
        ).model_dump(mode="json"),
        "speed_sweep": studies.sweep_speeds(
            SpeedSweepRequest.model_validate(SPEED_SWEEP_EXAMPLE), settings
        ).model_dump(mode="json"),
        "scenarios": studies.run_scenarios(
            ScenariosRequest.model_validate(SCENARIOS_EXAMPLE), settings
        ).model_dump(mode="json"),
        "electrification": electrification.run_study(
            ElectrificationRequest.model_validate(ELECTRIFICATION_EXAMPLE), settings
        ).model_dump(mode="json")
        | {"runtime_s": 4.2, "route_days_per_s": 124.0},  # this machine's, not the reader's
        "job": job.model_dump(mode="json"),
        "calibration": calibration.run_calibration(
            CalibrationRequest.model_validate(CALIBRATION_EXAMPLE), settings
        ).model_dump(mode="json")
        | {"id": "3b9d2f64-8c1e-4a7b-b0d5-6e2a9c4f7d13"},
    }


if __name__ == "__main__":
    import json
    from pathlib import Path

    target = Path(__file__).with_name("response_examples.json")
    target.write_text(json.dumps(record(), indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"wrote {target}")
