"""Liveness (``/healthz``) and readiness (``/readyz``)."""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from importlib.metadata import version

import httpx
from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse

from app.deps import ExecutorDep, SettingsDep
from app.jobs.celery_app import celery_for
from app.jobs.store import store_for
from app.schemas.service import Check, Health, Readiness

router = APIRouter(tags=["health"])
#: How long one dependency may take to answer the readiness probe [s].
CHECK_TIMEOUT_S = 2.0


@router.get("/healthz", operation_id="getHealth", summary="Liveness probe")
async def health() -> Health:
    """Answers while the process runs; it never waits for a solver."""
    return Health(version=version("coldroute"))


async def _check(name: str, probe: Callable[[], str], critical: bool = True) -> Check:
    try:
        detail = await asyncio.wait_for(asyncio.to_thread(probe), CHECK_TIMEOUT_S)
        return Check(name=name, ok=True, detail=detail, critical=critical)
    except TimeoutError:
        return Check(
            name=name, ok=False, detail=f"no answer in {CHECK_TIMEOUT_S:g} s", critical=critical
        )
    except Exception as error:  # whatever went wrong is the detail
        return Check(
            name=name, ok=False, detail=f"{type(error).__name__}: {error}"[:300], critical=critical
        )


def _http_probe(url: str) -> Callable[[], str]:
    def probe() -> str:
        response = httpx.get(url, timeout=CHECK_TIMEOUT_S)
        return f"HTTP {response.status_code} from {url}"

    return probe


@router.get(
    "/readyz",
    operation_id="getReadiness",
    summary="Readiness probe",
    response_model=Readiness,
    responses={503: {"model": Readiness, "description": "A critical dependency is down."}},
)
async def readiness(
    http: Request,
    settings: SettingsDep,
    pool: ExecutorDep,
) -> JSONResponse:
    """Whether the worker pool is alive and the database, the broker and every configured
    outside service answer; 503 naming what is down."""

    def workers() -> str:
        if pool.draining or not pool.alive():
            raise RuntimeError("the worker pool is not running")
        return f"{settings.workers} workers, {pool.running} busy, {pool.waiting} waiting"

    def database() -> str:
        store_for(settings.database_url).ping()
        return "the database answers"

    checks = [_check("workers", workers), _check("database", database)]
    if settings.broker_url is not None:

        def broker() -> str:
            with celery_for(settings).connection_for_write() as connection:
                connection.ensure_connection(max_retries=1, timeout=CHECK_TIMEOUT_S)
            return "the broker answers"

        def celery_workers() -> str:
            queue = settings.broker_queue
            answers = celery_for(settings).control.inspect(timeout=1.0).active_queues() or {}
            serving = sorted(
                worker
                for worker, queues in answers.items()
                if any(q.get("name") == queue for q in queues or [])
            )
            if not serving:
                raise RuntimeError(
                    f"no Celery worker takes jobs from queue {queue!r} "
                    f"({len(answers)} other workers answer): jobs would wait; start `make worker`"
                )
            return f"{len(serving)} Celery workers take jobs from {queue!r}: {', '.join(serving)}"

        checks.append(_check("broker", broker))
        checks.append(_check("celery_workers", celery_workers))
    if settings.osrm_url is not None:
        checks.append(
            _check("osrm", _http_probe(f"{settings.osrm_url.rstrip('/')}/nearest/v1/driving/0,0"))
        )
    if settings.weather_url is not None:
        checks.append(_check("weather", _http_probe(settings.weather_url), critical=False))
    results = await asyncio.gather(*checks)
    down = [c for c in results if not c.ok and c.critical]
    degraded = any(not c.ok for c in results)
    body = Readiness(
        status="unavailable" if down else "degraded" if degraded else "ready",
        checks=list(results),
    )
    return JSONResponse(body.model_dump(mode="json"), status_code=503 if down else 200)
