"""Scale-out: jobs run by Celery workers (``make worker``) on any number of machines.

All servers and workers share the PostgreSQL database (the jobs and their results) and the
broker (Redis). Late acknowledgement: a worker that dies mid-job leaves its message to another
worker (and the servers' sweep requeues a job whose heartbeat stopped). A job is claimed with
one conditional ``UPDATE``, so a message delivered twice runs the job once. Each message is one
attempt; a retry (:class:`app.jobs.lifecycle.RetryPolicy`) puts the job back in the queue with
its backoff, and the servers' dispatcher sends it again when it is due. A job run in parts
(an electrification study) is shared out over every worker (:mod:`app.jobs.fanout`): its
runner calls helpers through the broker, and a part lost with its worker is redone.

Run a worker with ``celery -A app.jobs.worker worker --pool=threads`` (``make worker``) and
``COLDROUTE_BROKER_URL`` / ``COLDROUTE_DATABASE_URL`` set: Celery's threads take the messages,
the worker's process pool (``COLDROUTE_WORKERS`` processes) does the work.
"""

from __future__ import annotations

from functools import lru_cache

from celery import Celery, Task
from sqlalchemy.exc import OperationalError

from app.execution import WorkerPool
from app.jobs.fanout import PartedRun
from app.jobs.lifecycle import JOB_EXTRA_TIME_S, Lifecycle, time_limit_s
from app.jobs.store import store_for
from app.operations.kinds import JOB_KINDS, run_job
from app.settings import Settings, get_settings

#: The name of the task that runs a job.
TASK = "coldroute.run_job"
#: The name of the task that helps run a job's parts (:mod:`app.jobs.fanout`).
HELP_TASK = "coldroute.help_job"
#: How soon a message whose job could not be claimed (the database away) is taken again [s].
DATABASE_RETRY_S = 2


def celery_for(settings: Settings) -> Celery:
    """The Celery app of the settings' broker."""
    if settings.broker_url is None:
        raise ValueError("COLDROUTE_BROKER_URL is not set: Celery needs a broker")
    return _celery(settings.broker_url, settings.broker_queue, visibility_timeout_s(settings))


def visibility_timeout_s(settings: Settings) -> int:
    """How long a taken message stays unacknowledged before the broker hands it to another
    worker [s]: the longest a job may run, and the time its heartbeat takes to go stale. (A
    message of a job still running elsewhere is then dropped by the claim.)"""
    return int(settings.max_job_time_limit_s + JOB_EXTRA_TIME_S + settings.job_stale_after_s)


@lru_cache(maxsize=4)
def _celery(broker_url: str, queue: str, visibility_s: int) -> Celery:
    app = Celery("coldroute", broker=broker_url)
    app.conf.update(
        task_default_queue=queue,
        task_acks_late=True,
        task_reject_on_worker_lost=True,
        worker_prefetch_multiplier=1,
        task_ignore_result=True,
        broker_connection_retry_on_startup=True,
        worker_hijack_root_logger=False,
        # A broker that is down fails a send at once (the job is stored; the dispatcher sends
        # it when the broker is back): a client's POST never waits on it.
        task_publish_retry=False,
        broker_connection_timeout=2,
        broker_transport_options={
            "visibility_timeout": visibility_s,
            "socket_connect_timeout": 2,
            "socket_timeout": 5,
        },
    )
    # no limit on its retries: a claim the database refused is retried until the database is
    # back (retry()'s max_retries=None means the task's default, which was Celery's 3: a
    # claim dropped after 6 s of outage waited for the servers' resend, 85-102 s)
    app.task(bind=True, name=TASK, max_retries=None)(_run_job)
    app.task(bind=True, name=HELP_TASK)(_help_job)
    return app


@lru_cache(maxsize=1)
def _pool(workers: int) -> WorkerPool:
    """This worker's process pool (one per Celery worker process)."""
    return WorkerPool(workers, get_settings().log_level)


def _run_job(task: Task, job_id: str) -> str:
    """Claim the job, run it in the worker's process pool and watch it to its end.

    The work runs in a separate process because OR-Tools holds the GIL: a heartbeat thread
    beside it would starve and the job would look lost.
    """
    settings = get_settings()
    lifecycle = Lifecycle(store_for(settings.database_url), settings, _runner(task))
    try:
        job = lifecycle.claim(job_id)
    except OperationalError as error:
        # The database is away: this message comes back in a moment, not when the servers
        # resend it (minutes); the attempt is not counted, as nothing was claimed.
        raise task.retry(countdown=DATABASE_RETRY_S, exc=error) from None
    if job is None:
        return "not queued (done, cancelled, waiting for a retry or running elsewhere)"
    if JOB_KINDS[job.type].fanout is not None:
        return _parted(task, lifecycle).coordinate(job)
    future = _pool(settings.workers).schedule(
        run_job, (job.type, job.request, settings), timeout_s=time_limit_s(job)
    )
    return lifecycle.watch(job, future)


def _runner(task: Task) -> str:
    """The runner's name: the worker's and the message's (which worker ran what)."""
    return f"{task.request.hostname}/{task.request.id}"


def _help_job(task: Task, job_id: str) -> str:
    """Run parts of a job run in parts until none is left to take."""
    settings = get_settings()
    lifecycle = Lifecycle(store_for(settings.database_url), settings, _runner(task))
    return f"{_parted(task, lifecycle).help(job_id)} parts done"


def _parted(task: Task, lifecycle: Lifecycle) -> PartedRun:
    """This worker's share of a job run in parts: one part at a time per Celery thread (as
    many threads as processes: ``make worker``), helpers called through the broker."""
    pool = _pool(lifecycle.settings.workers)

    def call_helpers(job_id: str, count: int) -> None:
        for _ in range(count):
            task.app.send_task(HELP_TASK, args=[job_id])

    return PartedRun(lifecycle, lambda fn, args: pool.schedule(fn, args), 1, call_helpers)


def stop_pool() -> None:
    """Stop this worker's process pool (its threads would keep the process alive)."""
    if _pool.cache_info().currsize:
        _pool(get_settings().workers).stop()
