"""Legs between every ordered pair of places: distance, duration, street type and grade.

Three sources, in this order: the client's own road matrices (checked here), a road
router's table (:class:`core.routing.roads.RoadTable`), or the built-in estimate — great-circle
distance times a detour factor, the street type by leg length and the duration from that
street type's mean speed. With known durations the street type follows the leg's mean speed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from core.arrays import FloatArray
from core.exceptions import InvalidMatrixError
from core.params import STREET_TYPES, Place, RoadMatrix, StreetTypeName
from core.routing.roads import RoadTable

DistanceSource = Literal["osrm", "client", "estimate"]

#: Mean Earth radius [m] (IUGG, Moritz 2000).
EARTH_RADIUS_M = 6_371_008.8
#: Road distance over great-circle distance. Circuity of road networks is 1.2–1.4 (Ballou,
#: Rahardja & Sakai 2002, "Selected country circuity factors for road travel distance
#: estimation"); 1.3 is their typical urban-regional value.
DETOUR_FACTOR = 1.3
#: Leg length [m] up to which a leg is urban, then highway up to the next bound, then expressway.
URBAN_MAX_M = 5_000.0
HIGHWAY_MAX_M = 25_000.0
STREET_TYPE_NAMES: tuple[StreetTypeName, ...] = ("urban", "highway", "expressway")
#: Steepest mean grade of a leg [–]; elevations that imply more are cut to it.
MAX_LEG_GRADE = 0.25


@dataclass(frozen=True)
class Legs:
    """Every ordered pair of places (index 0 the depot).

    Attributes
    ----------
    distance_m, duration_s, grade
        Road distance [m], driving time [s] and mean grade [–] of each pair.
    street_type
        Index into :data:`STREET_TYPE_NAMES` of each pair.
    source
        Where distances and durations came from.
    snap_distance_m
        Distance of each place from the road the router snapped it to [m]; None without one.
    """

    distance_m: FloatArray
    duration_s: FloatArray
    grade: FloatArray
    street_type: NDArray[np.int_]
    source: DistanceSource
    snap_distance_m: FloatArray | None = None

    def street_type_name(self, i: int, j: int) -> StreetTypeName:
        """Street type of the leg from ``i`` to ``j``."""
        return STREET_TYPE_NAMES[int(self.street_type[i, j])]

    def first(self, count: int) -> Legs:
        """The legs among the first ``count`` places."""
        square = (slice(count), slice(count))
        return Legs(
            distance_m=self.distance_m[square],
            duration_s=self.duration_s[square],
            grade=self.grade[square],
            street_type=self.street_type[square],
            source=self.source,
            snap_distance_m=None if self.snap_distance_m is None else self.snap_distance_m[:count],
        )

    def unreachable(self) -> list[int]:
        """Places with no road from or to the depot (a router's null), by index (≥ 1)."""
        known = np.isfinite(self.distance_m) & np.isfinite(self.duration_s)
        return [int(i) for i in np.flatnonzero(~(known[0] & known[:, 0])) if i > 0]


def great_circle_m(lat: FloatArray, lon: FloatArray) -> FloatArray:
    """Great-circle distance of every pair of points [m] (haversine, mean Earth radius).

    Parameters
    ----------
    lat, lon
        Latitudes and longitudes [°].
    """
    lat, lon = np.asarray(lat, dtype=float), np.asarray(lon, dtype=float)
    return _haversine_m(lat[:, None], lon[:, None], lat[None, :], lon[None, :])


def metres_from(lat0: float, lon0: float, lat: FloatArray, lon: FloatArray) -> FloatArray:
    """Great-circle distance from one point to each of ``lat``, ``lon`` [m] (haversine).

    Parameters
    ----------
    lat0, lon0
        The point [°].
    lat, lon
        The others [°].
    """
    return _haversine_m(np.float64(lat0), np.float64(lon0), np.asarray(lat), np.asarray(lon))


def _haversine_m(lat1: Any, lon1: Any, lat2: Any, lon2: Any) -> FloatArray:
    """The haversine formula on broadcast arrays of degrees, on the mean Earth radius [m]."""
    phi1, phi2 = np.radians(lat1), np.radians(lat2)
    dphi, dlam = phi2 - phi1, np.radians(lon2) - np.radians(lon1)
    h = np.sin(dphi / 2) ** 2 + np.cos(phi1) * np.cos(phi2) * np.sin(dlam / 2) ** 2
    return np.asarray(2 * EARTH_RADIUS_M * np.arcsin(np.sqrt(np.clip(h, 0.0, 1.0))))


def street_type_by_length(distance_m: FloatArray) -> NDArray[np.int_]:
    """Street type index by leg length: urban up to 5 km, highway up to 25 km, else expressway.

    Short hops between stops stay in town; longer legs reach the ring road or the motorway.
    """
    return np.searchsorted([URBAN_MAX_M, HIGHWAY_MAX_M], distance_m, side="left")


#: Mean speeds [m/s] from which a leg is highway, then expressway: 45 and 80 km/h, between the
#: street types' mean speeds (30, 70, 100 km/h).
STREET_SPEED_BOUNDS_MPS = (45 / 3.6, 80 / 3.6)


def street_type_by_speed(distance_m: ArrayLike, duration_s: ArrayLike) -> NDArray[np.int_]:
    """Street type index by a leg's mean speed; legs of no duration are urban.

    Parameters
    ----------
    distance_m, duration_s
        Distance [m] and driving time [s] of each leg.
    """
    distance = np.asarray(distance_m, dtype=float)
    duration = np.asarray(duration_s, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        speed = np.where(duration > 0, distance / duration, 0.0)
    return np.searchsorted(STREET_SPEED_BOUNDS_MPS, speed, side="right")


def build_legs(
    places: Sequence[Place], matrix: RoadMatrix | None = None, table: RoadTable | None = None
) -> Legs:
    """Distances, durations, street types and grades of every ordered pair of places.

    Parameters
    ----------
    places
        The depot first, then the stops.
    matrix
        The client's road matrices in the same order; they win over everything.
    table
        A road router's table in the same order; used when there is no client matrix.
    """
    n = len(places)
    lat = np.array([p.lat for p in places])
    lon = np.array([p.lon for p in places])
    source: DistanceSource
    snap = None
    if matrix is None and table is not None:
        distance, duration = table.distance_m, table.duration_s
        street = street_type_by_speed(distance, duration)
        source, snap = "osrm", table.snap_distance_m
    elif matrix is None:
        distance = great_circle_m(lat, lon) * DETOUR_FACTOR
        street = street_type_by_length(distance)
        speeds = np.array([STREET_TYPES[name].mean_speed_mps for name in STREET_TYPE_NAMES])
        duration = distance / speeds[street]
        source = "estimate"
    else:
        source = "client"
        distance = _checked_matrix(matrix.distances_m, "distances_m", n)
        duration = _checked_matrix(matrix.durations_s, "durations_s", n)
        if matrix.street_types is None:
            street = street_type_by_speed(distance, duration)
        else:
            _check_shape(matrix.street_types, "street_types", n)
            street = np.array(
                [[STREET_TYPE_NAMES.index(s) for s in row] for row in matrix.street_types]
            )
        positive = (distance > 0) & (duration == 0)
        if positive.any():
            i, j = (int(v) for v in np.argwhere(positive)[0])
            raise InvalidMatrixError(
                f"matrix.durations_s[{i}][{j}] is 0 for a leg of {distance[i, j]} m",
                f"matrix.durations_s[{i}][{j}]",
            )
    elevation = np.array([p.elevation_m if p.elevation_m is not None else np.nan for p in places])
    rise = elevation[None, :] - elevation[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        grade = np.where(np.isfinite(rise) & (distance > 0), rise / distance, 0.0)
    return Legs(
        distance_m=distance,
        duration_s=duration,
        grade=np.clip(grade, -MAX_LEG_GRADE, MAX_LEG_GRADE),
        street_type=street,
        source=source,
        snap_distance_m=snap,
    )


def _check_shape(rows: Sequence[Sequence[object]], name: str, n: int) -> None:
    if len(rows) != n:
        raise InvalidMatrixError(
            f"matrix.{name} has {len(rows)} rows; expected {n} (the depot, the stops, then the "
            "chargers on the way)",
            f"matrix.{name}",
        )
    for i, row in enumerate(rows):
        if len(row) != n:
            raise InvalidMatrixError(
                f"matrix.{name}[{i}] has {len(row)} columns; expected {n}", f"matrix.{name}[{i}]"
            )


def _checked_matrix(rows: Sequence[Sequence[float]], name: str, n: int) -> FloatArray:
    """A square, finite, non-negative matrix with a zero diagonal, or an error naming the cell."""
    _check_shape(rows, name, n)
    values = np.array(rows, dtype=float)
    bad = ~np.isfinite(values) | (values < 0)
    if bad.any():
        i, j = (int(v) for v in np.argwhere(bad)[0])
        raise InvalidMatrixError(
            f"matrix.{name}[{i}][{j}] = {values[i, j]} must be finite and >= 0",
            f"matrix.{name}[{i}][{j}]",
        )
    diagonal = np.flatnonzero(np.diag(values) != 0)
    if diagonal.size:
        i = int(diagonal[0])
        raise InvalidMatrixError(
            f"matrix.{name}[{i}][{i}] = {values[i, i]}: the diagonal must be 0",
            f"matrix.{name}[{i}][{i}]",
        )
    return values
