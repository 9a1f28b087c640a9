"""Fleets that must charge, through the product as users send them (``time_limit_s`` and
nothing else about the search): Schneider, Stenger & Goeke's E-VRPTW instances in
``../shared/reference/evrptw`` sent as fleet plans over HTTP to the real service with
:data:`VANS_OFFERED` vans, every answer replayed by the instance's own rules and set beside the
best known, and summed up by class (c1, c2, r1, r2, rc1, rc2); and the Vienna day of the issue
(80 stops, 30 °C, 30 kWh reefer vans, a 22 kW depot charger and two 150 kW chargers) beside the
same fleet without chargers and with batteries that never bind.

An instance as a day: one distance unit is ``s`` km and one time unit ``s`` minutes (60 km/h),
``s`` = min(1, the day's minutes / the horizon); windows rounded inwards to whole minutes, but a
minute wide at least (:func:`day_window`); the instance's distances and times sent as the
client's matrix, the stations' rows after the stops (each station a charger of many points, no
plug-in time). The van's energy is linear in distance: no drag worth the name, every braking
recovered, no standing loads (the box at the ambient temperature, no cab air-conditioning, no
auxiliaries), a flat charging curve; its energy per km ``e`` is measured on the product, its
battery holds the instance's range (Q / r units of distance) at ``e``, and its chargers' power
makes the product's charge time per energy the instance's ``g``. The replay drives each answer's
tour by the instance's rules (energy r × distance, charge time g × energy, a charge never beyond
a full battery): a van of the product never uses less energy than the instance's, so what the
product plans holds there — but at a window open for an instant (C87 and C100 of r110, r111,
r209, r210, rc205 and rc207: ready = due), which no window of whole minutes is: the day gives it
a minute, and the replay holds the van to that minute there.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import re
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import httpx
import numpy as np

from benchmarks.common import print_table
from testbed.evrptw import FOLDER, Instance, best_known, read
from testbed.reference import vienna_stops
from testbed.services import Server

#: The time limit of each plan [s] (``COLDROUTE_BENCH_EVRPTW_S`` shortens it).
BUDGET_S = float(os.environ.get("COLDROUTE_BENCH_EVRPTW_S", "60"))
#: Only these instances (``COLDROUTE_BENCH_EVRPTW_INSTANCES``: names, comma-separated, as
#: ``c103_21``); every one when unset.
ONLY = {name for name in os.environ.get("COLDROUTE_BENCH_EVRPTW_INSTANCES", "").split(",") if name}
#: The last minute of the day a shift may end at.
DAY_END_MIN = 1439
#: Kilograms per unit of the instance's demand: light, so the van's mass hardly changes.
KG_PER_UNIT = 0.1
#: Vans offered on every instance (more than any best known uses).
VANS_OFFERED = 25
#: Where an answer that breaks the instance's rules is kept with its request.
KEPT = Path(tempfile.gettempdir()) / "coldroute-bench-evrptw"
#: Slack of the replay on times and energy (the windows are whole minutes).
TOLERANCE = 1e-6
#: The van whose energy is linear in distance (module docstring).
LINEAR_VAN: dict[str, Any] = {
    "vehicle": {
        "preset": "paper-generic",
        "drag_coefficient": 0.05,
        "air_density_kg_m3": 0.5,
        "drivetrain_efficiency": 1.0,
        "regen_efficiency": 1.0,
        "max_regen_deceleration_mps2": 10.0,
        "auxiliaries_power_w": 0.0,
        "cabin_hvac_enabled": False,
    },
    "cargo_box": {
        "setpoint_c": 20.0,
        "product_limit_c": 25.0,
        "standby_power_w": 0.0,
        "solar_absorptivity": 0.0,
    },
}
AMBIENT = {"t_min_c": 20, "t_max_c": 20}


@dataclass(frozen=True)
class Scaled:
    """An instance as a day: its km and minutes per unit, r, Q, g and the van's energy per
    unit of distance [kWh]."""

    instance: Instance
    unit: float
    kwh_per_unit: float

    @property
    def kind(self) -> Any:
        return self.instance.problem.kinds[0]

    @property
    def r(self) -> float:
        d = self.instance.problem.distance
        i, j = np.unravel_index(np.argmax(d), d.shape)
        return float(self.kind.energy[i, j] / d[i, j])

    @property
    def kwh_per_energy(self) -> float:
        """One of the instance's units of energy [kWh]."""
        return self.kwh_per_unit / self.r


def clock(minutes: float) -> str:
    return f"{int(minutes) // 60:02d}:{int(minutes) % 60:02d}"


def scaled(instance: Instance, kwh_per_km: float) -> Scaled:
    unit = min(1.0, DAY_END_MIN / float(instance.problem.due[0]))
    return Scaled(instance, unit, kwh_per_km * unit)


