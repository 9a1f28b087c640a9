"""Every error as an RFC 9457 problem document (``application/problem+json``), in one place."""

from __future__ import annotations

import logging
from collections.abc import Awaitable, Callable, Mapping
from typing import Any, TypeVar

from fastapi import FastAPI, Request, Response
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from sqlalchemy.exc import OperationalError
from starlette.exceptions import HTTPException as StarletteHTTPException

from app.execution import UnavailableError
from core.exceptions import (
    CoreError,
    LimitExceededError,
    ServerLimitError,
    ServiceUnavailableError,
    TooMuchToWaitForError,
)
from core.params import BRANCH_TAG, plain_rule

PROBLEM_JSON = "application/problem+json"
E = TypeVar("E", bound=Exception)
_log = logging.getLogger("coldroute")


#: Every kind of problem the service answers, by its title: its status and when it comes.
#: A problem's ``type`` is ``/problems/<the title in lower case, dashed>``.
PROBLEMS: dict[str, tuple[int, str]] = {
    "Invalid request": (422, "a field breaks a rule; `errors[]` names each by its JSON path"),
    "Limit exceeded": (422, "valid, but beyond what the model allows (a job's work)"),
    "Request too large": (413, "more stops, vans, samples or bytes than the service takes at once"),
    "Unauthorized": (401, "`X-API-Key` missing or wrong while `COLDROUTE_API_KEY` is set"),
    "Not found": (404, "no such path, job or vehicle profile"),
    "Method not allowed": (405, "the path does not take the method (`Allow` says which do)"),
    "Conflict": (409, "an `Idempotency-Key` or profile name already used otherwise"),
    "HTTP error": (400, "a request HTTP itself refuses before it reaches the service"),
    "Service unavailable": (503, "workers busy, or a database, broker or router down"),
    "Time limit exceeded": (504, "a job's `error`: it ran longer than its time limit"),
    "Internal error": (500, "a bug: the answer carries the request id, the log its traceback"),
}


def problem_body(status: int, title: str, detail: str, **extra: Any) -> dict[str, Any]:
    """An RFC 9457 problem document of one of :data:`PROBLEMS`."""
    if title not in PROBLEMS:
        raise ValueError(f"{title!r} is not a problem the service documents")
    slug = title.lower().replace(" ", "-")
    body = {"type": f"/problems/{slug}", "title": title, "status": status, "detail": detail}
    return body | extra


def problem(
    status: int,
    title: str,
    detail: str,
    headers: Mapping[str, str] | None = None,
    **extra: Any,
) -> JSONResponse:
    """A problem response (:func:`problem_body`)."""
    return JSONResponse(
        problem_body(status, title, detail, **extra),
        status_code=status,
        media_type=PROBLEM_JSON,
        headers=headers,
    )


def core_problem(error: CoreError) -> dict[str, Any]:
    """The 422 problem of a core error, naming its field."""
    if isinstance(error, TooMuchToWaitForError | ServerLimitError):  # valid, but too large
        status, title = 413, "Request too large"
    elif isinstance(error, LimitExceededError):
        status, title = 422, "Limit exceeded"
    else:
        status, title = 422, "Invalid request"
    errors = [
        {
            "field": _echo(field, MAX_ECHO_PART * 4),
            "message": _echo(message, MAX_ECHO_MESSAGE),
            "type": "value_error",
        }
        for field, message in error.details
    ]
    return problem_body(status, title, _echo(error.message, MAX_ECHO_MESSAGE), **_listed(errors))


def service_problem(error: ServiceUnavailableError) -> dict[str, Any]:
    """The 503 problem of an outside service that failed, naming it."""
    return problem_body(503, "Service unavailable", error.message, service=error.service)


#: Longest part of a field path and longest message an error echoes [characters]: a client
#: that sends a 5 MB property name gets a short answer, not its name back twice.
MAX_ECHO_PART = 64
MAX_ECHO_MESSAGE = 500
#: Most entries a 422 lists: 100,000 empty stops in 400 kB would otherwise be 22 MB of errors.
MAX_ERRORS = 50


def _listed(errors: list[dict[str, str]], total: int | None = None) -> dict[str, Any]:
    """The ``errors`` member of a 422 (the first :data:`MAX_ERRORS` of ``total``, all of
    ``errors`` by default) and, when there were more, ``errors_omitted``: how many are not
    listed."""
    omitted = (len(errors) if total is None else total) - MAX_ERRORS
    return {"errors": errors[:MAX_ERRORS]} | ({"errors_omitted": omitted} if omitted > 0 else {})


def _echo(text: str, limit: int) -> str:
    """What a client sent, cut to ``limit`` characters with a note of its length."""
    return text if len(text) <= limit else f"{text[:limit]}… ({len(text):,} characters)"


def _location(loc: tuple[Any, ...], kind: str = "", body: Any = None) -> str:
    """``("body", "stops", 3, "lat")`` → ``stops[3].lat``; a body that is not JSON → ``body``
    (its location is the character where JSON broke, not a field).

    Every name is one the client sent, read against the ``body`` it sent: pydantic puts the
    branch of a union it tried in the location (``FitParameter``, ``literal['a','b']``), and
    such a name, which is not in the body, is left out — but the last name of an error of a
    field left out (``missing``), which names the field to send."""
    if kind == "json_invalid":
        return "body"
    in_body = bool(loc) and loc[0] == "body"
    parts = list(loc[1:] if in_body else loc)
    # a JSON body is read against; a form's parts (multipart, urlencoded) are named as sent
    path, value, known = "", body, in_body and isinstance(body, dict | list)
    for index, part in enumerate(parts):
        if isinstance(part, str) and part.startswith(BRANCH_TAG):  # a tagged union's branch
            continue
        last = index == len(parts) - 1
        if known and not isinstance(part, int):
            if isinstance(value, dict) and part in value:
                value = value[part]
            elif not last or _union_branch(part):
                continue  # a union's branch, not a field of the body
            else:  # a field left out (missing, or one of two to send): a field all the same
                known = False
        elif known:
            value = value[part] if isinstance(value, list) and 0 <= part < len(value) else None
            known = value is not None
        name = _echo(str(part), MAX_ECHO_PART)
        path += f"[{part}]" if isinstance(part, int) else (f".{name}" if path else name)
    return path or "body"


