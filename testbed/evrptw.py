"""Schneider, Stenger & Goeke's E-VRPTW instances (``../shared/reference/evrptw``) read into
:class:`~core.routing.evrp.EvrpInstance`, their best knowns, and an independent check of routes
by the instance's rules alone.

Rules (the README of the instances): energy = r × distance, recharge time = g × energy, the
battery within [0, Q], every customer once inside its window (waiting allowed), load ≤ C;
fewest vehicles, then distance.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from core.routing.evrp import EvrpInstance, VehicleKind
from testbed.reference import REFERENCE

FOLDER = REFERENCE / "evrptw"


#: Slack of the independent check on times and energy (the file's two decimals).
TOLERANCE = 1e-6


@dataclass(frozen=True)
class Instance:
    """An instance file: the ids of its places (depot, customers, stations in the solver's
    order), their coordinates and the problem."""

    name: str
    ids: list[str]
    xy: np.ndarray
    problem: EvrpInstance


def read(path: Path) -> Instance:
    """Schneider et al.'s format: a header row, one row per place (``StringID Type x y demand
    ReadyTime DueDate ServiceTime``), then ``Q``, ``C``, ``r``, ``g``, ``v`` as ``/value/``."""
    rows, values = [], {}
    for line in path.read_text().splitlines()[1:]:
        parts = line.split()
        if len(parts) == 8:
            rows.append(parts)
        elif parts and "/" in line:
            values[parts[0]] = float(line.split("/")[1])
    order = [r for r in rows if r[1] == "d"] + [r for r in rows if r[1] == "c"]
    order += [r for r in rows if r[1] == "f"]
    xy = np.array([[float(r[2]), float(r[3])] for r in order])
    distance = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
    column = [np.array([float(r[k]) for r in order]) for k in (4, 5, 6, 7)]
    customers = [k for k, r in enumerate(order) if r[1] == "c"]
    vehicles = VehicleKind(
        count=len(customers),
        energy=values["r"] * distance,
        battery=values["Q"],
        initial=values["Q"],
        capacity=values["C"],
        due=float(column[2][0]),
    )
    problem = EvrpInstance(
        distance=distance,
        duration=distance / values["v"],
        ready=column[1],
        due=column[2],
        service=column[3],
        demand=column[0],
        customers=customers,
        stations=[k for k, r in enumerate(order) if r[1] == "f"],
        charge_time=np.full(len(order), values["g"]),
        kinds=[vehicles],
    )
    return Instance(path.name.split("_")[0], [r[0] for r in order], xy, problem)


def check(instance: EvrpInstance, routes: list[list[tuple[int, float]]]) -> str | None:
    """What the routes break, by the rules alone (not the solver's code), or None."""
    seen: list[int] = []
    vehicles = instance.kinds[0]
    for n, route in enumerate(routes):
        if route[0][0] != 0 or route[-1][0] != 0:
            return f"route {n} does not start and end at the depot"
        battery, clock, load = vehicles.battery, instance.ready[0], 0.0
        for (i, _), (j, charge) in itertools.pairwise(route):
            battery -= vehicles.energy[i, j]
            clock += instance.duration[i, j]
            if battery < -TOLERANCE:
                return f"route {n} runs empty before place {j}"
            if clock > instance.due[j] + TOLERANCE:
                return f"route {n} reaches place {j} after its window"
            clock = max(clock, instance.ready[j]) + instance.service[j]
            if j in instance.stations:
                if battery + charge > vehicles.battery + TOLERANCE or charge < 0:
                    return f"route {n} charges {charge} at {j}, beyond the battery"
                battery += charge
                clock += instance.charge_time[j] * charge
            elif j != 0:
                seen.append(j)
                load += instance.demand[j]
        if load > vehicles.capacity + TOLERANCE:
            return f"route {n} carries {load}, more than {vehicles.capacity}"
    if sorted(seen) != sorted(instance.customers):
        return "not every customer is served exactly once"
    return None


def best_known() -> dict[str, tuple[int, float]]:
    rows = (FOLDER / "bks.tsv").read_text().splitlines()[1:]
    return {
        r.split("\t")[0].lower(): (int(r.split("\t")[1]), float(r.split("\t")[2])) for r in rows
    }