def day_window(day: Scaled, k: int) -> tuple[int, int]:
    """Place ``k``'s window in the day's minutes: rounded inwards to whole minutes, but a
    minute wide at least (some windows of the set are open for an instant)."""
    problem = day.instance.problem
    a, b = problem.ready[k] * day.unit, problem.due[k] * day.unit
    opens = math.ceil(a - 1e-9)
    return opens, max(min(math.floor(b + 1e-9), DAY_END_MIN), opens + 1)


def fleet_request(day: Scaled, time_limit_s: float) -> dict[str, Any]:
    """The instance as the JSON body of ``POST /v1/fleet-plans`` (module docstring)."""
    problem, ids, xy = day.instance.problem, day.instance.ids, day.instance.xy
    g = float(problem.charge_time[problem.stations[0]])
    power_kw = day.kwh_per_energy / (g * day.unit / 60.0)
    battery = {
        "usable_capacity_kwh": day.kind.battery * day.kwh_per_energy,
        "initial_soc": 1.0,
        "min_soc": 0.0,
        "temperature_derating": False,
        "charging_efficiency": 1.0,
        "max_charge_power_kw": min(power_kw * 2, 1000.0),
        "charging_curve": [{"soc": 0.0, "power_kw": power_kw}, {"soc": 1.0, "power_kw": power_kw}],
    }

    def where(k: int) -> dict[str, float]:
        dx, dy = (xy[k] - xy[0]) * day.unit * 1000.0
        return {"lat": 48.0 + dy / 111_000, "lon": 16.0 + dx / 74_000}

    return {
        "date": "2026-04-15",
        "timezone": "UTC",
        "depot": {"id": ids[0], **where(0)},
        "vehicles": [
            LINEAR_VAN
            | {
                "id": f"v{k}",
                "battery": battery,
                "payload_kg": day.kind.capacity * KG_PER_UNIT,
                "shift_start": "00:00",
                "shift_end": clock(day_window(day, 0)[1]),
                "breaks": "none",
            }
            for k in range(VANS_OFFERED)
        ],
        "stops": [
            {
                "id": ids[k],
                **where(k),
                "delivery_kg": float(problem.demand[k]) * KG_PER_UNIT,
                "service_time_s": float(problem.service[k]) * day.unit * 60.0,
                "door_open_s": 0.0,
                "time_windows": [
                    {"start": clock(day_window(day, k)[0]), "end": clock(day_window(day, k)[1])}
                ],
            }
            for k in problem.customers
        ],
        "chargers": [
            {"id": ids[k], **where(k), "power_kw": power_kw, "points": 50, "plug_minutes": 0}
            for k in problem.stations
        ],
        "matrix": {
            "distances_m": (problem.distance * day.unit * 1000.0).tolist(),
            "durations_s": (problem.duration * day.unit * 60.0).tolist(),
        },
        "weather": AMBIENT,
        "objective": "distance",
        "minimize_vehicles": True,
        "time_limit_s": time_limit_s,
    }


def replay(day: Scaled, answer: dict[str, Any]) -> tuple[float, str | None]:
    """The answer's routes driven by the instance's rules: their distance [units] and what
    they break, or None."""
    problem = day.instance.problem
    index = {place: k for k, place in enumerate(day.instance.ids)}
    kind, total, seen = day.kind, 0.0, []
    for route in answer["routes"]:
        charged = {c["arrive"]: c["battery_kwh"] / day.kwh_per_energy for c in route["charges"]}
        battery, clock_u, place = kind.battery, float(problem.ready[0]), 0
        for name, leg in zip(route["tour"][1:], route["legs"], strict=True):
            j = index[name]
            battery -= kind.energy[place, j]
            total += problem.distance[place, j]
            clock_u += problem.duration[place, j]
            if battery < -TOLERANCE * kind.battery:
                return total, f"{route['vehicle_id']} runs empty before {name}"
            # a window the day widened to a minute closes at the minute's end
            due = max(problem.due[j], day_window(day, j)[1] / day.unit)
            if clock_u > due + TOLERANCE:
                return total, f"{route['vehicle_id']} reaches {name} after its window"
            clock_u = max(clock_u, problem.ready[j]) + problem.service[j]
            if j in problem.stations:
                charge = min(charged.get(leg["arrive"], 0.0), kind.battery - battery)
                battery += charge
                clock_u += problem.charge_time[j] * charge
            elif j:
                seen.append(j)
            place = j
    if len(seen) != len(set(seen)):
        return total, "a customer is served twice"
    return total, None


