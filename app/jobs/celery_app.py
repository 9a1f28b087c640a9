"""Scale-out: jobs run by Celery workers (``make worker``) on any number of machines.

All servers and workers share the PostgreSQL database (the jobs and their results) and the
broker (Redis). Late acknowledgement: a worker that dies mid-job leaves its message to another
worker (and the servers' sweep requeues a job whose heartbeat stopped). A job is claimed with
one conditional ``UPDATE``, so a message delivered twice runs the job once. Retries only where
they are safe: a plan is a pure function of its request, so a job whose road router was down
is run again (``job_max_attempts``); a bad request is failed at once.

Run a worker with ``celery -A app.jobs.worker worker --pool=threads`` (``make worker``) and
``COLDROUTE_BROKER_URL`` / ``COLDROUTE_DATABASE_URL`` set: Celery's threads take the messages,
the worker's process pool (``COLDROUTE_WORKERS`` processes) does the work.
"""

from __future__ import annotations

import logging
from concurrent.futures import TimeoutError as FutureTimeoutError
from functools import lru_cache

from celery import Celery, Task

from app.errors import problem_body
from app.execution import worker_pool
from app.jobs.runner import failure, time_limit_s
from app.jobs.store import store_for
from app.settings import Settings, get_settings
from app.work import run_job

_log = logging.getLogger("coldroute.jobs")
#: Seconds before a job whose road router or weather failed is tried again, by attempt.
RETRY_BACKOFF_S = (5, 20, 60)


def celery_for(settings: Settings) -> Celery:
    """The Celery app of the settings' broker."""
    if settings.broker_url is None:
        raise ValueError("COLDROUTE_BROKER_URL is not set: Celery needs a broker")
    return _celery(settings.broker_url, settings.broker_queue)


@lru_cache(maxsize=4)
def _celery(broker_url: str, queue: str) -> Celery:
    app = Celery("coldroute", broker=broker_url)
    app.conf.update(
        task_default_queue=queue,
        task_acks_late=True,
        task_reject_on_worker_lost=True,
        worker_prefetch_multiplier=1,
        task_ignore_result=True,
        broker_connection_retry_on_startup=True,
        worker_hijack_root_logger=False,
        # A message unacknowledged this long is delivered again (its worker died); the claim
        # keeps a job that is still running from running twice.
        broker_transport_options={"visibility_timeout": 3600},
    )
    app.task(bind=True, name="coldroute.run_job")(_run_job)
    return app


def _run_job(task: Task, job_id: str) -> str:
    """Claim the job, run it in the worker's process pool and keep its heartbeat.

    The work runs in a separate process because OR-Tools holds the GIL: a heartbeat thread
    beside it would starve and the job would look lost. This thread waits, beats, watches for
    a cancellation (then stops the process) and enforces the time limit.
    """
    settings = get_settings()
    store = store_for(settings.database_url)
    runner = task.request.id
    job = store.claim(job_id, runner, stale_after_s=settings.job_stale_after_s)
    if job is None:
        return "not queued (done, cancelled or running elsewhere)"
    future = worker_pool(settings.workers).schedule(
        run_job, args=(job.type, job.request, settings), timeout=time_limit_s(job)
    )
    try:
        while True:
            try:
                result = future.result(timeout=settings.job_heartbeat_s)
                store.finish(job_id, runner, result=result)
                return "succeeded"
            except FutureTimeoutError:
                if future.done():  # the job itself ran out of time
                    raise
            store.heartbeat([job_id], runner)
            if store.cancelled_among([job_id]):
                future.cancel()  # type: ignore[no-untyped-call]  # Pebble stops the process
                return "cancelled"
    except FutureTimeoutError:
        limit = time_limit_s(job)
        problem = problem_body(504, "Time limit exceeded", f"the job ran longer than {limit:g} s")
        store.finish(job_id, runner, error=problem)
        return "failed"
    except Exception as error:
        problem, retry = failure(error)
        if retry and job.attempts < settings.job_max_attempts:
            store.requeue(job_id, runner)
            delay = RETRY_BACKOFF_S[min(job.attempts, len(RETRY_BACKOFF_S)) - 1]
            raise task.retry(countdown=delay, max_retries=settings.job_max_attempts) from None
        store.finish(job_id, runner, error=problem)
        return "failed"
