"""What every answer of the service must keep, checked in one place: the test client of every
API test (:class:`CheckedClient`) checks each answer it receives.

- Every 422 names fields the client sent (or, for a field left out, one the request model
  has at that place): never an internal name (``speed_mps[35]`` for a matrix cell,
  ``Weather.t_min_c``, ``parameters[0].literal[…]``).
- Every round's battery verdict agrees with its own numbers: ``feasible`` ⇔ ``min_soc ≥
  reserve_soc`` ⇔ ``margin_kwh ≥ 0``, the margin is the lowest charge's distance to the reserve,
  and no state of charge in legs, stops, charges or the profile lies below ``min_soc``.
"""

from __future__ import annotations

import json
import re
from functools import cache
from typing import Any

import httpx
from fastapi.testclient import TestClient

_SEGMENT = re.compile(r"([^.\[\]]+)|\[(\d+)\]")
_CUT = re.compile(r"… \([0-9,]+ characters\)$")
#: Float noise allowed between figures computed in different places [–].
SOC_TOLERANCE = 1e-9


def field_segments(path: str) -> list[str | int]:
    """``trips[1].speed_mps[40]`` → ``["trips", 1, "speed_mps", 40]``."""
    return [int(index) if index else name for name, index in _SEGMENT.findall(path)]


@cache
def _openapi() -> dict[str, Any]:
    from app.main import app

    return app.openapi()


def _resolve(schema: dict[str, Any]) -> list[dict[str, Any]]:
    """The schema and every branch of it (``$ref``, ``anyOf``, ``oneOf``, ``allOf``)."""
    if "$ref" in schema:
        name = schema["$ref"].rsplit("/", 1)[-1]
        return _resolve(_openapi()["components"]["schemas"][name])
    found = [schema]
    for key in ("anyOf", "oneOf", "allOf"):
        for branch in schema.get(key, []):
            found += _resolve(branch)
    return found


def _child_schemas(schemas: list[dict[str, Any]], segment: str | int) -> list[dict[str, Any]]:
    children: list[dict[str, Any]] = []
    for schema in schemas:
        if isinstance(segment, int):
            for key in ("items", "prefixItems"):
                items = schema.get(key)
                if isinstance(items, dict):
                    children += _resolve(items)
                elif isinstance(items, list) and segment < len(items):
                    children += _resolve(items[segment])
        else:
            prop = schema.get("properties", {}).get(segment)
            if prop is not None:
                children += _resolve(prop)
            extra = schema.get("additionalProperties")
            if isinstance(extra, dict):
                children += _resolve(extra)
    return children


def field_problem(path: str, body: Any, schema: dict[str, Any] | None) -> str | None:
    """Why ``path`` is not a field of the request ``body``, or None when it is: every
    segment but the last is in the body, and the last is in the body or in the request model
    at that place (a field left out and named is one the client could send)."""
    if path == "body":
        return None
    segments = field_segments(path)
    value: Any = body
    schemas = [] if schema is None else _resolve(schema)
    for depth, segment in enumerate(segments):
        last = depth == len(segments) - 1
        if isinstance(segment, str) and isinstance(value, dict) and _CUT.search(segment):
            # a name echoed cut short (app.errors.MAX_ECHO_PART): the one it begins
            segment = next((k for k in value if k.startswith(_CUT.split(segment)[0])), segment)
        present = (
            isinstance(segment, int) and isinstance(value, list) and segment < len(value)
        ) or (isinstance(segment, str) and isinstance(value, dict) and segment in value)
        schemas = _child_schemas(schemas, segment)
        if present:
            value = value[segment]
            continue
        if last and schemas:
            return None
        return f"{path!r}: {segment!r} is not in the request"
    return None


def _template(path: str) -> str | None:
    for template in _openapi()["paths"]:
        if re.fullmatch(re.sub(r"\{[^}]+\}", "[^/]+", template), path):
            return template
    return None


def _request_schema(method: str, template: str | None) -> dict[str, Any] | None:
    if template is None:
        return None
    body = _openapi()["paths"][template].get(method.lower(), {}).get("requestBody", {})
    content = body.get("content", {}).get("application/json")
    return None if content is None else content["schema"]


