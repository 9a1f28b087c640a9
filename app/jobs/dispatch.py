"""The servers' side of the Celery scale-out: hand queued jobs to the workers and keep the
queue honest. A job is stored before it is sent, so a broker that is down loses nothing: the
job is sent when the broker is back (within a sweep). Retries are sent when their backoff is
over, one message per attempt. A broker that restarted (Redis keeps nothing on disk) lost every
message it held: those jobs are sent again at once. A message can also vanish with a worker
that died holding it; a job sent long ago that has not started is sent again only when the
queue is empty — a backlog is messages waiting for workers, not lost ones."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import uuid
from typing import Literal

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
        self._broker_run: str | None = None  # the broker's run id: it changes when it restarts

    def start(self) -> None:
        self._task = asyncio.create_task(self._loop())

    async def stop(self) -> None:
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._task

    async def submitted(self, job: JobView) -> None:
        """A job was queued: send it now, or — the broker being down — when it is back."""
        try:
            await asyncio.to_thread(self.dispatch, job.id)
        except Exception as error:  # stored: the sweep sends it
            _log.warning("broker unavailable (%s); job %s is sent when it is back", error, job.id)

    def dispatch(self, job_id: str) -> None:
        """Send one attempt of a job to the workers, unless another dispatcher just did."""
        if not self.store.take_dispatch(job_id, self.settings.job_resend_after_s):
            return
        try:
            self.celery.send_task(TASK, args=[job_id], task_id=f"{job_id}.{uuid.uuid4().hex[:8]}")
        except Exception:
            self.store.undo_dispatch(job_id)
            raise

    def _sweep(self) -> None:
        self.lifecycle.sweep()
        broker = self._broker()
        if isinstance(broker, tuple):
            run, waiting = broker
            if self._broker_run is not None and run != self._broker_run:
                lost = self.store.forget_dispatches()
                _log.warning("the broker restarted: %d queued jobs are sent again", lost)
            self._broker_run = run
            resend = waiting == 0
        else:  # "other": a broker that cannot say what it holds; "down": nothing goes out now
            resend = broker == "other"
        # Never sent (the broker was down, or a crash between storing and sending) and due; and,
        # with nothing waiting in the queue, sent long ago without starting.
        for job in self.store.undispatched(self.settings.job_resend_after_s if resend else None):
            self.dispatch(job.id)

    def _broker(self) -> tuple[str, int] | Literal["other", "down"]:
        """The broker's run id and the messages waiting in the queue (Redis); "other" for a
        broker that cannot tell, "down" when it does not answer."""
        try:
            with self.celery.connection_for_write() as connection:
                client = connection.default_channel.client
                run = str(client.info("server")["run_id"])
                return run, int(client.llen(self.settings.broker_queue))
        except AttributeError:  # not a Redis broker
            return "other"
        except Exception:
            return "down"

    async def _loop(self) -> None:
        while True:
            try:
                await asyncio.to_thread(self._sweep)
            except Exception:
                _log.exception("job dispatcher: housekeeping failed; retrying")
            await asyncio.sleep(SWEEP_EVERY_S)