#: How pydantic names the branches of a union in a location: a model's class name, a
#: ``literal[…]``, ``function-after[…]``, ``list[…]``, or a plain type's name.
_PLAIN_TYPES = frozenset({"str", "int", "float", "bool", "none", "bytes", "decimal"})


def _union_branch(part: str) -> bool:
    """Whether a name in a location that the body does not have is a union's branch."""
    return "[" in part or part[:1].isupper() or part in _PLAIN_TYPES


#: FastAPI's word for a form field where a file was expected.
_NOT_A_FILE = "Expected UploadFile"


def _message(error: Any) -> str:
    if plain_rule(error).startswith(_NOT_A_FILE):
        return "must be a file (multipart/form-data, a part with a filename), not a text field"
    if error["type"] == "json_invalid":
        position = error["loc"][-1] if error["loc"] else "?"
        reason = (error.get("ctx") or {}).get("error", "invalid JSON")
        return f"the body is not valid JSON at character {position}: {reason}"
    return _echo(plain_rule(error), MAX_ECHO_MESSAGE)


def _handler(
    kind: type[E], answer: Callable[[Request, E], Response]
) -> Callable[[Request, Exception], Awaitable[Response]]:
    """An exception handler for ``kind`` (Starlette hands every handler a plain exception)."""

    async def handle(request: Request, error: Exception) -> Response:
        if not isinstance(error, kind):  # registered for another class: not ours to answer
            raise error
        return answer(request, error)

    return handle


#: Errors that only follow from another: a default computed from fields that failed
#: (``time_limit_s``'s, from the stops) is no error of the client's.
_CONSEQUENCES = {"default_factory_not_called"}


def _validation(_: Request, error: RequestValidationError) -> JSONResponse:
    found = [e for e in error.errors() if e["type"] not in _CONSEQUENCES]
    errors = [
        {
            "field": _location(tuple(e["loc"]), e["type"], error.body),
            "message": _message(e),
            "type": e["type"],
        }
        for e in found[:MAX_ERRORS]
    ]
    detail = "; ".join(f"{e['field']}: {e['message']}" for e in errors[:5])
    if len(found) > 5:
        detail += f"; and {len(found) - 5:,} more"
    return problem(422, "Invalid request", detail, **_listed(errors, len(found)))


def _core(_: Request, error: CoreError) -> JSONResponse:
    body = core_problem(error)
    return JSONResponse(body, status_code=body["status"], media_type=PROBLEM_JSON)


def _http(request: Request, error: StarletteHTTPException) -> JSONResponse:
    if error.status_code == 405:
        headers = dict(error.headers or {}) | {
            # Every method documented at this path (Starlette names only the first route's).
            "Allow": ", ".join(sorted(request.app.state.routes.methods(request.url.path)))
        }
        return problem(405, "Method not allowed", str(error.detail), headers=headers)
    if error.status_code == 400:  # a body that cannot even be read is an invalid request
        kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
        what = kind if kind.startswith("multipart/") else "JSON"
        detail = f"the body cannot be read as {_echo(what, MAX_ECHO_PART)} ({error.detail})"
        errors = [{"field": "body", "message": detail, "type": "json_invalid"}]
        return problem(422, "Invalid request", detail, errors=errors)
    titles = {
        401: "Unauthorized",
        404: "Not found",
        405: "Method not allowed",
        409: "Conflict",
        413: "Request too large",
    }
    title = titles.get(error.status_code, "HTTP error")
    return problem(error.status_code, title, str(error.detail), headers=error.headers)


#: Seconds a client should wait before retrying after an outside service failed.
SERVICE_RETRY_AFTER_S = 30


def _service(_: Request, error: ServiceUnavailableError) -> JSONResponse:
    return JSONResponse(
        service_problem(error),
        status_code=503,
        media_type=PROBLEM_JSON,
        headers={"Retry-After": str(SERVICE_RETRY_AFTER_S)},
    )


def _unavailable(_: Request, error: UnavailableError) -> JSONResponse:
    return problem(
        503,
        "Service unavailable",
        error.reason,
        headers={"Retry-After": str(error.retry_after_s)},
        service="workers",
    )


def _database(_: Request, error: OperationalError) -> JSONResponse:
    _log.warning("database unavailable: %s", error)
    return problem(
        503,
        "Service unavailable",
        "the job database does not answer; try again shortly",
        headers={"Retry-After": str(SERVICE_RETRY_AFTER_S)},
        service="database",
    )


def install(app: FastAPI) -> None:
    """Register the problem handlers on ``app``."""
    app.add_exception_handler(RequestValidationError, _handler(RequestValidationError, _validation))
    app.add_exception_handler(CoreError, _handler(CoreError, _core))
    app.add_exception_handler(ServiceUnavailableError, _handler(ServiceUnavailableError, _service))
    app.add_exception_handler(UnavailableError, _handler(UnavailableError, _unavailable))
    app.add_exception_handler(StarletteHTTPException, _handler(StarletteHTTPException, _http))
    app.add_exception_handler(OperationalError, _handler(OperationalError, _database))
    # Anything else: app.main.RequestContext answers 500 and logs it once.
