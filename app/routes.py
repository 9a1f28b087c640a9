"""The full path template of a request ("/v1/jobs/{job_id}") and the methods documented there,
read from the OpenAPI paths. (FastAPI's route objects hold their path relative to the router
they were declared in, so ``scope["route"].path`` says "/plans" for "/v1/plans".) The pages
outside the contract (the guide, the viewer, Swagger UI) have their methods from the router
itself."""

from __future__ import annotations

import re
from functools import cached_property
from typing import Any

from starlette.routing import Match

#: The methods a path outside the OpenAPI document is tried with (HTTP's, RFC 9110, and PATCH).
METHODS = ("GET", "HEAD", "POST", "PUT", "PATCH", "DELETE", "OPTIONS")


class RouteTemplates:
    """The documented paths of one application, matched against request paths."""

    def __init__(self, app: Any) -> None:
        self.app = app

    @cached_property
    def _patterns(self) -> list[tuple[re.Pattern[str], str, frozenset[str]]]:
        paths: dict[str, dict[str, Any]] = self.app.openapi().get("paths", {})
        # Literal paths before templated ones: "/v1/presets" is not "/v1/presets/{name}".
        ordered = sorted(paths.items(), key=lambda item: item[0].count("{"))
        return [
            (
                re.compile(re.sub(r"\\\{[^/]+?\\\}", "[^/]+", re.escape(template))),
                template,
                frozenset(method.upper() for method in operations),
            )
            for template, operations in ordered
        ]

    def load(self) -> None:
        """Build the OpenAPI document and its patterns now (1–2 s): at start-up, before the
        first request's log line would have it built on the event loop."""
        _ = self._patterns  # the cached property, computed once

    def template(self, path: str) -> str | None:
        """The documented template that ``path`` matches, if any."""
        for pattern, template, _ in self._patterns:
            if pattern.fullmatch(path):
                return template
        return None

    def methods(self, path: str) -> set[str]:
        """Every method documented at ``path``, or the router serves there (a page outside
        the contract: the guide, the viewer)."""
        documented = {
            method
            for pattern, _, methods in self._patterns
            if pattern.fullmatch(path)
            for method in methods
        }
        return documented or {method for method in METHODS if self._routed(path, method)}

    def _routed(self, path: str, method: str) -> bool:
        scope = {"type": "http", "path": path, "method": method, "root_path": "", "headers": []}
        return any(route.matches(scope)[0] == Match.FULL for route in self.app.router.routes)