def check_problem_fields(
    method: str, url: httpx.URL, body: Any, headers: Any, answer: dict[str, Any]
) -> None:
    template = _template(url.path)
    for error in answer.get("errors", []):
        field = error["field"]
        where, _, name = field.partition(".")
        if where == "path":
            assert template is not None and f"{{{name}}}" in template, f"{field}: not in the path"
        elif where == "query":
            assert name in url.params, f"{field}: no such query parameter sent"
    schema = _request_schema(method, template)
    if schema is None:
        return
    pairs = headers.items() if isinstance(headers, dict) else (headers or [])
    sent_headers = {
        (name.decode() if isinstance(name, bytes) else str(name)).lower() for name, _ in pairs
    }
    for error in answer.get("errors", []):
        field = error["field"]
        if field.startswith("header."):
            assert field.removeprefix("header.") in sent_headers, f"{field}: no such header sent"
            continue
        if field.startswith(("path.", "query.")):
            continue
        problem = field_problem(field, body, schema)
        assert problem is None, f"422 of {method} {url.path} names a field nobody sent: {problem}"


def check_battery(route: dict[str, Any]) -> None:
    """A round's verdict against its own series."""
    battery = route["battery"]
    lowest, reserve = battery["min_soc"], battery["reserve_soc"]
    assert battery["feasible"] == (lowest >= reserve - SOC_TOLERANCE), battery
    assert battery["feasible"] == (battery["margin_kwh"] >= -1e-6), battery
    expected_margin = (lowest - reserve) * battery["usable_capacity_kwh"]
    assert abs(battery["margin_kwh"] - expected_margin) < 1e-6, battery
    series = [leg[k] for leg in route["legs"] for k in ("soc_start", "soc_end")]
    series += [stop[k] for stop in route["stops"] for k in ("soc_arrival", "soc_departure")]
    series += [c[k] for c in route.get("charges", []) for k in ("soc_before", "soc_after")]
    if route.get("profile"):
        series += route["profile"]["soc"]
    assert min(series, default=lowest) >= lowest - SOC_TOLERANCE, (min(series), battery)
    if route["legs"]:
        assert abs(route["legs"][-1]["soc_end"] - battery["final_soc"]) < SOC_TOLERANCE, battery
    if not battery["feasible"]:
        assert battery["first_infeasible_leg"] is not None, battery


def check_cold_chain(route: dict[str, Any]) -> None:
    """A round's cold-chain verdict, its deliveries' and its baselines against its own
    numbers."""
    chain = route.get("cold_chain")
    if not chain:
        return
    low, high = chain["product_min_c"], chain["product_max_c"]
    inside = chain["min_c"] <= low and high <= chain["max_c"] + chain["excursion_c"]
    if chain["verdict"] == "holds":
        assert inside and chain["reason"] is None and chain["first_break_s"] is None, chain
    else:
        too_long = chain["minutes_outside_band"] > chain["excursion_minutes"]
        assert chain["reason"] and (not inside or too_long or "cannot hold" in chain["reason"])
    delivered = [stop["goods"] for stop in route["stops"] if stop.get("goods")]
    warmest = [goods["product_max_c"] for goods in delivered]
    assert warmest == sorted(warmest) and all(w <= high + 1e-9 for w in warmest), warmest
    verdicts = [goods["verdict"] for goods in delivered]
    assert verdicts == sorted(verdicts, key=lambda v: v == "breaks"), verdicts
    assert chain["verdict"] == "breaks" or "breaks" not in verdicts, verdicts
    unit = route.get("refrigeration") or {}
    for baseline in unit.get("baselines", []):
        saved = 1 - unit["battery_kwh"] / baseline["battery_kwh"] if baseline["battery_kwh"] else 0
        assert abs(baseline["battery_saved"] - saved) < 1e-9, baseline


def check_answer(answer: Any) -> None:
    """Every round in a plan, a fleet plan or a job's result."""
    if not isinstance(answer, dict):
        return
    if "battery" in answer and "legs" in answer:
        check_battery(answer)
        check_cold_chain(answer)
    for route in answer.get("routes", []) if isinstance(answer.get("routes"), list) else []:
        if isinstance(route, dict) and "battery" in route:
            check_battery(route)
            check_cold_chain(route)
    if isinstance(answer.get("result"), dict):
        check_answer(answer["result"])


class CheckedClient(TestClient):
    """A test client that checks :mod:`tests.app.invariants` on every answer."""

    def request(self, method: str, url: Any, **kwargs: Any) -> httpx.Response:  # type: ignore[override]
        response = super().request(method, url, **kwargs)
        sent = httpx.URL(str(url), params=kwargs.get("params"))
        path = sent.path
        body = kwargs.get("json")
        if body is None and isinstance(kwargs.get("content"), (str, bytes)):
            try:
                body = json.loads(kwargs["content"])
            except ValueError:
                body = None
        is_json = response.headers.get("content-type", "").endswith("json")
        if response.status_code == 422 and body is not None and is_json:
            check_problem_fields(method, sent, body, kwargs.get("headers"), response.json())
        elif response.status_code == 200 and is_json and path.startswith("/v1/"):
            check_answer(response.json())
        return response
