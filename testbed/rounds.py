"""Round trips that look like delivery days, for the solver's tests and benchmarks: stops in a
few clusters (villages, districts, shops along two streets) with the depot away from them, on
symmetric distances or on a road-like asymmetric matrix (one-way streets)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.sparse.csgraph import shortest_path


@dataclass(frozen=True)
class Round:
    """A generated round: integer arc costs [m], depot first, and how it was made."""

    name: str
    cost: NDArray[np.int64]
    clusters: int
    asymmetric: bool


def clustered_points(
    n_stops: int, n_clusters: int, rng: np.random.Generator, area_m: float = 20_000.0
) -> NDArray[np.float64]:
    """The depot at the edge of the area, then ``n_stops`` stops around ``n_clusters``
    centres (each cluster a few hundred metres to 1.5 km across, some stretched along a street)
    [m]."""
    centres = rng.uniform(0.25 * area_m, area_m, size=(n_clusters, 2))
    spread = rng.uniform(200.0, 1500.0, size=n_clusters)
    stretch = rng.uniform(1.0, 4.0, size=n_clusters)  # a street: long and thin
    angle = rng.uniform(0.0, np.pi, size=n_clusters)
    which = rng.integers(0, n_clusters, size=n_stops)
    local = rng.normal(size=(n_stops, 2)) * spread[which, None]
    local[:, 0] *= stretch[which]
    cos, sin = np.cos(angle[which]), np.sin(angle[which])
    rotated = np.column_stack(
        (cos * local[:, 0] - sin * local[:, 1], sin * local[:, 0] + cos * local[:, 1])
    )
    depot = np.array([[0.05 * area_m, 0.05 * area_m]])
    return np.vstack((depot, centres[which] + rotated))


def euclidean_m(points: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.sqrt(((points[:, None, :] - points[None, :, :]) ** 2).sum(axis=2))


def one_way(distance_m: NDArray[np.float64], rng: np.random.Generator) -> NDArray[np.float64]:
    """Road-like asymmetric distances: each direction of each link 5–40 % longer than the
    crow flies, independently (one-way streets, turn restrictions), then the shortest paths
    through other places, as a road router's matrix is."""
    detour = 1.05 + 0.35 * rng.random(distance_m.shape)
    roads = distance_m * detour
    np.fill_diagonal(roads, 0.0)
    return np.asarray(shortest_path(roads, method="FW", directed=True))


def clustered_round(n_stops: int, n_clusters: int, seed: int, asymmetric: bool = False) -> Round:
    """One delivery day's round trip, integer metres."""
    rng = np.random.default_rng(seed)
    distance = euclidean_m(clustered_points(n_stops, n_clusters, rng))
    if asymmetric:
        distance = one_way(distance, rng)
    kind = "asym" if asymmetric else "sym"
    return Round(
        f"clustered-{n_stops}-{n_clusters}-{kind}-{seed}",
        np.rint(distance).astype(np.int64),
        n_clusters,
        asymmetric,
    )


def uniform_round(n_stops: int, seed: int, asymmetric: bool = False) -> Round:
    """Stops spread uniformly over 20 km × 20 km, the depot in a corner."""
    rng = np.random.default_rng(seed)
    points = np.vstack(([[1000.0, 1000.0]], rng.uniform(0, 20_000.0, size=(n_stops, 2))))
    distance = euclidean_m(points)
    if asymmetric:
        distance = one_way(distance, rng)
    kind = "asym" if asymmetric else "sym"
    return Round(
        f"uniform-{n_stops}-{kind}-{seed}", np.rint(distance).astype(np.int64), 1, asymmetric
    )
