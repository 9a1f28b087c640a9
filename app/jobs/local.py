"""The server's own job runner: jobs on the server's worker pool, a few at a time, with the one
lifecycle (:mod:`app.jobs.lifecycle`); a job run in parts (:mod:`app.jobs.fanout`) holds one
worker's place and shares its parts out over every worker."""

from __future__ import annotations

import asyncio
import contextlib
import logging

from sqlalchemy.exc import OperationalError

from app.execution import Executor
from app.jobs.fanout import PartedRun
from app.jobs.lifecycle import SWEEP_EVERY_S, Lifecycle, runner_name
from app.jobs.store import JobStore, JobView
from app.operations.kinds import JOB_KINDS, run_job
from app.settings import Settings

_log = logging.getLogger("coldroute.jobs")
#: How often the runner looks for queued jobs when nobody tells it of one [s].
LOOK_EVERY_S = 0.5


class LocalRunner:
    """Runs queued jobs on the server's worker pool, ``job_concurrency`` at a time."""

    def __init__(self, store: JobStore, executor: Executor, settings: Settings) -> None:
        self.executor = executor
        self.settings = settings
        self.lifecycle = Lifecycle(store, settings, runner_name())
        self.watching: set[asyncio.Task[object]] = set()
        self._loop_task: asyncio.Task[None] | None = None
        self._queued = asyncio.Event()

    def start(self) -> None:
        self._loop_task = asyncio.create_task(self._loop())

    async def submitted(self, job: JobView) -> None:
        """A job was queued: look now."""
        self._queued.set()

    async def stop(self) -> None:
        """Take no more jobs; the runs under way end with the worker pool (a shutdown puts them
        back in the queue without counting the run)."""
        if self._loop_task is not None:
            self._loop_task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._loop_task

    async def _loop(self) -> None:
        last_sweep = 0.0
        away = False  # the database, as last seen: said once when it goes, once when it is back
        loop = asyncio.get_running_loop()
        while True:
            self._queued.clear()  # before looking: a job queued while we look is seen next
            try:
                if loop.time() - last_sweep >= SWEEP_EVERY_S:
                    await asyncio.to_thread(self.lifecycle.sweep)
                    last_sweep = loop.time()
                while len(self.watching) < self.settings.job_concurrency:
                    if not await self._take():
                        break
            except OperationalError as error:  # the database is away: one line, no trace
                if not away:
                    _log.warning("job runner: the database is away (%s); waiting for it", error)
                away = True
            except Exception:
                _log.exception("job runner: housekeeping failed; retrying")
            else:
                if away:
                    _log.warning("job runner: the database is back")
                away = False
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(self._queued.wait(), LOOK_EVERY_S)

    async def _take(self) -> bool:
        """Claim the next job and start it; whether there was one. A worker is held before
        the claim: a job is never running here without a worker to run it (busy workers, or a
        shutdown, would leave it claimed and idle)."""
        if not await self.executor.reserve(LOOK_EVERY_S):
            return False
        try:
            job = await asyncio.to_thread(self.lifecycle.claim_next)
        except BaseException:
            self.executor.release()
            raise
        if job is None:
            self.executor.release()
            return False
        if JOB_KINDS[job.type].fanout is not None:  # in parts, over every worker
            parted = PartedRun(self.lifecycle, self.executor.schedule, self.settings.workers)
            watch = asyncio.create_task(asyncio.to_thread(parted.coordinate, job))
            watch.add_done_callback(lambda _: self.executor.release())
        else:
            try:
                future = self.executor.start(run_job, job.type, job.request, self.settings)
            except BaseException:  # not started: its worker free, the job queued again
                self.executor.release()
                await asyncio.to_thread(self.lifecycle.not_started, job)
                raise
            watch = asyncio.create_task(asyncio.to_thread(self.lifecycle.watch, job, future))
        self.watching.add(watch)
        watch.add_done_callback(self._ended)
        return True

    def _ended(self, watch: asyncio.Task[object]) -> None:
        """A run ended: its slot is free, take the next job now."""
        self.watching.discard(watch)
        self._queued.set()
