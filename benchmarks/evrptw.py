"""Schneider, Stenger & Goeke's E-VRPTW instances with partial recharge, solved by
:mod:`core.routing.evrp` and checked independently of it.

As a command a harness can call::

    python -m benchmarks.evrptw FILE... --time-limit S

prints one JSON object per line and instance: ``{"instance", "vehicles", "distance",
"routes": [[{"id", "charge"}, …], …], "feasible", "runtime_s"}`` — each route the place ids of
the file from depot to depot, stations included, with the energy charged at each. ``make
bench`` solves the six shared instances (``../shared/reference/evrptw/``) and prints them beside
the best known (``bks.tsv``) and RoutingBlocks' ALNS at 60 s on this machine (README there).

Rules (the README of the instances): energy = r × distance, recharge time = g × energy, the
battery within [0, Q], every customer once inside its window (waiting allowed), load ≤ C;
fewest vehicles, then distance.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from benchmarks.common import REFERENCE, print_table
from core.routing.effort import Effort
from core.routing.evrp import EvrpInstance, EvrpSolution, VehicleKind, solve_evrptw

FOLDER = REFERENCE / "evrptw"
#: RoutingBlocks' ALNS (Klein & Schiffer 2023) at 60 s on this machine: (vehicles, distance).
ROUTING_BLOCKS = {"r101": (19, 1611.8), "rc201": (4, 1461.5)}
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


def solved(instance: Instance, time_limit_s: float) -> dict[str, object]:
    """The instance solved, as one JSON object."""
    started = time.perf_counter()
    solution: EvrpSolution = solve_evrptw(
        instance.problem, Effort.starting_now(time_limit_s, time_limit_s)
    )
    runtime_s = time.perf_counter() - started
    routes = [[(v.place, v.charge) for v in route.visits] for route in solution.routes]
    broken = check(instance.problem, routes)
    return {
        "instance": instance.name,
        "vehicles": solution.vehicles,
        "distance": round(solution.distance, 3),
        "routes": [
            [{"id": instance.ids[place], "charge": charge} for place, charge in route]
            for route in routes
        ],
        "feasible": broken is None,
        "broken": broken,
        "runtime_s": round(runtime_s, 1),
    }


def best_known() -> dict[str, tuple[int, float]]:
    rows = (FOLDER / "bks.tsv").read_text().splitlines()[1:]
    return {
        r.split("\t")[0].lower(): (int(r.split("\t")[1]), float(r.split("\t")[2])) for r in rows
    }


def main(time_limit_s: float = 60.0) -> None:
    """``make bench``: the six instances at ``time_limit_s`` beside the best known."""
    known = best_known()
    rows = []
    for path in sorted(FOLDER.glob("*_21.txt")):
        answer = solved(read(path), time_limit_s)
        name = str(answer["instance"])
        vans, distance = known[name]
        ours_vans, ours = int(answer["vehicles"]), float(answer["distance"])  # type: ignore[call-overload]
        peer = ROUTING_BLOCKS.get(name)
        rows.append(
            [
                name,
                f"{vans} / {distance:.1f}",
                f"{ours_vans} / {ours:.1f}",
                f"{ours_vans - vans:+d}",
                f"{(ours / distance - 1) * 100:+.1f} %",
                "yes" if answer["feasible"] else f"no: {answer['broken']}",
                "—" if peer is None else f"{peer[0]} / {peer[1]:.1f}",
            ]
        )
    print_table(
        f"E-VRPTW with partial recharge (Schneider et al. 2014) at {time_limit_s:g} s",
        [
            "instance",
            "best known",
            "coldroute",
            "vans",
            "distance",
            "feasible (checked)",
            "RoutingBlocks 60 s",
        ],
        rows,
    )


def _command(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.evrptw", description=__doc__)
    parser.add_argument("files", nargs="+", type=Path, help="instance files")
    parser.add_argument("--time-limit", type=float, default=60.0, help="seconds per instance")
    args = parser.parse_args(argv)
    if not math.isfinite(args.time_limit) or args.time_limit <= 0:
        parser.error("--time-limit must be a positive number of seconds")
    for path in args.files:
        print(json.dumps(solved(read(path), args.time_limit)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(_command(sys.argv[1:]))