def linear_kwh_per_km(plan: Any) -> tuple[float, float]:
    """The linear van's energy per km empty (the least it draws) on a 20 km leg there and
    back, and how far from linear
    it is on a 1 km leg (the ratio of the two per km) — through ``plan`` (a request body to
    an answer)."""
    per_km = []
    for km in (20.0, 1.0):
        body = {
            "date": "2026-04-15",
            "timezone": "UTC",
            "depot": {"id": "d", "lat": 48.0, "lon": 16.0},
            "vehicles": [
                LINEAR_VAN | {"id": "v", "payload_kg": 0, "battery": {"usable_capacity_kwh": 100}}
            ],
            "stops": [{"id": "s", "lat": 48.0 + km / 111, "lon": 16.0, "service_time_s": 0}],
            "matrix": {
                "distances_m": [[0, km * 1000], [km * 1000, 0]],
                "durations_s": [[0, km * 60], [km * 60, 0]],
            },
            "weather": AMBIENT,
            "time_limit_s": 1,
        }
        answer = plan(body)
        per_km.append(answer["totals"]["energy_kwh"]["total"] / (2 * km))
    return per_km[0], per_km[1] / per_km[0]


def _over_http(url: str, timeout_s: float) -> Any:
    def plan(body: dict[str, Any]) -> dict[str, Any]:
        response = httpx.post(f"{url}/v1/fleet-plans", json=body, timeout=timeout_s)
        assert response.status_code == 200, response.text[:500]
        return dict(response.json())

    return plan


def evrptw_tables(budget_s: float = BUDGET_S) -> None:
    """Every instance over HTTP at ``budget_s``, and the sum by class."""
    known = best_known()
    by_class: dict[str, list[Instance]] = {}
    for path in sorted(FOLDER.glob("*_21.txt")):
        if ONLY and path.stem not in ONLY:
            continue
        by_class.setdefault(re.sub(r"\d\d_21$", "", path.stem), []).append(read(path))
    # the classes in turn, so that a run cut short has seen each
    instances = [i for group in itertools.zip_longest(*by_class.values()) for i in group if i]
    server = Server({"COLDROUTE_MAX_TIME_LIMIT_S": str(max(budget_s, 60))}).start()
    rows = []
    found: dict[str, list[tuple[int, int, float, float]]] = {}
    try:
        plan = _over_http(server.url, budget_s * 4 + 60)
        kwh_per_km, short = linear_kwh_per_km(plan)
        for instance in instances:
            day = scaled(instance, kwh_per_km)
            started = time.perf_counter()
            body = fleet_request(day, budget_s)
            answer = plan(body)
            wall_s = time.perf_counter() - started
            distance, broken = replay(day, answer)
            if broken is not None:  # kept, to be explained: the request and its answer
                kept = KEPT / f"{instance.name}.json"
                kept.parent.mkdir(parents=True, exist_ok=True)
                kept.write_text(json.dumps({"request": body, "answer": answer, "broken": broken}))
                broken = f"{broken} (kept in {kept})"
            vans, best = known[instance.name]
            served = sum(len(route["stops"]) for route in answer["routes"])
            customers = len(instance.problem.customers)
            used = answer["totals"]["vehicles_used"]
            kind = re.sub(r"\d\d(_21)?$", "", instance.name)  # c101 (c101_21.txt): c1
            found.setdefault(kind, []).append(
                (used - vans, customers - served, distance / best - 1, wall_s)
            )
            rows.append(
                [
                    instance.name,
                    f"{vans} / {best:.1f}",
                    f"{served}/{customers}",
                    f"{used} ({used - vans:+d})",
                    f"{distance:.1f} ({(distance / best - 1) * 100:+.1f} %)",
                    sum(len(route["charges"]) for route in answer["routes"]),
                    "yes" if broken is None else f"no: {broken}",
                    f"{wall_s:.0f}",
                    answer["solver"]["stopped_by"],
                ]
            )
            print("| " + " | ".join(str(cell) for cell in rows[-1]) + " |", flush=True)
    finally:
        server.close()
    print_table(
        f"E-VRPTW (Schneider et al. 2014) as fleet plans over HTTP, time_limit_s {budget_s:g} "
        f"alone, {VANS_OFFERED} vans offered (the linear van: {kwh_per_km:.4f} kWh/km; on 1 km "
        f"legs {short:.3f}× that)",
        [
            "instance",
            "best known (vans / distance)",
            "served",
            "vans",
            "distance (vs best known)",
            "charges",
            "holds by the instance's rules",
            "answer [s]",
            "stopped_by",
        ],
        rows,
    )
    print_table(
        "E-VRPTW by class: vans over the best known, stops left out, distance against the best "
        "known (its vans counted or not)",
        [
            "class",
            "instances",
            "vans over (mean, most)",
            "within +1 van",
            "unserved",
            "distance (mean, worst)",
            "answer [s] (most)",
        ],
        [
            [
                kind,
                len(results),
                f"{np.mean([r[0] for r in results]):+.2f}, {max(r[0] for r in results):+d}",
                f"{sum(r[0] <= 1 for r in results)}/{len(results)}",
                sum(r[1] for r in results),
                f"{np.mean([r[2] for r in results]) * 100:+.1f} %, "
                f"{max(r[2] for r in results) * 100:+.1f} %",
                f"{max(r[3] for r in results):.0f}",
            ]
            for kind, results in sorted(found.items())
        ],
    )


