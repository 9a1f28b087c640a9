"""The servers' side of the Celery scale-out: hand queued jobs to the workers and keep the
queue honest — jobs the broker never got (or lost: Redis keeps nothing on disk) are sent again,
retries when their backoff is over, jobs whose worker died are queued again."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import uuid

from app.jobs.celery_app import TASK, celery_for
from app.jobs.lifecycle import SWEEP_EVERY_S, Lifecycle, runner_name
from app.jobs.store import JobStore, JobView
from app.settings import Settings

_log = logging.getLogger("coldroute.jobs")


class CeleryDispatcher:
    """Sends each due job to the broker once per attempt."""

    def __init__(self, store: JobStore, settings: Settings) -> None:
        self.store = store
        self.settings = settings
        self.lifecycle = Lifecycle(store, settings, runner_name())
        self.celery = celery_for(settings)
        self._task: asyncio.Task[None] | None = None

    def start(self) -> None:
        self._task = asyncio.create_task(self._loop())

    async def stop(self) -> None:
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._task

    @property
    def resend_after_s(self) -> float:
        """How long a sent job may wait to start before its message counts as lost [s]."""
        return max(10 * self.settings.job_stale_after_s, 120.0)

    async def submitted(self, job: JobView) -> None:
        """A job was queued: send it now."""
        await asyncio.to_thread(self.dispatch, job.id)

    def dispatch(self, job_id: str) -> None:
        """Send one attempt of a job to the workers, unless another dispatcher just did."""
        if not self.store.take_dispatch(job_id, self.resend_after_s):
            return
        try:
            self.celery.send_task(TASK, args=[job_id], task_id=f"{job_id}.{uuid.uuid4().hex[:8]}")
        except Exception:
            self.store.undo_dispatch(job_id)
            raise

    def _sweep(self) -> None:
        self.lifecycle.sweep()
        # Jobs the broker never got (a crash between storing and sending), retries now due,
        # and messages lost (Redis restarted) once they have waited well past a normal start.
        for job in self.store.undispatched(older_than_s=self.resend_after_s):
            self.dispatch(job.id)

    async def _loop(self) -> None:
        while True:
            try:
                await asyncio.to_thread(self._sweep)
            except Exception:
                _log.exception("job dispatcher: housekeeping failed; retrying")
            await asyncio.sleep(SWEEP_EVERY_S)
