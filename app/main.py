"""The coldroute web service: ``create_app()`` wires routers, middleware and error handlers."""

from __future__ import annotations

import asyncio
import json
import logging
import secrets
import signal
import threading
import time
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from importlib.metadata import version
from typing import Annotated, Any

from fastapi import APIRouter, Depends, FastAPI, Header, HTTPException
from fastapi.middleware.cors import CORSMiddleware
from pydantic import BaseModel
from pydantic.json_schema import models_json_schema
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from app import errors
from app.execution import Executor
from app.jobs.runner import CeleryDispatcher, LocalRunner
from app.jobs.store import store_for
from app.routers import health, jobs, plans, presets, simulate, studies
from app.schemas import PlanFeatureCollection, Problem
from app.settings import Settings, get_settings

_log = logging.getLogger("coldroute.requests")

DESCRIPTION = """
Route planning and energy simulation for **all-electric refrigerated delivery vans**.

`POST /v1/plans` orders a round's stops with OR-Tools, simulates every leg with the
drive-train, cab and refrigeration model of *"Wholistic simulation of an all-electric
refrigerated delivery vehicle"* and says whether the battery holds out with its reserve.
`POST /v1/simulate` gives the energy of one speed trace. Units are in the field names
(`_m`, `_s`, `_kwh`, `_c`...). Errors are `application/problem+json` (RFC 9457).
"""


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
        body = json.dumps(
            {
                "type": "/problems/request-too-large",
                "title": "Request too large",
                "status": 413,
                "detail": f"request body exceeds {self.max_bytes} bytes",
            }
        ).encode()
        await send(
            {
                "type": "http.response.start",
                "status": 413,
                "headers": [
                    (b"content-type", errors.PROBLEM_JSON.encode()),
                    (b"content-length", str(len(body)).encode()),
                ],
            }
        )
        await send({"type": "http.response.body", "body": body})


class RequestLog:
    """One structured (JSON) log line per request: method, path, status, duration."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        started = time.perf_counter()
        status = 500

        async def recording_send(message: Message) -> None:
            nonlocal status
            if message["type"] == "http.response.start":
                status = message["status"]
            await send(message)

        try:
            await self.app(scope, receive, recording_send)
        finally:
            _log.info(
                json.dumps(
                    {
                        "method": scope["method"],
                        "path": scope["path"],
                        "status": status,
                        "duration_ms": round((time.perf_counter() - started) * 1000, 1),
                    }
                )
            )


def require_api_key(
    settings: Annotated[Settings, Depends(get_settings)],
    x_api_key: Annotated[
        str | None, Header(description="Needed when the server sets a key.")
    ] = None,
) -> None:
    """401 unless the request carries the configured key (no key configured: open)."""
    if settings.api_key is None:
        return
    expected = settings.api_key.get_secret_value()
    if x_api_key is None or not secrets.compare_digest(x_api_key, expected):
        raise HTTPException(
            401, "missing or wrong X-API-Key", headers={"WWW-Authenticate": "ApiKey"}
        )


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
        body = json.dumps(
            errors.problem_body(503, "Service unavailable", "the server is shutting down")
        ).encode()
        await send(
            {
                "type": "http.response.start",
                "status": 503,
                "headers": [
                    (b"content-type", errors.PROBLEM_JSON.encode()),
                    (b"content-length", str(len(body)).encode()),
                    (b"retry-after", b"1"),
                    (b"connection", b"close"),
                ],
            }
        )
        await send({"type": "http.response.body", "body": body})


def _drain_on_signals(executor: Executor) -> None:
    """SIGTERM or SIGINT: start draining at once, then let the server's own handler (uvicorn's)
    stop accepting connections and wait for the ones under way."""
    if threading.current_thread() is not threading.main_thread():
        return  # only the main thread may set handlers (tests run the app elsewhere)
    loop = asyncio.get_running_loop()
    tasks: set[asyncio.Task[None]] = set()

    def start() -> None:
        if not executor.draining:
            task = loop.create_task(executor.drain())
            tasks.add(task)

    for number in (signal.SIGTERM, signal.SIGINT):
        previous = signal.getsignal(number)

        def handler(signum: int, frame: Any, previous: Any = previous) -> None:
            loop.call_soon_threadsafe(start)
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
    runner = (
        CeleryDispatcher(store, settings)
        if settings.broker_url is not None
        else LocalRunner(store, executor, settings)
    )
    runner.start()
    app.state.runner = runner
    await executor.warm_up()
    try:
        yield
    finally:
        await runner.stop()
        app.state.runner = None
        if executor.draining:
            executor.stop()


def create_app(settings: Settings | None = None) -> FastAPI:
    """The ASGI application; ``settings`` overrides the environment (tests)."""
    settings = settings or get_settings()
    logging.basicConfig(level=settings.log_level.upper(), format="%(message)s")
    # One line per request is ours to write; the router and weather calls are not news.
    logging.getLogger("httpx").setLevel(logging.WARNING)
    app = FastAPI(
        title="coldroute",
        version=version("coldroute"),
        description=DESCRIPTION,
        lifespan=_lifespan,
        responses={
            status: {
                "model": Problem,
                "description": description,
                "content": {errors.PROBLEM_JSON: {}},
            }
            for status, description in (
                (400, "Unreadable body"),
                (401, "Missing or wrong X-API-Key"),
                (413, "Request body too large"),
                (422, "Invalid request, fields named"),
            )
        },
    )
    app.dependency_overrides[get_settings] = lambda: settings
    app.state.settings = settings
    app.state.executor = Executor(settings)
    app.state.runner = None
    errors.install(app)
    v1 = APIRouter(prefix="/v1", dependencies=[Depends(require_api_key)])
    for module in (plans, simulate, presets, studies, jobs):
        v1.include_router(module.router)
    app.include_router(v1)
    app.include_router(health.router)
    if settings.cors_origins:
        app.add_middleware(
            CORSMiddleware,
            allow_origins=settings.cors_origins,
            allow_methods=["*"],
            allow_headers=["*"],
        )
    app.add_middleware(BodyLimit, max_bytes=settings.max_body_bytes)
    app.add_middleware(Draining, executor=app.state.executor)
    app.add_middleware(RequestLog)
    _add_response_schemas(app, [PlanFeatureCollection])
    return app


def _add_response_schemas(app: FastAPI, models: list[type[BaseModel]]) -> None:
    """Put models that operations reference by ``$ref`` only (alternative media types) into
    the OpenAPI components."""
    generate = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            schema = generate()
            _, definitions = models_json_schema(
                [(model, "serialization") for model in models],
                ref_template="#/components/schemas/{model}",
            )
            schema["components"]["schemas"].update(definitions.get("$defs", {}))
            app.openapi_schema = schema
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]


app = create_app()
