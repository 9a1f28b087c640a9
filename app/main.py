"""The coldroute web service: ``create_app()`` wires routers, middleware and error handlers."""

from __future__ import annotations

import asyncio
import json
import logging
import re
import signal
import threading
import time
import uuid
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from importlib.metadata import version
from typing import Any

from fastapi import APIRouter, FastAPI, HTTPException, Response
from fastapi.middleware.cors import CORSMiddleware
from fastapi_offline import FastAPIOffline
from prometheus_client import CONTENT_TYPE_LATEST, generate_latest
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from app import errors, openapi_doc
from app.deps import api_key_refusal
from app.execution import Executor
from app.jobs.dispatch import CeleryDispatcher
from app.jobs.local import LocalRunner
from app.jobs.store import store_for
from app.logs import REQUEST_ID, configure_logging
from app.metrics import Metrics
from app.operations.kinds import loaded
from app.routers import (
    calibrations,
    fleet,
    guide,
    health,
    jobs,
    plans,
    presets,
    profiles,
    simulate,
    studies,
    viewer,
)
from app.routes import RouteTemplates
from app.schemas.plans import PlanFeatureCollection
from app.settings import Settings, get_settings

_log = logging.getLogger("coldroute.requests")

DESCRIPTION = """
Route planning and energy simulation for **all-electric refrigerated delivery vans**.

`POST /v1/plans` orders a round's stops (a local search, CP-SAT's proof), simulates every leg with
the drive-train, cab and refrigeration model of *"Wholistic simulation of an all-electric
refrigerated delivery vehicle"* and says whether the battery holds out with its reserve. `POST
/v1/fleet-plans` splits the day's stops across several vans with time windows, shifts, payload and
each battery as constraints, and verifies every route by the full simulation. `POST /v1/simulate`
gives the energy of one speed trace. `POST /v1/calibrations` fits the model to a van's measured
trips (JSON, or CSV files at `/v1/calibrations/csv`), and `/v1/vehicle-profiles` keeps your vans by
name — from a preset with changes or from a calibration — for any request's
`"vehicle": {"profile": …}`. Units are in the field names (`_m`, `_s`, `_kwh`, `_c`...).
Errors are `application/problem+json` (RFC 9457). A search uses the time it is given
(`time_limit_s`; absent: a default for the request's size), and the same request gives the same
answer, byte for byte but the timing fields (`solver.runtime_s`): searches stop on their work
(`work_s`, by default 85 % of the limit less 0.3 s; seeded by `seed`). When the limit stops one
first (`solver.stopped_by: time_limit`, on a slow or busy machine), the answer's
`solver.replay`, sent back as the request's `replay`, gives the same answer again.

**[The plan viewer](/viewer)** plans a day from a CSV of stops and shows it: the routes on a map,
the state of charge, the energy per consumer and the box temperature over the day.
**[The guide](/guide/)** explains it all per kind of user, with examples that the tests run."""


class BodyLimit:
    """Answer 413 to a request body larger than ``max_bytes`` (declared or streamed)."""

    def __init__(self, app: ASGIApp, max_bytes: int) -> None:
        self.app = app
        self.max_bytes = max_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope["headers"]).get(b"content-length")
        if declared is not None and declared.isdigit() and int(declared) > self.max_bytes:
            await self._reject(send)
            return
        received = 0

        async def counting_receive() -> Message:
            nonlocal received
            message = await receive()
            received += len(message.get("body", b""))
            if received > self.max_bytes:
                raise HTTPException(413, f"request body exceeds {self.max_bytes} bytes")
            return message

        await self.app(scope, counting_receive, send)

    async def _reject(self, send: Send) -> None:
        detail = f"request body exceeds {self.max_bytes} bytes"
        await _send_problem(send, 413, "Request too large", detail)


_REQUEST_ID_PATTERN = re.compile(r"^[A-Za-z0-9._:-]{1,128}$")
#: The methods of HTTP (RFC 9110 and PATCH): any other token is answered before routing (405
#: naming the path's methods, 404 on a path the service does not have) and counted under one
#: label ("OTHER"), so made-up methods cannot grow the metrics without bound.
KNOWN_METHODS = frozenset(
    {"GET", "HEAD", "POST", "PUT", "DELETE", "PATCH", "OPTIONS", "TRACE", "CONNECT"}
)


def _shown(text: str, limit: int = 40) -> str:
    """A token a client sent, short enough to echo."""
    return text if len(text) <= limit else f"{text[:limit]}…"


async def _send_problem(
    send: Send,
    status: int,
    title: str,
    detail: str,
    headers: tuple[tuple[bytes, bytes], ...] = (),
    **extra: str,
) -> None:
    """Answer with a problem document from a middleware (before or instead of any router)."""
    body = json.dumps(errors.problem_body(status, title, detail, **extra)).encode()
    await send(
        {
            "type": "http.response.start",
            "status": status,
            "headers": [
                (b"content-type", errors.PROBLEM_JSON.encode()),
                (b"content-length", str(len(body)).encode()),
                *headers,
            ],
        }
    )
    await send({"type": "http.response.body", "body": body})


