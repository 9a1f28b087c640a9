"""A local stand-in for an Open-Meteo-compatible API (no machine here can reach the real one).

It serves the documented JSON of ``/v1/forecast`` and ``/v1/archive`` — ``latitude``,
``longitude``, ``utc_offset_seconds``, ``timezone``, ``hourly_units`` and ``hourly`` arrays for
every hour of ``start_date``..``end_date`` — and misbehaves on request. The first path segment
chooses the weather or the failure:

* ``/hot/…``: 33 °C all day, sun by a clear-sky curve, calm;
* ``/cold/…``: −8 °C, overcast;
* ``/windy/…``: 15 °C, 15 m/s (54 km/h) from the north, no sun;
* ``/garbage/…``: HTTP 200 with HTML; ``/broken/…``: arrays of the wrong length;
* ``/error/…``: HTTP 500; ``/slow/…``: answers after 5 s.

Every request is recorded in ``StubServer.requests`` (path and query).
"""

from __future__ import annotations

import datetime as dt
import json
import math
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import parse_qs, urlparse

WEATHERS = {
    "hot": {"temperature": 33.0, "sun": 1.0, "wind_kmh": 0.0, "wind_from": 0.0},
    "cold": {"temperature": -8.0, "sun": 0.1, "wind_kmh": 0.0, "wind_from": 0.0},
    "windy": {"temperature": 15.0, "sun": 0.0, "wind_kmh": 54.0, "wind_from": 0.0},
}


def _hourly(mode: str, start: dt.date, end: dt.date) -> dict[str, object]:
    weather = WEATHERS[mode]
    hours = int(((end - start).days + 1) * 24)
    times = [dt.datetime.combine(start, dt.time()) + dt.timedelta(hours=h) for h in range(hours)]
    # A clear-sky-like bell from 06:00 to 18:00 UTC, scaled by the mode's sunshine.
    bell = [max(0.0, math.sin((t.hour - 6) / 12 * math.pi)) for t in times]
    return {
        "time": [t.strftime("%Y-%m-%dT%H:%M") for t in times],
        "temperature_2m": [weather["temperature"]] * hours,
        "direct_radiation": [round(700 * weather["sun"] * b, 1) for b in bell],
        "diffuse_radiation": [round(120 * b, 1) for b in bell],
        "cloud_cover": [round(100 * (1 - weather["sun"]))] * hours,
        "wind_speed_10m": [weather["wind_kmh"]] * hours,
        "wind_direction_10m": [weather["wind_from"]] * hours,
    }


class _Handler(BaseHTTPRequestHandler):
    server: StubServer

    def log_message(self, *args: object) -> None:  # quiet
        pass

    def do_GET(self) -> None:
        url = urlparse(self.path)
        query = {k: v[0] for k, v in parse_qs(url.query).items()}
        self.server.requests.append((url.path, query))
        mode, _, endpoint = url.path.strip("/").partition("/")
        if mode == "slow":
            time.sleep(5)
        if mode == "error":
            return self._send(500, b"internal error", "text/plain")
        if mode == "garbage":
            return self._send(200, b"<html>maintenance</html>", "text/html")
        if endpoint not in ("v1/forecast", "v1/archive"):
            return self._send(404, b"{}", "application/json")
        start = dt.date.fromisoformat(query["start_date"])
        end = dt.date.fromisoformat(query["end_date"])
        hourly = _hourly("hot" if mode in ("slow", "broken") else mode, start, end)
        if mode == "broken":
            hourly["temperature_2m"] = hourly["temperature_2m"][:-3]
        body = {
            "latitude": float(query["latitude"]),
            "longitude": float(query["longitude"]),
            "generationtime_ms": 0.1,
            "utc_offset_seconds": 0,
            "timezone": "GMT",
            "timezone_abbreviation": "GMT",
            "elevation": 150.0,
            "hourly_units": {
                "time": "iso8601",
                "temperature_2m": "°C",
                "direct_radiation": "W/m²",
                "diffuse_radiation": "W/m²",
                "cloud_cover": "%",
                "wind_speed_10m": "km/h",
                "wind_direction_10m": "°",
            },
            "hourly": hourly,
        }
        self._send(200, json.dumps(body).encode(), "application/json")

    def _send(self, status: int, body: bytes, content_type: str) -> None:
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)


class StubServer(ThreadingHTTPServer):
    daemon_threads = True

    def __init__(self) -> None:
        super().__init__(("127.0.0.1", 0), _Handler)
        self.requests: list[tuple[str, dict[str, str]]] = []
        self.thread = threading.Thread(target=self.serve_forever, daemon=True)
        self.thread.start()

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.server_address[1]}"
