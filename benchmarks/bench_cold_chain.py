"""The refrigeration unit's strategy on planned days, through the plan's entry point
(``app.operations.plan.run_plan``, what ``POST /v1/plans`` runs): the reference summer day
(the ev-van-3.5t-reefer, 30 °C, 30 stops with 2-minute doors, chilled dairy at +6 °C at most,
500 kg loaded at +4 °C) with a thermostat and with the optimal schedule, a frozen day, a
winter day, a day whose battery the thermostat runs below its reserve, a fixed-speed (on-off)
unit's day and a day priced at the depot (the cost objective beside the energy one); the
battery energy of each, the grid's for pre-cooling, the cost, the goods' extremes and
verdict, and the answer's time."""

from __future__ import annotations

from typing import Any

import numpy as np

from app.operations.plan import run_plan
from app.schemas.plans import PlanRequest
from app.settings import Settings
from benchmarks.common import best_time_s, print_table
from core.planning.model import PlanResult

#: Stops of the reference day, their doors [s] and service [s].
STOPS = 30
DOOR_S = 120
SERVICE_S = 300
PAYLOAD_KG = 500.0
#: The depot's charger on the priced day.
PRICED_CHARGER = {"power_kw": 22, "price_per_kwh": 0.3}


def reference_day(**changes: Any) -> dict[str, Any]:
    """The reference summer day as a plan request (``changes`` on top)."""
    rng = np.random.default_rng(32)
    stops = [
        {
            "id": f"s{k}",
            "lat": 48.21 + float(rng.uniform(-0.05, 0.05)),
            "lon": 16.37 + float(rng.uniform(-0.08, 0.08)),
            "service_time_s": SERVICE_S,
            "door_open_s": DOOR_S,
            "delivery_kg": round(PAYLOAD_KG / STOPS - 0.05, 1),  # 16.6 kg: 498 of 500 kg
        }
        for k in range(STOPS)
    ]
    body = {
        "date": "2026-07-15",
        "start_time": "08:00",
        "timezone": "Europe/Vienna",
        "depot": {"id": "depot", "lat": 48.21, "lon": 16.37},
        "stops": stops,
        "vehicle": {"preset": "ev-van-3.5t-reefer"},
        "payload_kg": PAYLOAD_KG,
        "cargo_box": {"product": "chilled-dairy", "load_temperature_c": 4.0},
        "weather": {"t_min_c": 20, "t_max_c": 30},
        "time_limit_s": 10,
    }
    return body | changes


#: The frozen day's box: a unit rated 4.5 kW at 0 °C, 2.5 kW at the frozen band's −20 °C
#: (the reefer preset's 2.5 kW at 0 °C is a chilled unit: 1.1 kW at −24 °C, short of a hot
#: day's doors).
FROZEN_BOX = {"product": "frozen", "load_temperature_c": -22.0, "refrigeration_capacity_w": 4500.0}
#: The strategies each day is planned with: the thermostat first (the rows' reference).
STRATEGIES = [("thermostat", {"strategy": "thermostat"}), ("optimal", {"strategy": "optimal"})]


def planned(body: dict[str, Any], refrigeration: dict[str, str]) -> tuple[PlanResult, float]:
    request = PlanRequest.model_validate(body | {"refrigeration": refrigeration})
    settings = Settings()
    result = run_plan(request, settings)
    return result, best_time_s(lambda: run_plan(request, settings), repeat=3)


def rows_of(
    name: str, body: dict[str, Any], strategies: list[tuple[str, dict[str, str]]] = STRATEGIES
) -> list[list[object]]:
    rows = []
    kept: tuple[PlanResult, float] | None = None
    for label, refrigeration in strategies:
        result, seconds = planned(body, refrigeration)
        kept = kept or (result, seconds)
        unit, chain = result.refrigeration, result.cold_chain
        assert unit is not None and chain is not None
        thermostat, best = unit.baselines
        rows.append(
            [
                name,
                label,
                unit.followed,
                f"{unit.battery_kwh:.2f}",
                f"{unit.grid_kwh:.2f}",
                f"{-thermostat.battery_saved * 100:+.1f} %",
                f"{-best.battery_saved * 100:+.1f} % / {-best.total_saved * 100:+.1f} %",
                f"{best.setpoint_c:.1f} ({best.battery_kwh:.2f} + {best.grid_kwh:.2f})",
                "–" if unit.cost is None else f"{unit.cost:.3f}",
                f"{chain.product_min_c:.1f} … {chain.product_max_c:.1f}",
                chain.verdict,
                f"{result.battery.min_soc:.1%} ({'holds' if result.battery.feasible else 'below'})",
                f"{seconds * 1000:.0f} ({(seconds / kept[1] - 1) * 100:+.0f} %)",
            ]
        )
    return rows


def test_days() -> list[tuple[str, dict[str, Any]]]:
    """The reference summer day, a frozen one and a winter one, by name."""
    return [
        ("summer, chilled dairy", reference_day()),
        (
            "summer, frozen",
            reference_day(cargo_box=FROZEN_BOX),
        ),
        (
            "spring, chilled dairy",
            reference_day(date="2026-04-15", weather={"t_min_c": 8, "t_max_c": 16}),
        ),
        (
            "winter, chilled dairy",
            reference_day(date="2026-01-15", weather={"t_min_c": -12, "t_max_c": -4}),
        ),
        ("summer, 8 stops", reference_day(stops=reference_day()["stops"][:8])),
    ]


def main() -> None:
    days = test_days()
    reference = days[0][1]
    thermostat, _ = planned(reference, {"strategy": "thermostat"})
    optimal, _ = planned(reference, {"strategy": "optimal"})
    # a battery between what the two draw: the thermostat runs it below its reserve
    used = [
        (r.legs[0].soc_start - r.battery.min_soc) * r.battery.usable_capacity_kwh
        for r in (thermostat, optimal)
    ]
    window = 0.95 - 0.1  # the preset's initial state of charge less its reserve, below
    tight = reference_day(
        battery={
            "usable_capacity_kwh": round(sum(used) / 2 / window, 2),
            "initial_soc": 0.95,
            "min_soc": 0.1,
        }
    )
    on_off = reference_day(
        cargo_box={"product": "chilled-dairy", "load_temperature_c": 4.0, "control": "on-off"}
    )
    priced = reference_day(
        depot={"id": "depot", "lat": 48.21, "lon": 16.37, "charger": PRICED_CHARGER}
    )
    by_cost = [*STRATEGIES, ("optimal, cost", {"strategy": "optimal", "objective": "cost"})]
    rows = [
        row
        for name, body in [
            *days,
            ("summer, a tight battery", tight),
            ("summer, an on-off unit", on_off),
        ]
        for row in rows_of(name, body)
    ] + rows_of("summer, the depot at 0.30/kWh", priced, by_cost)
    print_table(
        "Refrigeration strategy on planned days (run_plan, 30 stops, ev-van-3.5t-reefer)",
        [
            "day",
            "strategy",
            "the unit follows",
            "refrigeration from the battery [kWh]",
            "from the grid [kWh] (pre-cooling)",
            "battery vs thermostat",
            "vs best constant: battery / battery + grid",
            "best constant [°C] (battery + grid [kWh])",
            "cost (battery refilled at the depot)",
            "goods [°C]",
            "cold chain",
            "lowest charge (reserve)",
            "answer [ms] (vs thermostat)",
        ],
        rows,
    )


if __name__ == "__main__":
    main()
