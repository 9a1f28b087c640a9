"""Every error as an RFC 9457 problem document (``application/problem+json``), in one place."""

from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from core.exceptions import CoreError, LimitExceededError, ServiceUnavailableError

PROBLEM_JSON = "application/problem+json"
_log = logging.getLogger("coldroute")


def problem(
    status: int,
    title: str,
    detail: str,
    headers: Mapping[str, str] | None = None,
    **extra: Any,
) -> JSONResponse:
    """A problem response; ``type`` names the problem kind under /problems/."""
    slug = title.lower().replace(" ", "-")
    body = {"type": f"/problems/{slug}", "title": title, "status": status, "detail": detail}
    return JSONResponse(body | extra, status_code=status, media_type=PROBLEM_JSON, headers=headers)


def _location(loc: tuple[Any, ...]) -> str:
    """``("body", "stops", 3, "lat")`` → ``stops[3].lat``."""
    path = ""
    for part in loc[1:] if loc and loc[0] == "body" else loc:
        path += f"[{part}]" if isinstance(part, int) else (f".{part}" if path else str(part))
    return path or "body"


async def _validation(_: Request, error: Exception) -> JSONResponse:
    assert isinstance(error, RequestValidationError)
    errors = [
        {"field": _location(tuple(e["loc"])), "message": e["msg"], "type": e["type"]}
        for e in error.errors()
    ]
    detail = "; ".join(f"{e['field']}: {e['message']}" for e in errors[:5])
    return problem(422, "Invalid request", detail, errors=errors)


async def _core(_: Request, error: Exception) -> JSONResponse:
    assert isinstance(error, CoreError)
    title = "Limit exceeded" if isinstance(error, LimitExceededError) else "Invalid request"
    errors = [{"field": error.field or "body", "message": error.message, "type": "value_error"}]
    return problem(422, title, error.message, errors=errors)


async def _http(_: Request, error: Exception) -> JSONResponse:
    assert isinstance(error, StarletteHTTPException)
    titles = {
        401: "Unauthorized",
        404: "Not found",
        405: "Method not allowed",
        413: "Request too large",
    }
    title = titles.get(error.status_code, "HTTP error")
    return problem(error.status_code, title, str(error.detail), headers=error.headers)


#: Seconds a client should wait before retrying after an outside service failed.
SERVICE_RETRY_AFTER_S = 30


async def _service(_: Request, error: Exception) -> JSONResponse:
    assert isinstance(error, ServiceUnavailableError)
    return problem(
        503,
        "Service unavailable",
        error.message,
        headers={"Retry-After": str(SERVICE_RETRY_AFTER_S)},
        service=error.service,
    )


async def _unexpected(_: Request, error: Exception) -> JSONResponse:
    _log.exception("unexpected error", exc_info=error)
    return problem(500, "Internal error", "An unexpected error occurred; it has been logged.")


def install(app: FastAPI) -> None:
    """Register the problem handlers on ``app``."""
    app.add_exception_handler(RequestValidationError, _validation)
    app.add_exception_handler(CoreError, _core)
    app.add_exception_handler(ServiceUnavailableError, _service)
    app.add_exception_handler(StarletteHTTPException, _http)
    app.add_exception_handler(Exception, _unexpected)
