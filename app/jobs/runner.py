"""Running jobs: the server's own runner (its worker pool) or the Celery dispatcher.

Both keep the promise that nothing accepted is lost: the database is the truth. A running job
says it is alive every ``job_heartbeat_s``; one silent for ``job_stale_after_s`` has lost its
worker (the server or a Celery worker was killed) and goes back to the queue, up to
``job_max_attempts`` runs. Finished jobs are deleted after ``job_retention_s``.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import socket
import uuid
from concurrent.futures import Future
from typing import Any

from app.errors import core_problem, problem_body, service_problem
from app.execution import Executor, UnavailableError
from app.jobs.store import JobStore, JobView
from app.settings import Settings
from app.work import run_job
from core.exceptions import CoreError, ServiceUnavailableError

_log = logging.getLogger("coldroute.jobs")
#: Time a job may run beyond its solver budget: routing, weather and the simulation [s].
JOB_EXTRA_TIME_S = 120.0
#: How often the housekeeping runs (stale jobs, retention, undispatched jobs) [s].
SWEEP_EVERY_S = 2.0


def runner_name() -> str:
    """This process's name in the ``runner`` column."""
    return f"{socket.gethostname()}:{os.getpid()}:{uuid.uuid4().hex[:8]}"


def time_limit_s(job: JobView) -> float:
    """Longest a job may run [s]."""
    return job.time_limit_s + JOB_EXTRA_TIME_S


def failure(error: BaseException) -> tuple[dict[str, Any], bool]:
    """The problem document of a failed run and whether another run may succeed."""
    if isinstance(error, CoreError):
        return core_problem(error), False
    if isinstance(error, ServiceUnavailableError):
        return service_problem(error), True
    if isinstance(error, UnavailableError):
        return problem_body(503, "Service unavailable", error.reason, service="workers"), True
    _log.error("job failed unexpectedly", exc_info=error)
    return problem_body(
        500, "Internal error", "An unexpected error occurred; it has been logged."
    ), False


def exhausted_problem(job: JobView) -> dict[str, Any]:
    return problem_body(
        503,
        "Service unavailable",
        f"the job lost its worker {job.attempts} times; it was given up",
        service="workers",
    )


def sweep(store: JobStore, settings: Settings) -> list[JobView]:
    """Requeue the jobs whose runner went silent (fail those out of attempts) and purge the
    expired; the requeued jobs."""
    requeued = []
    for job in store.stale(settings.job_stale_after_s):
        if job.attempts >= settings.job_max_attempts:
            store.fail_exhausted(job.id, settings.job_max_attempts, exhausted_problem(job))
        elif store.requeue(job.id, job.runner):
            _log.warning("job %s lost its runner %s; queued again", job.id, job.runner)
            requeued.append(job)
    store.purge(settings.job_retention_s)
    return requeued


class LocalRunner:
    """Runs queued jobs on the server's worker pool, a few at a time."""

    def __init__(self, store: JobStore, executor: Executor, settings: Settings) -> None:
        self.store = store
        self.executor = executor
        self.settings = settings
        self.name = runner_name()
        self.active: dict[str, Future[Any]] = {}
        self._finishing: set[asyncio.Task[None]] = set()
        self._task: asyncio.Task[None] | None = None
        self._wake = asyncio.Event()

    def start(self) -> None:
        self._task = asyncio.create_task(self._loop())

    def wake(self) -> None:
        """A job was queued or cancelled: look now."""
        self._wake.set()

    async def stop(self) -> None:
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._task

    async def _loop(self) -> None:
        loop = asyncio.get_running_loop()
        last_sweep = last_beat = 0.0
        while True:
            try:
                now = loop.time()
                if now - last_sweep >= SWEEP_EVERY_S:
                    await asyncio.to_thread(sweep, self.store, self.settings)
                    last_sweep = now
                if now - last_beat >= self.settings.job_heartbeat_s:
                    await asyncio.to_thread(self.store.heartbeat, list(self.active), self.name)
                    last_beat = now
                for job_id in await asyncio.to_thread(
                    self.store.cancelled_among, list(self.active)
                ):
                    self.active[job_id].cancel()  # Pebble stops the worker process
                while len(self.active) < self.settings.job_concurrency:
                    job = await asyncio.to_thread(self.store.claim_next, self.name)
                    if job is None:
                        break
                    future = await self.executor.start(
                        run_job, job.type, job.request, self.settings
                    )
                    self.active[job.id] = future
                    finishing = asyncio.create_task(self._finish(job, future))
                    self._finishing.add(finishing)
                    finishing.add_done_callback(self._finishing.discard)
            except asyncio.CancelledError:
                raise
            except Exception:  # the database may be briefly away: keep going
                _log.exception("job runner: housekeeping failed; retrying")
            self._wake.clear()
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(self._wake.wait(), 0.5)

    async def _finish(self, job: JobView, future: Future[Any]) -> None:
        try:
            result = await asyncio.wait_for(self.executor.finish(future), time_limit_s(job))
            await asyncio.to_thread(self.store.finish, job.id, self.name, result)
        except (asyncio.CancelledError, TimeoutError) as error:
            future.cancel()
            if isinstance(error, TimeoutError):
                problem = problem_body(
                    504, "Time limit exceeded", f"the job ran longer than {time_limit_s(job):g} s"
                )
                await asyncio.to_thread(self.store.finish, job.id, self.name, None, problem)
        except BaseException as error:
            problem, retry = failure(error)
            if retry and job.attempts < self.settings.job_max_attempts:
                await asyncio.to_thread(self.store.requeue, job.id, self.name)
            else:
                await asyncio.to_thread(self.store.finish, job.id, self.name, None, problem)
        finally:
            self.active.pop(job.id, None)
            self.wake()


class CeleryDispatcher:
    """Hands queued jobs to Celery workers and keeps the queue honest: jobs the broker never
    got (or lost, Redis keeps nothing on disk) are sent again, jobs whose worker died are
    queued again. (A worker stops a running job that was cancelled within its heartbeat.)"""

    def __init__(self, store: JobStore, settings: Settings) -> None:
        from app.jobs.celery_app import celery_for

        self.store = store
        self.settings = settings
        self.celery = celery_for(settings)
        self._task: asyncio.Task[None] | None = None

    def start(self) -> None:
        self._task = asyncio.create_task(self._loop())

    def wake(self) -> None:
        pass

    async def stop(self) -> None:
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._task

    def dispatch(self, job: JobView) -> None:
        """Send one job to the workers (a repeated send is harmless: a job runs once)."""
        self.celery.send_task(
            "coldroute.run_job", args=[job.id], task_id=f"{job.id}.{uuid.uuid4().hex[:8]}"
        )
        self.store.mark_dispatched(job.id)

    def _sweep(self) -> None:
        sweep(self.store, self.settings)
        # Jobs the broker never got (a crash between storing and sending) or lost (Redis
        # restarted): sent again once they have waited well past a normal start.
        resend_after_s = max(10 * self.settings.job_stale_after_s, 120.0)
        for job in self.store.undispatched(older_than_s=resend_after_s):
            self.dispatch(job)

    async def _loop(self) -> None:
        while True:
            try:
                await asyncio.to_thread(self._sweep)
            except asyncio.CancelledError:
                raise
            except Exception:
                _log.exception("job dispatcher: housekeeping failed; retrying")
            await asyncio.sleep(SWEEP_EVERY_S)
