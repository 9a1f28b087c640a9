"""The shared reference data (``../shared/reference`` beside the repository) read for tests
and benchmarks: TSPLIB matrices, PyVRP on a VRPTW, Vienna's stops."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

REFERENCE = Path(__file__).resolve().parents[1].parent / "shared" / "reference"


def euc_2d_matrix(path: Path) -> np.ndarray:
    """Integer distance matrix of a TSPLIB EUC_2D instance: nint(euclidean distance)."""
    lines = path.read_text().splitlines()
    start = lines.index("NODE_COORD_SECTION") + 1
    points = []
    for line in lines[start:]:
        if line.strip() in ("EOF", ""):
            break
        _, x, y = line.split()[:3]
        points.append((float(x), float(y)))
    xy = np.array(points)
    distance = np.sqrt(((xy[:, None, :] - xy[None, :, :]) ** 2).sum(axis=-1))
    return np.floor(distance + 0.5).astype(np.int64)


def pyvrp_vrptw(
    distance: np.ndarray,
    demand: Sequence[float],
    service_min: Sequence[float],
    window_min: Sequence[tuple[int, int]],
    minutes_per_unit: float,
    capacity: float,
    vans: int,
    budget_s: float,
    fixed_cost: bool = False,
    scale: int = 100,
) -> tuple[float, int, int]:
    """PyVRP alone on a VRPTW instance (the depot first; one unit of distance is one of time,
    ``minutes_per_unit`` minutes; windows in whole minutes) for ``budget_s``, in ``scale``-ths
    of a unit; ``fixed_cost``: a cost per van larger than any set of routes. Its distance
    [units], vans and the stops served (0 when its best breaks a rule)."""
    from pyvrp import Client, Depot, Location, ProblemData, VehicleType, solve
    from pyvrp.stop import MaxRuntime

    per_minute = scale / minutes_per_unit
    arcs = np.rint(distance * scale).astype(np.int64)
    n = arcs.shape[0]
    horizon = int(window_min[0][1] * per_minute)
    data = ProblemData(
        [Location(0.0, 0.0) for _ in range(n)],
        [
            Client(
                location=k,
                delivery=[int(demand[k])],
                service_duration=round(service_min[k] * per_minute),
                tw_early=int(a * per_minute),
                tw_late=int(b * per_minute),
            )
            for k, (a, b) in enumerate(window_min)
            if k
        ],
        [Depot(location=0, tw_early=0, tw_late=horizon)],
        [
            VehicleType(
                vans,
                capacity=[int(capacity)],
                fixed_cost=int(arcs.max() * 2 * n) if fixed_cost else 0,
                tw_late=horizon,
            )
        ],
        [arcs],
        [arcs],
    )
    result = solve(data, stop=MaxRuntime(budget_s), seed=1, display=False)
    served = result.best.num_clients() if result.is_feasible() else 0
    return result.best.distance() / scale, result.best.num_routes(), served


def vienna_stops(
    rng: np.random.Generator,
    n_stops: int,
    service_time_s: float,
    door_open_s: float,
    delivery_kg: float,
    spread_deg: tuple[float, float] = (0.05, 0.08),
) -> list[dict[str, Any]]:
    """``n_stops`` stops (as JSON) scattered uniformly around Vienna's centre, up to
    ``spread_deg`` degrees of latitude and longitude either way, named S0, S1, …"""
    return [
        {
            "id": f"S{i}",
            "lat": 48.21 + rng.uniform(-spread_deg[0], spread_deg[0]),
            "lon": 16.37 + rng.uniform(-spread_deg[1], spread_deg[1]),
            "service_time_s": service_time_s,
            "door_open_s": door_open_s,
            "delivery_kg": delivery_kg,
        }
        for i in range(n_stops)
    ]
