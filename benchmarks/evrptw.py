"""Schneider, Stenger & Goeke's E-VRPTW instances with partial recharge, solved by
:mod:`core.routing.evrp` and checked independently of it (:mod:`testbed.evrptw`: the
instances read, the rules, the best knowns).

As a command a harness can call::

    python -m benchmarks.evrptw FILE... --time-limit S

prints one JSON object per line and instance: ``{"instance", "vehicles", "distance",
"routes": [[{"id", "charge"}, …], …], "feasible", "runtime_s"}`` — each route the place ids of
the file from depot to depot, stations included, with the energy charged at each. ``make
bench`` solves the six shared instances (``../shared/reference/evrptw/``) and prints them beside
the best known (``bks.tsv``) and RoutingBlocks' ALNS at 60 s on this machine (README there).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

from benchmarks.common import print_table
from core.routing.effort import Effort
from core.routing.evrp import EvrpSolution, solve_evrptw
from testbed.evrptw import FOLDER, Instance, best_known, check, read

#: RoutingBlocks' ALNS (Klein & Schiffer 2023) at 60 s on this machine: (vehicles, distance).
ROUTING_BLOCKS = {"r101": (19, 1611.8), "rc201": (4, 1461.5)}


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
