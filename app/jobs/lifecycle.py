"""One job lifecycle, for the server's own runner and for the Celery workers alike: claim a job,
watch its run (heartbeat, cancellation, time limit) and record how it ended — its answer, a
failure, or a retry after its backoff (:class:`RetryPolicy`).

The database is the truth, so nothing accepted is lost: a running job says it is alive every
``job_heartbeat_s``; one silent for ``job_stale_after_s`` has lost its worker (the server or a
Celery worker was killed) and goes back to the queue (:meth:`Lifecycle.sweep`), up to
``job_max_attempts`` runs. Finished jobs are deleted after ``job_retention_s``.
"""

from __future__ import annotations

import logging
import os
import socket
import time
import uuid
from collections.abc import Callable
from concurrent.futures import CancelledError, Future
from dataclasses import dataclass
from functools import partial
from typing import Any, Literal

from pebble import ProcessExpired
from sqlalchemy.exc import OperationalError

from app.errors import core_problem, problem_body, service_problem
from app.execution import UnavailableError, pool_broke
from app.jobs.store import JobStore, JobView
from app.settings import Settings
from core.exceptions import CoreError, ServiceUnavailableError

_log = logging.getLogger("coldroute.jobs")
#: Time a job may run beyond its solver budget: routing, weather and the simulation [s].
JOB_EXTRA_TIME_S = 120.0
#: How often the housekeeping runs (stale jobs, retention, undispatched jobs) [s].
SWEEP_EVERY_S = 2.0
#: Longest a run waits for the database to record how it ended [s]; beyond, its heartbeat is
#: long stale and the job runs again.
DATABASE_PATIENCE_S = 600.0
#: How a watched run ended.
Ending = Literal["succeeded", "failed", "cancelled", "retrying", "interrupted"]


def runner_name() -> str:
    """This process's name in the ``runner`` column."""
    return f"{socket.gethostname()}:{os.getpid()}:{uuid.uuid4().hex[:8]}"


def time_limit_s(job: JobView) -> float:
    """Longest a job may run [s]."""
    return job.time_limit_s + JOB_EXTRA_TIME_S


@dataclass(frozen=True)
class RetryPolicy:
    """When a failed run is tried again: only when another run may succeed (an outside
    service or a worker was lost; a plan is a pure function of its request), at most
    ``max_attempts`` runs in all, each retry after its backoff.

    Attributes
    ----------
    max_attempts
        Runs of a job before it is failed.
    backoff_s
        Wait before the 2nd, 3rd, … run [s]; the last value repeats.
    """

    max_attempts: int
    backoff_s: tuple[float, ...]

    def retry_after_s(self, attempts: int) -> float | None:
        """The wait before the next run after ``attempts`` runs [s], or None: no more runs."""
        if attempts >= self.max_attempts:
            return None
        return self.backoff_s[min(attempts, len(self.backoff_s)) - 1]


def failure(error: BaseException) -> tuple[dict[str, Any], bool]:
    """The problem document of a failed run and whether another run may succeed."""
    if isinstance(error, CoreError):
        return core_problem(error), False
    if isinstance(error, ServiceUnavailableError):
        return service_problem(error), True
    if isinstance(error, UnavailableError | ProcessExpired) or pool_broke(error):
        reason = error.reason if isinstance(error, UnavailableError) else "its worker was lost"
        return problem_body(503, "Service unavailable", reason, service="workers"), True
    _log.error("job failed unexpectedly", exc_info=error)
    return problem_body(
        500, "Internal error", "An unexpected error occurred; it has been logged."
    ), False