class RequestContext:
    """Per request: an ``X-Request-ID`` (the client's, if it is a sane token, else a new
    one) returned in the answer; one structured (JSON) log line (method, path, route, status,
    duration, request id); the request metrics; and a last safety net: an unexpected error is
    a 500 problem with ``Connection: close`` and one logged traceback carrying the request
    id, never a dropped connection."""

    def __init__(self, app: ASGIApp, metrics: Metrics, routes: RouteTemplates) -> None:
        self.app = app
        self.metrics = metrics
        self.routes = routes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        started = time.perf_counter()
        method = scope["method"] if scope["method"] in KNOWN_METHODS else "OTHER"
        sent = dict(scope["headers"]).get(b"x-request-id", b"").decode("latin-1")
        request_id = sent if _REQUEST_ID_PATTERN.match(sent) else uuid.uuid4().hex
        token = REQUEST_ID.set(request_id)
        status = 500
        answered = False

        async def tagged_send(message: Message) -> None:
            nonlocal status, answered
            if message["type"] == "http.response.start":
                status = message["status"]
                answered = True
                message["headers"] = [
                    *message.get("headers", []),
                    (b"x-request-id", request_id.encode()),
                    # every answer is what its Content-Type says: never sniffed as a script
                    (b"x-content-type-options", b"nosniff"),
                ]
            await send(message)

        try:
            if method == "OTHER":  # answered before routing: a made-up method is no route's
                await self._unknown_method(scope, tagged_send)
            else:
                await self.app(scope, receive, tagged_send)
        except Exception:
            _log.exception("unexpected error")
            if not answered:
                await _send_problem(
                    tagged_send,
                    500,
                    "Internal error",
                    f"An unexpected error occurred; it has been logged as {request_id}.",
                    ((b"connection", b"close"),),
                    request_id=request_id,
                )
        finally:
            template = self.routes.template(scope["path"]) or "unmatched"
            seconds = time.perf_counter() - started
            self.metrics.observe(method, template, status, seconds)
            _log.info(
                "request",
                extra={
                    "method": method,
                    "path": scope["path"],
                    "route": template,
                    "status": status,
                    "duration_ms": round(seconds * 1000, 1),
                },
            )
            REQUEST_ID.reset(token)

    async def _unknown_method(self, scope: Scope, send: Send) -> None:
        allowed = sorted(self.routes.methods(scope["path"]))
        if not allowed:
            await _send_problem(send, 404, "Not found", "no such path")
            return
        await _send_problem(
            send,
            405,
            "Method not allowed",
            f"{_shown(scope['method'])} is not a method of {self.routes.template(scope['path'])}; "
            "it takes "
            f"{', '.join(allowed)}",
            ((b"allow", ", ".join(allowed).encode()),),
        )


class ApiKey:
    """``/v1/…`` only with the configured ``X-API-Key`` (none configured: open): a 401 before
    anything of the request is read — a large upload is not parsed for a client without the
    key."""

    def __init__(self, app: ASGIApp, settings: Settings) -> None:
        self.app = app
        self.settings = settings

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        path = scope.get("path", "")
        if scope["type"] == "http" and (path == "/v1" or path.startswith("/v1/")):
            sent = [v.decode("latin-1") for k, v in scope["headers"] if k == b"x-api-key"]
            refusal = api_key_refusal(self.settings, sent)
            if refusal is not None:
                headers = ((b"www-authenticate", b"ApiKey"),)
                await _send_problem(send, 401, "Unauthorized", refusal, headers)
                return
        await self.app(scope, receive, send)


DOCS_PATHS = frozenset({"/docs", "/redoc"})
# The docs pages may load only what the service itself serves: ReDoc's attribution logo would
# otherwise be fetched from a CDN, which a dispatcher's offline network cannot reach.
DOCS_POLICY = (
    b"default-src 'self'; script-src 'self' 'unsafe-inline'; style-src 'self' 'unsafe-inline'; "
    b"img-src 'self' data:; font-src 'self' data:; worker-src 'self' blob:; connect-src 'self'"
)


