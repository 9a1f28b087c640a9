"""What the planner needs from a road router, as core types and a protocol.

The core never talks to the network. A road router (OSRM, :mod:`app.connectors.osrm`)
implements :class:`RoadRouter` and hands back plain arrays; the planner calls it at the right
moment (the matrix before the tour, the roads of the chosen tour's legs). The weather service's
protocol is :class:`core.physics.weather.WeatherService`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from core.arrays import FloatArray
from core.params import Place


@dataclass(frozen=True)
class RoadTable:
    """A router's answer for every ordered pair of places (depot first).

    Attributes
    ----------
    distance_m, duration_s
        Road distance [m] and free-flow driving time [s] of each pair.
    snap_distance_m
        How far each place is from the road the router snapped it to [m].
    """

    distance_m: FloatArray
    duration_s: FloatArray
    snap_distance_m: FloatArray


@dataclass(frozen=True)
class LegRoute:
    """The road of one leg, segment by segment.

    Attributes
    ----------
    segment_distance_m, segment_speed_mps, segment_heading_deg
        Length [m], the router's speed [m/s] and the direction of travel [°, 0 north] of each
        segment, in driving order.
    coordinates
        The road's polyline, ``(lon, lat)`` [°] per row.
    """

    segment_distance_m: FloatArray
    segment_speed_mps: FloatArray
    segment_heading_deg: FloatArray
    coordinates: FloatArray

    @property
    def distance_m(self) -> float:
        """Length of the road [m]."""
        return float(self.segment_distance_m.sum())


class RoadRouter(Protocol):
    """A road router: distances, durations and roads between places."""

    name: str

    def table(self, places: Sequence[Place]) -> RoadTable:
        """Distances and durations of every ordered pair, NaN where no road leads; raises
        :class:`core.exceptions.ServiceUnavailableError` when the router fails and
        :class:`core.exceptions.InvalidStopsError` naming a stop it cannot use (too far from
        any road)."""
        ...

    def route(self, origin: Place, destination: Place) -> LegRoute:
        """The road from ``origin`` to ``destination``."""
        ...


class RememberingRouter:
    """A road router that asks its inner router once per set of places and once per leg (the
    cells of a study grid, the verification rounds of a fleet plan drive the same roads)."""

    def __init__(self, inner: RoadRouter) -> None:
        self.inner = inner
        self.name = inner.name
        self._tables: dict[tuple[tuple[float, float], ...], RoadTable] = {}
        self._routes: dict[tuple[float, float, float, float], LegRoute] = {}

    def table(self, places: Sequence[Place]) -> RoadTable:
        key = tuple((p.lat, p.lon) for p in places)
        if key not in self._tables:
            self._tables[key] = self.inner.table(places)
        return self._tables[key]

    def route(self, origin: Place, destination: Place) -> LegRoute:
        key = (origin.lat, origin.lon, destination.lat, destination.lon)
        if key not in self._routes:
            self._routes[key] = self.inner.route(origin, destination)
        return self._routes[key]


def bearing_deg(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Initial great-circle bearing from point 1 to point 2 [°, 0 north, 90 east]."""
    phi1, phi2 = np.radians(lat1), np.radians(lat2)
    dlam = np.radians(lon2 - lon1)
    y = np.sin(dlam) * np.cos(phi2)
    x = np.cos(phi1) * np.sin(phi2) - np.sin(phi1) * np.cos(phi2) * np.cos(dlam)
    return float(np.degrees(np.arctan2(y, x)) % 360.0)