class Lifecycle:
    """The lifecycle of the jobs one runner takes (``runner`` names it in the store)."""

    def __init__(self, store: JobStore, settings: Settings, runner: str) -> None:
        self.store = store
        self.settings = settings
        self.runner = runner
        self.policy = RetryPolicy(settings.job_max_attempts, tuple(settings.job_retry_backoff_s))
        self._reachable_since: float | None = None

    def claim_next(self) -> JobView | None:
        """The oldest due job, now running here."""
        return self.store.claim_next(self.runner)

    def claim(self, job_id: str) -> JobView | None:
        """This job, now running here: if it is queued and due, or its runner went silent."""
        return self.store.claim(job_id, self.runner, self.settings.job_stale_after_s)

    def watch(self, job: JobView, future: Future[Any]) -> Ending:
        """Wait for the run of ``job`` in ``future`` (a worker process), beating its heartbeat,
        stopping it when it is cancelled or runs out of time, and record how it ended. The
        database may be away meanwhile: the run goes on, and what it records waits for the
        database (:meth:`stored`) — an outage costs no run."""
        deadline = time.monotonic() + time_limit_s(job)
        while True:
            try:
                result = future.result(timeout=self.settings.job_heartbeat_s)
            except TimeoutError:
                if future.done():  # the pool's own time limit ended the run
                    return self.out_of_time(job)
            except CancelledError:  # the server shuts down: another run, not counted
                self.stored(lambda: self.store.requeue(job.id, self.runner, count=False))
                return "interrupted"
            except Exception as error:
                return self.failed(job, error)
            else:
                self.stored(partial(self.store.finish, job.id, self.runner, result=result))
                return "succeeded"
            if time.monotonic() > deadline:
                future.cancel()
                return self.out_of_time(job)
            try:
                self.store.heartbeat([job.id], self.runner)
                cancelled = self.store.cancelled_among([job.id])
            except OperationalError as error:  # the database is away: beat again later
                _log.warning("job %s: no heartbeat (%s); the run goes on", job.id, error)
                continue
            if cancelled:
                future.cancel()  # Pebble stops the worker process
                return "cancelled"

    def not_started(self, job: JobView) -> None:
        """Put back a job claimed here that could not be started (not counted as a run)."""
        self.stored(lambda: self.store.requeue(job.id, self.runner, count=False))

    def stored(self, write: Callable[[], object]) -> None:
        """Record an ending, waiting out a database that is away (every heartbeat period, up
        to :data:`DATABASE_PATIENCE_S`; then the job's heartbeat is stale and it runs again)."""
        given_up = time.monotonic() + DATABASE_PATIENCE_S
        while True:
            try:
                write()
                return
            except OperationalError as error:
                if time.monotonic() > given_up:
                    raise
                _log.warning("the database is away (%s); the job's ending waits for it", error)
                time.sleep(self.settings.job_heartbeat_s)

    def out_of_time(self, job: JobView) -> Ending:
        """Fail a job that ran out of time."""
        limit_s = time_limit_s(job)
        problem = problem_body(504, "Time limit exceeded", f"the job ran longer than {limit_s:g} s")
        self.stored(lambda: self.store.finish(job.id, self.runner, error=problem))
        return "failed"

    def failed(self, job: JobView, error: BaseException) -> Ending:
        """Retry a run that failed, after its backoff, if another may succeed; else fail. A
        run the pool broke under before it ran (a worker dead while idle) is no attempt: it
        goes back to the queue at once, not counted."""
        if pool_broke(error):
            _log.warning("job %s: the worker pool broke under it; queued again", job.id)
            self.stored(lambda: self.store.requeue(job.id, self.runner, count=False))
            return "retrying"
        problem, retryable = failure(error)
        wait_s = self.policy.retry_after_s(job.attempts) if retryable else None
        if wait_s is not None:
            self.stored(lambda: self.store.requeue(job.id, self.runner, after_s=wait_s))
            _log.warning("job %s failed (%s); again in %g s", job.id, problem["detail"], wait_s)
            return "retrying"
        self.stored(lambda: self.store.finish(job.id, self.runner, error=problem))
        return "failed"

    def sweep(self) -> list[JobView]:
        """Requeue the jobs whose runner went silent (fail those out of attempts) and purge the
        expired; the requeued jobs. Silence is judged only once this sweeper has reached the
        database for ``job_stale_after_s`` without a break: after an outage (or at start) the
        runners that kept running get their heartbeat in first, and lose no attempt."""
        settings = self.settings
        try:
            stale = self.store.stale(settings.job_stale_after_s)
        except OperationalError:
            self._reachable_since = None
            raise
        moment = time.monotonic()
        if self._reachable_since is None:
            self._reachable_since = moment
        if moment - self._reachable_since < settings.job_stale_after_s:
            stale = []
        requeued = []
        for job in stale:
            if job.attempts >= settings.job_max_attempts:
                self.store.fail_exhausted(job.id, settings.job_max_attempts, _exhausted(job))
            elif self.store.requeue(job.id, job.runner):
                _log.warning("job %s lost its runner %s; queued again", job.id, job.runner)
                requeued.append(job)
        self.store.purge(settings.job_retention_s)
        return requeued


def _exhausted(job: JobView) -> dict[str, Any]:
    return problem_body(
        503,
        "Service unavailable",
        f"the job lost its worker {job.attempts} times; it was given up",
        service="workers",
    )
