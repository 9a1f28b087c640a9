"""Every parameter at each end of its documented range, in both box modes: a finite answer and
no numerical warning (the subnormal numbers an audit sent — 1e-310 m² of wall — now sit below
each field's smallest meaningful value and are refused by the schema)."""

from __future__ import annotations

import datetime as dt
import math
import warnings
from zoneinfo import ZoneInfo

import numpy as np
import pytest
from annotated_types import Ge, Gt, Le, Lt

from core.params import (
    STREET_TYPES,
    BatteryParams,
    CargoBoxParams,
    DoorOpening,
    Interval,
    Location,
    VanParams,
    VehicleParams,
    Weather,
)
from core.physics.cycles import generate_leg
from core.physics.simulate import Along, simulate

START = dt.datetime(2026, 7, 15, 12, 0, tzinfo=ZoneInfo("Europe/Vienna"))
HOT = Weather(t_min_c=25, t_max_c=38)
SECTIONS = {"vehicle": VehicleParams, "cargo_box": CargoBoxParams, "battery": BatteryParams}
#: Ends that another field's rule excludes, and what that field is then: the reserve below the
#: departure charge, the product's limit above the set-point, the gross mass above the empty
#: one; with the value tested where the
#: partner's own range excludes the very end.
PARTNERS = {
    ("battery", "initial_soc"): ({"min_soc": 0.0}, None),
    ("battery", "min_soc"): ({"initial_soc": 1.0}, 0.99),
    ("cargo_box", "product_limit_c"): ({"setpoint_c": -40.0}, None),
    ("cargo_box", "setpoint_c"): ({"product_limit_c": 40.0}, None),
    ("vehicle", "gross_mass_kg"): ({"mass_kg": 100.0}, None),
}


def ends(model: type) -> list[tuple[str, float]]:
    """Each numeric field's lowest and highest allowed value."""
    found = []
    for name, info in model.model_fields.items():
        for rule in info.metadata:
            if isinstance(rule, Ge):
                found.append((name, float(rule.ge)))
            elif isinstance(rule, Le):
                found.append((name, float(rule.le)))
            elif isinstance(rule, Gt):
                found.append((name, math.nextafter(float(rule.gt), math.inf)))
            elif isinstance(rule, Lt):
                found.append((name, math.nextafter(float(rule.lt), -math.inf)))
    return found


CASES = [
    (section, name, value, mode)
    for section, model in SECTIONS.items()
    for name, value in ends(model)
    for mode in ("steady", "dynamic")
]


@pytest.mark.parametrize(("section", "name", "value", "mode"), CASES)
def test_each_end_of_each_range_gives_a_finite_answer(section, name, value, mode):
    base = VanParams()
    box = base.cargo_box.model_copy(update={"mode": mode})
    current = {"vehicle": base.vehicle, "cargo_box": box, "battery": base.battery}[section]
    partner, inside = PARTNERS.get((section, name), ({}, None))
    if inside is not None and value > inside:
        value = inside
    fields = current.model_dump() | partner | {name: value}
    if name == "product_limit_c" and value <= -40.0:
        fields["product_limit_c"] = -39.9
    van = base.model_copy(update={"cargo_box": box, section: SECTIONS[section](**fields)})
    speed = generate_leg(3000, STREET_TYPES["urban"], 0.5, van.vehicle.max_acceleration_mps2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = simulate(
            np.concatenate((speed, np.zeros(600))),
            1.0,
            START,
            Location(lat=48.2, lon=16.4),
            van,
            weather=HOT,
            along=Along(
                door_openings=[DoorOpening(start_s=speed.size, duration_s=300)],
                parked=[Interval(start_s=speed.size, duration_s=600)],
            ),
        )
    assert all(math.isfinite(v) for v in result.energy_kwh.values())
    assert np.all(np.isfinite(result.soc)) and np.all(np.isfinite(result.box.temperature_c))
