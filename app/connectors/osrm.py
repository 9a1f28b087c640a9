"""OSRM over HTTP: the distance/duration table and each leg's road with its speed profile.

Calls ``/table/v1/driving`` (in blocks when a round has more places than the server's
``--max-table-size``) and ``/route/v1/driving`` with ``overview=full``, ``geometries=geojson``
and ``annotations=distance,duration,speed``. One shared ``httpx.Client`` per process, with a
timeout and one retry on connection errors. A router that is down, slow or answers garbage
raises :class:`core.exceptions.ServiceUnavailableError` (503); a stop it cannot use raises
:class:`core.exceptions.InvalidStopsError` naming the stop (422).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import Any

import httpx
import numpy as np

from core.exceptions import NoRouteError, ServiceUnavailableError, off_road
from core.params import Place
from core.routing.roads import LegRoute, RoadTable, bearing_deg

SERVICE = "osrm"


class OsrmRouter:
    """A :class:`core.routing.roads.RoadRouter` backed by an osrm-routed server.

    Parameters
    ----------
    url
        Base URL, e.g. ``http://127.0.0.1:5000``.
    timeout_s
        Timeout of each call [s].
    table_size
        Most places per side of one ``/table`` call (the server's ``--max-table-size``).
    max_snap_m
        Farthest a place may be from its snapped road position [m].
    """

    name = SERVICE

    def __init__(self, url: str, timeout_s: float, table_size: int, max_snap_m: float) -> None:
        self.url = url.rstrip("/")
        self.table_size = table_size
        self.max_snap_m = max_snap_m
        self._client = httpx.Client(
            base_url=self.url,
            timeout=httpx.Timeout(timeout_s),
            transport=httpx.HTTPTransport(retries=1),
        )

    def _get(self, path: str, params: dict[str, str]) -> dict[str, Any]:
        """One call; the parsed JSON of an answer OSRM understood (``code`` set)."""
        try:
            response = self._client.get(path, params=params)
        except httpx.TimeoutException:
            raise ServiceUnavailableError(
                SERVICE, f"the OSRM router at {self.url} did not answer in time"
            ) from None
        except httpx.HTTPError as error:
            raise ServiceUnavailableError(
                SERVICE, f"the OSRM router at {self.url} is unreachable ({type(error).__name__})"
            ) from None
        try:
            body = response.json()
        except ValueError:
            body = None
        if not isinstance(body, dict) or not isinstance(body.get("code"), str):
            raise ServiceUnavailableError(
                SERVICE,
                f"the OSRM router at {self.url} answered HTTP {response.status_code} without "
                "an OSRM response",
            )
        return body

    def table(self, places: Sequence[Place]) -> RoadTable:
        """Distances [m] and durations [s] of every ordered pair, and each place's snap
        distance [m]."""
        n = len(places)
        distance = np.full((n, n), np.nan)
        duration = np.full((n, n), np.nan)
        snap = np.full(n, np.nan)
        block = self.table_size
        while True:
            try:
                for rows, cols in itertools.product(_blocks(n, block), repeat=2):
                    self._fill(places, rows, cols, distance, duration, snap)
                break
            except _TooBigError:
                if block <= 1:
                    raise ServiceUnavailableError(
                        SERVICE, "the OSRM router refuses even a 1×1 table"
                    ) from None
                block //= 2
        far = np.flatnonzero(snap > self.max_snap_m)
        if far.size:
            k = int(far[0])
            raise off_road(
                f"'{places[k].id}' ({places[k].lat}, {places[k].lon}) is {snap[k]:,.0f} m from "
                f"the nearest road; at most {self.max_snap_m:g} m is accepted",
                k,
            )
        # A pair with no road stays NaN (OSRM's null): a plan names the stop, a fleet plan
        # leaves it out as unreachable.
        np.fill_diagonal(distance, 0.0)
        np.fill_diagonal(duration, 0.0)
        return RoadTable(distance, duration, snap)

    def _fill(
        self,
        places: Sequence[Place],
        rows: range,
        cols: range,
        distance: np.ndarray,
        duration: np.ndarray,
        snap: np.ndarray,
    ) -> None:
        members = sorted(set(rows) | set(cols))
        if len(members) == 1:  # one place to itself: the diagonal (its snap comes with others)
            distance[members[0], members[0]] = duration[members[0], members[0]] = 0.0
            return
        position = {place: k for k, place in enumerate(members)}
        coordinates = ";".join(f"{places[i].lon:.6f},{places[i].lat:.6f}" for i in members)
        body = self._get(
            f"/table/v1/driving/{coordinates}",
            {
                "annotations": "distance,duration",
                "sources": ";".join(str(position[i]) for i in rows),
                "destinations": ";".join(str(position[j]) for j in cols),
            },
        )
        if body["code"] == "TooBig":
            raise _TooBigError
        if body["code"] != "Ok":
            raise ServiceUnavailableError(
                SERVICE, f"OSRM /table answered {body['code']}: {body.get('message', '')}"
            )
        try:
            d = np.array(body["distances"], dtype=float)
            t = np.array(body["durations"], dtype=float)
            snapped = [float(w["distance"]) for w in body["sources"]]
        except (KeyError, TypeError, ValueError):
            raise ServiceUnavailableError(SERVICE, "OSRM /table answer is malformed") from None
        if d.shape != (len(rows), len(cols)) or t.shape != d.shape or len(snapped) != len(rows):
            raise ServiceUnavailableError(SERVICE, "OSRM /table answer has the wrong shape")
        # null (no route) arrives as NaN; anything negative is garbage.
        if np.any(d < 0) or np.any(t < 0) or not all(math.isfinite(x) for x in snapped):
            raise ServiceUnavailableError(SERVICE, "OSRM /table answer holds invalid numbers")
        distance[np.ix_(list(rows), list(cols))] = d
        duration[np.ix_(list(rows), list(cols))] = t
        snap[list(rows)] = snapped

    def route(self, origin: Place, destination: Place) -> LegRoute:
        """The road from ``origin`` to ``destination``, segment by segment."""
        coordinates = (
            f"{origin.lon:.6f},{origin.lat:.6f};{destination.lon:.6f},{destination.lat:.6f}"
        )
        body = self._get(
            f"/route/v1/driving/{coordinates}",
            {
                "overview": "full",
                "geometries": "geojson",
                "annotations": "distance,duration,speed",
            },
        )
        if body["code"] in ("NoRoute", "NoSegment"):
            raise NoRouteError(f"no road from '{origin.id}' to '{destination.id}'")
        if body["code"] != "Ok":
            raise ServiceUnavailableError(
                SERVICE, f"OSRM /route answered {body['code']}: {body.get('message', '')}"
            )
        try:
            route = body["routes"][0]
            points = np.array(route["geometry"]["coordinates"], dtype=float)
            annotations = [leg["annotation"] for leg in route["legs"]]
            lengths = np.concatenate([np.array(a["distance"], dtype=float) for a in annotations])
            seconds = np.concatenate([np.array(a["duration"], dtype=float) for a in annotations])
        except (KeyError, IndexError, TypeError, ValueError):
            raise ServiceUnavailableError(SERVICE, "OSRM /route answer is malformed") from None
        if (
            points.ndim != 2
            or points.shape[1] != 2
            or lengths.shape != seconds.shape
            or not np.all(np.isfinite(points))
            or not np.all(np.isfinite(lengths) & (lengths >= 0))
            or not np.all(np.isfinite(seconds) & (seconds >= 0))
        ):
            raise ServiceUnavailableError(SERVICE, "OSRM /route answer holds invalid numbers")
        if lengths.size == 0:  # origin and destination snap to the same point
            lengths, seconds = np.zeros(1), np.ones(1)
        # OSRM's own speed annotation is rounded to 0.1 m/s; distance over duration is exact.
        # A segment of no duration (a snapped end point) takes the leg's mean speed.
        mean = lengths.sum() / seconds.sum() if seconds.sum() > 0 else 1.0
        with np.errstate(invalid="ignore", divide="ignore"):
            speeds = np.where(seconds > 0, lengths / seconds, mean)
        return LegRoute(
            segment_distance_m=lengths,
            segment_speed_mps=speeds,
            segment_heading_deg=_headings(points, lengths),
            coordinates=points,
        )


class _TooBigError(Exception):
    """OSRM refused a table block as too big."""


def _blocks(n: int, size: int) -> list[range]:
    return [range(start, min(start + size, n)) for start in range(0, n, size)]


def _headings(points: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Direction of travel of each annotated segment [°], from the polyline.

    With ``overview=full`` the polyline has one point more than there are segments; otherwise
    each segment takes the heading of the polyline piece at its middle (by distance).
    """
    if len(points) < 2:
        return np.full(lengths.size, np.nan)
    pieces = np.array([bearing_deg(a[1], a[0], b[1], b[0]) for a, b in itertools.pairwise(points)])
    if pieces.size == lengths.size:
        return pieces
    along = np.concatenate(([0.0], np.cumsum(lengths)))
    middle = (along[:-1] + along[1:]) / 2 / max(along[-1], 1e-9)
    index = np.minimum((middle * pieces.size).astype(int), pieces.size - 1)
    return np.asarray(pieces[index], dtype=float)