def vienna_day(chargers: bool, battery_kwh: float, budget_s: float) -> dict[str, Any]:
    """The issue's Vienna day: 80 stops within 30 km (a box of ±21 km), 30 °C, ten
    ``ev-van-3.5t-reefer`` with ``battery_kwh`` on the default shift (08:00–18:00, EU breaks);
    with ``chargers`` a 22 kW depot charger and two 150 kW ones 10 km north and south."""
    rng = np.random.default_rng(29)
    stops = vienna_stops(rng, 80, 300.0, 90.0, 10.0, spread_deg=(0.19, 0.28))
    depot: dict[str, Any] = {"id": "depot", "lat": 48.21, "lon": 16.37}
    body: dict[str, Any] = {
        "date": "2026-07-15",
        "timezone": "Europe/Vienna",
        "depot": depot,
        "vehicles": [
            {
                "id": f"van-{k + 1}",
                "vehicle": {"preset": "ev-van-3.5t-reefer"},
                "battery": {"usable_capacity_kwh": battery_kwh, "min_soc": 0.1},
            }
            for k in range(10)
        ],
        "stops": stops,
        "weather": {"t_min_c": 30, "t_max_c": 30},
        "objective": "distance",
        "minimize_vehicles": True,
        "time_limit_s": budget_s,
    }
    if chargers:
        body["depot"] = depot | {"charger": {"power_kw": 22, "points": 2}}
        body["chargers"] = [
            {"id": "hpc-north", "lat": 48.30, "lon": 16.40, "power_kw": 150, "points": 2},
            {"id": "hpc-south", "lat": 48.12, "lon": 16.33, "power_kw": 150, "points": 2},
        ]
    return body


#: Time limits of the Vienna day with chargers [s]: its outcome swings with the work, so the
#: table shows three.
VIENNA_LIMITS_S = (30.0, 45.0, 60.0)


def vienna_table(budget_s: float = 45.0) -> None:
    """The Vienna day with chargers (at each of :data:`VIENNA_LIMITS_S`) beside the same fleet
    without and with batteries that never bind (at ``budget_s``), over HTTP."""
    rows = []
    answers: dict[str, dict[str, Any]] = {}
    walls: dict[str, float] = {}
    with_server = Server({"COLDROUTE_MAX_TIME_LIMIT_S": str(max(*VIENNA_LIMITS_S, 60))}).start()
    try:
        plan = _over_http(with_server.url, max(VIENNA_LIMITS_S) * 4 + 60)
        days = {
            f"30 kWh, chargers, {limit:g} s": vienna_day(True, 30.0, limit)
            for limit in VIENNA_LIMITS_S
        } | {
            f"30 kWh, no charger, {budget_s:g} s": vienna_day(False, 30.0, budget_s),
            f"never binding (500 kWh), {budget_s:g} s": vienna_day(False, 500.0, budget_s),
        }
        for name, body in days.items():
            started = time.perf_counter()
            answers[name] = plan(body)
            walls[name] = time.perf_counter() - started
    finally:
        with_server.close()
    free = answers[f"never binding (500 kWh), {budget_s:g} s"]["totals"]["distance_m"]
    for name, answer in answers.items():
        rows.append(
            [
                name,
                sum(len(route["stops"]) for route in answer["routes"]),
                answer["totals"]["vehicles_used"],
                f"{answer['totals']['distance_m'] / 1000:.1f}",
                f"{(answer['totals']['distance_m'] / free - 1) * 100:+.1f} %",
                sum(len(route["charges"]) for route in answer["routes"]),
                f"{walls[name]:.0f}",
                answer["solver"]["stopped_by"],
            ]
        )
    print_table(
        "The Vienna day (80 stops within ~30 km, 30 °C, ev-van-3.5t-reefer) over HTTP, "
        "time_limit_s alone",
        [
            "fleet",
            "served",
            "vans",
            "distance [km]",
            "vs never binding",
            "charges",
            "answer [s]",
            "stopped_by",
        ],
        rows,
    )


def main() -> None:
    evrptw_tables()
    vienna_table()


if __name__ == "__main__":
    if os.environ.get("COLDROUTE_BENCH_ONLY") == "vienna":
        vienna_table()
    else:
        main()