class DocsPolicy:
    """A ``Content-Security-Policy`` on the Swagger UI and ReDoc pages: same origin only."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["path"] not in DOCS_PATHS:
            await self.app(scope, receive, send)
            return

        async def with_policy(message: Message) -> None:
            if message["type"] == "http.response.start":
                message["headers"] = [
                    *message.get("headers", []),
                    (b"content-security-policy", DOCS_POLICY),
                ]
            await send(message)

        await self.app(scope, receive, with_policy)


class Draining:
    """After SIGTERM, a request that still reaches the server (a kept-alive connection) is
    answered 503 at once and its connection closed; liveness still answers."""

    def __init__(self, app: ASGIApp, executor: Executor) -> None:
        self.app = app
        self.executor = executor

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or not self.executor.draining or scope["path"] == "/healthz":
            await self.app(scope, receive, send)
            return
        await _send_problem(
            send,
            503,
            "Service unavailable",
            "the server is shutting down",
            ((b"retry-after", b"1"), (b"connection", b"close")),
        )


class ProbesAnswerHead:
    """``HEAD`` on the probes (``/healthz``, ``/readyz``) is their ``GET`` without the body,
    as load balancers and container runtimes send it."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["method"] != "HEAD" or scope["path"] not in PROBES:
            await self.app(scope, receive, send)
            return

        async def headers_only(message: Message) -> None:
            if message["type"] == "http.response.body":
                message = {**message, "body": b""}
            await send(message)

        await self.app({**scope, "method": "GET"}, receive, headers_only)


PROBES = frozenset({"/healthz", "/readyz"})


def _drain_on_signals(executor: Executor) -> None:
    """SIGTERM or SIGINT: start draining at once, then let the server's own handler (uvicorn's)
    stop accepting connections and wait for the ones under way."""
    if threading.current_thread() is not threading.main_thread():
        return  # only the main thread may set handlers (tests run the app elsewhere)
    loop = asyncio.get_running_loop()

    for number in (signal.SIGTERM, signal.SIGINT):
        previous = signal.getsignal(number)

        def handler(signum: int, frame: Any, previous: Any = previous) -> None:
            loop.call_soon_threadsafe(executor.begin_drain)
            if callable(previous):
                previous(signum, frame)

        signal.signal(number, handler)


@asynccontextmanager
async def _lifespan(app: FastAPI) -> AsyncIterator[None]:
    settings: Settings = app.state.settings
    executor: Executor = app.state.executor
    _drain_on_signals(executor)
    store = store_for(settings.database_url)
    await asyncio.to_thread(store.migrate)
    runner: LocalRunner | CeleryDispatcher
    if settings.broker_url is None:
        runner = LocalRunner(store, executor, settings)
    else:
        runner = CeleryDispatcher(store, settings)
    runner.start()
    app.state.runner = runner
    await asyncio.gather(executor.warm_up(), asyncio.to_thread(app.state.routes.load))
    try:
        yield
    finally:
        await runner.stop()
        app.state.runner = None
        # Runs under way get the grace (a shutdown began it, or begins it now), then the
        # workers stop.
        await executor.drain()


def create_app(settings: Settings | None = None) -> FastAPI:
    """The ASGI application; ``settings`` overrides the environment (tests)."""
    settings = settings or get_settings()
    configure_logging(settings.log_level)
    # Swagger UI and ReDoc from the service itself (fastapi-offline's pinned assets): the docs
    # work without internet.
    app = FastAPIOffline(
        title="coldroute",
        version=version("coldroute"),
        description=DESCRIPTION,
        lifespan=_lifespan,
        swagger_ui_parameters={"persistAuthorization": True, "displayRequestDuration": True},
    )
    app.dependency_overrides[get_settings] = lambda: settings
    app.state.settings = settings
    executor = Executor(settings, load=loaded)
    app.state.executor = executor
    app.state.runner = None
    metrics = Metrics()
    metrics.watch(
        lambda: executor.waiting,
        lambda: executor.running,
        lambda: store_for(settings.database_url).counts(),
    )
    app.state.metrics = metrics
    errors.install(app)
    v1 = APIRouter(prefix="/v1")
    for module in (plans, fleet, simulate, presets, profiles, studies, calibrations, jobs):
        v1.include_router(module.router)
    app.include_router(v1)
    app.include_router(health.router)
    app.include_router(viewer.router)
    app.include_router(guide.router)

    @app.get("/metrics", include_in_schema=False)
    def prometheus() -> Response:
        return Response(generate_latest(metrics.registry), media_type=CONTENT_TYPE_LATEST)

    app.add_middleware(ApiKey, settings=settings)
    if settings.cors_origins:
        app.add_middleware(
            CORSMiddleware,
            allow_origins=settings.cors_origins,
            allow_methods=["*"],
            allow_headers=["*"],
        )
    app.add_middleware(BodyLimit, max_bytes=settings.max_body_bytes)
    app.add_middleware(DocsPolicy)
    app.add_middleware(Draining, executor=executor)
    app.add_middleware(ProbesAnswerHead)
    app.state.routes = RouteTemplates(app)
    app.add_middleware(RequestContext, metrics=metrics, routes=app.state.routes)
    generate = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            app.openapi_schema = openapi_doc.finish(generate(), [PlanFeatureCollection])
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
    return app


app = create_app()
