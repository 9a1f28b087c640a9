"""Jobs and their results in a relational database (SQLAlchemy 2, Alembic migrations).

SQLite by default (a file beside the server), PostgreSQL (psycopg 3) by URL. Every state
change is one conditional ``UPDATE`` (``… WHERE status = 'queued'``), so two runners can never
both take a job and a cancelled job is never overwritten by a late result.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import json
import uuid
from contextlib import AbstractContextManager
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from sqlalchemy import ColumnElement, case, delete, func, select, text, update
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from app.database import database_for, now
from app.jobs.models import ACTIVE, FINISHED, Job, JobPart


def request_hash(job_type: str, request: dict[str, Any]) -> str:
    """A fingerprint of what was asked, to tell a repeated Idempotency-Key from a reused one."""
    canonical = json.dumps({"type": job_type, "request": request}, sort_keys=True)
    return hashlib.sha256(canonical.encode()).hexdigest()


@dataclass(frozen=True)
class JobView:
    """A job as read from the store."""

    id: str
    type: str
    status: str
    request: dict[str, Any]
    request_hash: str
    result: dict[str, Any] | None
    error: dict[str, Any] | None
    attempts: int
    time_limit_s: float
    runner: str | None
    created_at: dt.datetime
    started_at: dt.datetime | None
    heartbeat_at: dt.datetime | None
    finished_at: dt.datetime | None
    context: dict[str, Any] | None = None

    @classmethod
    def of(cls, job: Job) -> JobView:
        return cls(
            id=job.id,
            type=job.type,
            status=job.status,
            request=job.request,
            request_hash=job.request_hash,
            result=job.result,
            error=job.error,
            attempts=job.attempts,
            time_limit_s=job.time_limit_s,
            runner=job.runner,
            created_at=job.created_at,
            started_at=job.started_at,
            heartbeat_at=job.heartbeat_at,
            finished_at=job.finished_at,
            context=job.context,
        )


@dataclass(frozen=True)
class PartView:
    """A part of a job run in parts (:mod:`app.jobs.fanout`), as claimed."""

    job_id: str
    index: int
    spec: dict[str, Any]
    weight: int
    attempts: int
    runner: str | None


@dataclass(frozen=True)
class Progress:
    """How far a job run in parts is: its parts' weights done and in all (the work they
    stand for, e.g. route-days), and its parts done and in all."""

    done: int
    total: int
    parts_done: int
    parts_total: int


class IdempotencyConflictError(Exception):
    """An Idempotency-Key already names a job with a different request."""

    def __init__(self, job: JobView) -> None:
        super().__init__(job.id)
        self.job = job


class JobStore:
    """The jobs table behind one database URL."""

    def __init__(self, url: str) -> None:
        self.url = url
        self.database = database_for(url)
        self.engine = self.database.engine

    def migrate(self) -> None:
        """Bring the database to the newest revision (idempotent)."""
        self.database.migrate()

    def transaction(self) -> AbstractContextManager[Session]:
        return self.database.transaction()

    def ping(self) -> None:
        """Raise when the database cannot be reached."""
        self.database.ping()

    def create(
        self,
        job_type: str,
        request: dict[str, Any],
        time_limit_s: float,
        idempotency_key: str | None = None,
    ) -> tuple[JobView, bool]:
        """Store a queued job; with a key already used for the same request, the existing
        job. Returns the job and whether it is new."""
        fingerprint = request_hash(job_type, request)
        if idempotency_key is not None:
            existing = self.by_key(idempotency_key)
            if existing is not None:
                if existing.request_hash != fingerprint:
                    raise IdempotencyConflictError(existing)
                return existing, False
        job = Job(
            id=str(uuid.uuid4()),
            type=job_type,
            status="queued",
            request=request,
            request_hash=fingerprint,
            idempotency_key=idempotency_key,
            attempts=0,
            time_limit_s=time_limit_s,
            created_at=now(),
        )
        try:
            with self.transaction() as session:
                session.add(job)
        except IntegrityError:  # the same key, sent twice at once: the other one won
            existing = self.by_key(idempotency_key) if idempotency_key else None
            if existing is None:
                raise
            if existing.request_hash != fingerprint:
                raise IdempotencyConflictError(existing) from None
            return existing, False
        return JobView.of(job), True

    def get(self, job_id: str) -> JobView | None:
        with self.transaction() as session:
            job = session.get(Job, job_id)
            return None if job is None else JobView.of(job)

    def by_key(self, key: str) -> JobView | None:
        with self.transaction() as session:
            job = session.scalars(select(Job).where(Job.idempotency_key == key)).first()
            return None if job is None else JobView.of(job)

    def recent(self, status: str | None = None, limit: int = 50) -> list[JobView]:
        """The newest jobs first, optionally of one status."""
        with self.transaction() as session:
            query = select(Job).order_by(Job.created_at.desc(), Job.id).limit(limit)
            if status is not None:
                query = query.where(Job.status == status)
            return [JobView.of(job) for job in session.scalars(query)]

    def counts(self) -> dict[str, int]:
        """Jobs per status."""
        with self.transaction() as session:
            rows = session.execute(text("SELECT status, COUNT(*) FROM jobs GROUP BY status"))
            return {str(status): int(count) for status, count in rows}

    def claim_next(self, runner: str) -> JobView | None:
        """Take the oldest queued job that is due for ``runner`` (queued → running), in one
        conditional ``UPDATE`` (on PostgreSQL its candidate row is locked, so runners on several
        servers never wait for each other)."""
        moment = now()
        oldest = (
            select(Job.id)
            .where(Job.status == "queued", _due(moment))
            .order_by(Job.created_at, Job.id)
            .limit(1)
        )
        if self.engine.dialect.name == "postgresql":
            oldest = oldest.with_for_update(skip_locked=True)
        with self.transaction() as session:
            taken = session.execute(
                update(Job)
                .where(Job.id == oldest.scalar_subquery(), Job.status == "queued")
                .values(_running(runner, moment))
                .returning(Job.id)
            ).first()
            if taken is None:
                return None
            job = session.get(Job, taken[0])
            return None if job is None else JobView.of(job)

    def claim(self, job_id: str, runner: str, stale_after_s: float | None = None) -> JobView | None:
        """Take one job for ``runner``: a queued one that is due, or (with ``stale_after_s``) a
        running one whose runner has been silent that long. None when it is not to be run."""
        moment = now()
        takeable = (Job.status == "queued") & _due(moment)
        if stale_after_s is not None:
            silent_since = moment - dt.timedelta(seconds=stale_after_s)
            takeable = takeable | ((Job.status == "running") & (Job.heartbeat_at < silent_since))
        with self.transaction() as session:
            taken = session.execute(
                update(Job).where(Job.id == job_id, takeable).values(_running(runner, moment))
            )
            if taken.rowcount != 1:  # type: ignore[attr-defined]
                return None
            job = session.get(Job, job_id)
            return None if job is None else JobView.of(job)

    def heartbeat(self, job_ids: list[str], runner: str) -> None:
        if not job_ids:
            return
        with self.transaction() as session:
            session.execute(
                update(Job)
                .where(Job.id.in_(job_ids), Job.status == "running", Job.runner == runner)
                .values(heartbeat_at=now())
            )

    def finish(
        self,
        job_id: str,
        runner: str,
        result: dict[str, Any] | None = None,
        error: dict[str, Any] | None = None,
    ) -> bool:
        """Record the answer of a running job of ``runner``; False when it was cancelled or
        taken over meanwhile (the answer is then dropped)."""
        with self.transaction() as session:
            done = session.execute(
                update(Job)
                .where(Job.id == job_id, Job.status == "running", Job.runner == runner)
                .values(
                    status="succeeded" if error is None else "failed",
                    result=result,
                    error=error,
                    finished_at=now(),
                )
            )
            return bool(done.rowcount == 1)  # type: ignore[attr-defined]

    def requeue(
        self, job_id: str, runner: str | None = None, *, after_s: float = 0.0, count: bool = True
    ) -> bool:
        """Put a running job back in the queue: its runner lost it (any runner), a retry that
        may run ``after_s`` from now, or a run cut short by a shutdown that does not ``count``
        as an attempt."""
        with self.transaction() as session:
            query = update(Job).where(Job.id == job_id, Job.status == "running")
            if runner is not None:
                query = query.where(Job.runner == runner)
            values: dict[str, Any] = {
                "status": "queued",
                "runner": None,
                "dispatched_at": None,
                "run_after": now() + dt.timedelta(seconds=after_s) if after_s > 0 else None,
            }
            if not count:
                values["attempts"] = Job.attempts - 1
            done = session.execute(query.values(values))
            return bool(done.rowcount == 1)  # type: ignore[attr-defined]

    def cancel(self, job_id: str) -> JobView | None:
        """Cancel a queued or running job (a finished one stays as it is)."""
        with self.transaction() as session:
            session.execute(
                update(Job)
                .where(Job.id == job_id, Job.status.in_(ACTIVE))
                .values(status="cancelled", finished_at=now())
            )
            job = session.get(Job, job_id)
            return None if job is None else JobView.of(job)

    def status_of(self, job_id: str) -> str | None:
        """A job's status (None: no such job), without reading its request or result."""
        with self.transaction() as session:
            return session.scalars(select(Job.status).where(Job.id == job_id)).first()

    def cancelled_among(self, job_ids: list[str]) -> list[str]:
        """Which of these jobs were cancelled."""
        if not job_ids:
            return []
        with self.transaction() as session:
            return list(
                session.scalars(
                    select(Job.id).where(Job.id.in_(job_ids), Job.status == "cancelled")
                )
            )

    def stale(self, stale_after_s: float) -> list[JobView]:
        """Running jobs whose runner has been silent for ``stale_after_s``."""
        silent_since = now() - dt.timedelta(seconds=stale_after_s)
        with self.transaction() as session:
            query = select(Job).where(Job.status == "running", Job.heartbeat_at < silent_since)
            return [JobView.of(job) for job in session.scalars(query)]

    def undispatched(self, resend_after_s: float | None) -> list[JobView]:
        """Queued jobs that are due and were not handed to the broker — or, with
        ``resend_after_s``, were handed that long ago and have not started."""
        moment = now()
        sent: ColumnElement[bool] = Job.dispatched_at.is_(None)
        if resend_after_s is not None:
            sent = sent | (Job.dispatched_at < moment - dt.timedelta(seconds=resend_after_s))
        with self.transaction() as session:
            query = select(Job).where(Job.status == "queued", _due(moment), sent)
            return [JobView.of(job) for job in session.scalars(query)]

    def forget_dispatches(self) -> int:
        """The broker lost its messages: every queued job counts as never sent; how many."""
        with self.transaction() as session:
            done = session.execute(
                update(Job)
                .where(Job.status == "queued", Job.dispatched_at.is_not(None))
                .values(dispatched_at=None)
            )
            return int(done.rowcount)  # type: ignore[attr-defined]

    def take_dispatch(self, job_id: str, resend_after_s: float) -> bool:
        """Whether this caller is to send the job to the broker now: it is queued and due, and
        was not sent (or was sent longer ago than ``resend_after_s``, a lost message). One
        conditional ``UPDATE``, so two dispatchers never both send one attempt."""
        moment = now()
        before = moment - dt.timedelta(seconds=resend_after_s)
        with self.transaction() as session:
            taken = session.execute(
                update(Job)
                .where(
                    Job.id == job_id,
                    Job.status == "queued",
                    _due(moment),
                    Job.dispatched_at.is_(None) | (Job.dispatched_at < before),
                )
                .values(dispatched_at=moment)
            )
            return bool(taken.rowcount == 1)  # type: ignore[attr-defined]

    def undo_dispatch(self, job_id: str) -> None:
        """The send failed: the job waits for the next dispatch."""
        with self.transaction() as session:
            session.execute(
                update(Job)
                .where(Job.id == job_id, Job.status == "queued")
                .values(dispatched_at=None)
            )

    def fail(self, job_id: str, error: dict[str, Any]) -> bool:
        """Fail a running job, whoever runs it (a part of it cannot be done)."""
        with self.transaction() as session:
            done = session.execute(
                update(Job)
                .where(Job.id == job_id, Job.status == "running")
                .values(status="failed", error=error, finished_at=now())
            )
            return bool(done.rowcount == 1)  # type: ignore[attr-defined]

    def fail_exhausted(self, job_id: str, max_attempts: int, error: dict[str, Any]) -> bool:
        """Fail a queued or running job that has used its attempts."""
        with self.transaction() as session:
            done = session.execute(
                update(Job)
                .where(Job.id == job_id, Job.status.in_(ACTIVE), Job.attempts >= max_attempts)
                .values(status="failed", error=error, finished_at=now())
            )
            return bool(done.rowcount == 1)  # type: ignore[attr-defined]

    # Jobs run in parts: each part is claimed, beaten and finished like a job, by one runner.

    def set_parts(
        self, job_id: str, runner: str, context: dict[str, Any], parts: list[tuple[Any, int]]
    ) -> bool:
        """Store the plan of a job ``runner`` runs: what its parts share and each part (its
        spec and weight), all queued; False when the job is no longer this runner's."""
        with self.transaction() as session:
            done = session.execute(
                update(Job)
                .where(Job.id == job_id, Job.status == "running", Job.runner == runner)
                .values(context=context)
            )
            if done.rowcount != 1:  # type: ignore[attr-defined]
                return False
            session.execute(delete(JobPart).where(JobPart.job_id == job_id))
            session.add_all(
                JobPart(job_id=job_id, index=k, spec=spec, weight=weight, status="queued")
                for k, (spec, weight) in enumerate(parts)
            )
            return True

    def claim_part(self, job_id: str, runner: str) -> PartView | None:
        """Take the first queued part of a running job for ``runner``, in one conditional
        ``UPDATE`` (two runners never take one part)."""
        first = (
            select(JobPart.index)
            .where(JobPart.job_id == job_id, JobPart.status == "queued")
            .order_by(JobPart.index)
            .limit(1)
        )
        if self.engine.dialect.name == "postgresql":
            first = first.with_for_update(skip_locked=True)
        with self.transaction() as session:
            running = select(Job.id).where(Job.id == job_id, Job.status == "running").exists()
            taken = session.execute(
                update(JobPart)
                .where(
                    JobPart.job_id == job_id,
                    JobPart.index == first.scalar_subquery(),
                    JobPart.status == "queued",
                    running,
                )
                .values(
                    status="running",
                    runner=runner,
                    heartbeat_at=now(),
                    attempts=JobPart.attempts + 1,
                )
                .returning(JobPart.index)
            ).first()
            if taken is None:
                return None
            part = session.get(JobPart, (job_id, taken[0]))
            return None if part is None else _part_view(part)

    def heartbeat_parts(self, job_id: str, indices: list[int], runner: str) -> None:
        if not indices:
            return
        with self.transaction() as session:
            session.execute(
                update(JobPart)
                .where(_held(job_id, runner), JobPart.index.in_(indices))
                .values(heartbeat_at=now())
            )

    def finish_part(self, job_id: str, index: int, runner: str, result: dict[str, Any]) -> bool:
        """Record a part's result; False when it is no longer ``runner``'s (it was judged lost
        and given to another): the result is dropped, so nothing counts twice."""
        with self.transaction() as session:
            done = session.execute(
                update(JobPart)
                .where(_held(job_id, runner), JobPart.index == index)
                .values(status="done", result=result)  # the runner stays: who did it
            )
            return bool(done.rowcount == 1)  # type: ignore[attr-defined]

    def release_part(self, job_id: str, index: int, runner: str, count: bool = True) -> None:
        """Put a part ``runner`` holds back in the queue: its worker was lost, or (not to
        ``count`` as an attempt) its run was cut short by a shutdown."""
        values: dict[str, Any] = {"status": "queued", "runner": None}
        if not count:
            values["attempts"] = JobPart.attempts - 1
        with self.transaction() as session:
            session.execute(
                update(JobPart).where(_held(job_id, runner), JobPart.index == index).values(values)
            )

    def requeue_lost_parts(self, job_id: str, stale_after_s: float) -> list[PartView]:
        """Queue again the running parts whose runner has been silent for ``stale_after_s``
        (a worker was killed); those parts, as they were."""
        silent_since = now() - dt.timedelta(seconds=stale_after_s)
        lost = (
            JobPart.job_id == job_id,
            JobPart.status == "running",
            JobPart.heartbeat_at < silent_since,
        )
        with self.transaction() as session:
            parts = [_part_view(p) for p in session.scalars(select(JobPart).where(*lost))]
            if parts:
                session.execute(
                    update(JobPart)
                    .where(*lost, JobPart.index.in_([p.index for p in parts]))
                    .values(status="queued", runner=None)
                )
            return parts

    def part_results(self, job_id: str) -> list[dict[str, Any]]:
        """The results of a job's parts, in their order (each part once)."""
        with self.transaction() as session:
            query = (
                select(JobPart.result)
                .where(JobPart.job_id == job_id, JobPart.status == "done")
                .order_by(JobPart.index)
            )
            return [result for result in session.scalars(query) if result is not None]

    def progress(self, job_ids: list[str]) -> dict[str, Progress]:
        """How far each of these jobs run in parts is (jobs not run in parts are absent)."""
        if not job_ids:
            return {}
        done = case((JobPart.status == "done", 1), else_=0)
        with self.transaction() as session:
            rows = session.execute(
                select(
                    JobPart.job_id,
                    func.sum(JobPart.weight * done),
                    func.sum(JobPart.weight),
                    func.sum(done),
                    func.count(),
                )
                .where(JobPart.job_id.in_(job_ids))
                .group_by(JobPart.job_id)
            )
            return {
                str(job_id): Progress(int(w_done), int(w_all), int(n_done), int(n_all))
                for job_id, w_done, w_all, n_done, n_all in rows
            }

    def purge(self, retention_s: float) -> int:
        """Delete jobs finished more than ``retention_s`` ago, and their parts; how many."""
        before = now() - dt.timedelta(seconds=retention_s)
        with self.transaction() as session:
            expired = select(Job.id).where(Job.status.in_(FINISHED), Job.finished_at < before)
            session.execute(delete(JobPart).where(JobPart.job_id.in_(expired)))
            gone = session.execute(
                delete(Job).where(Job.status.in_(FINISHED), Job.finished_at < before)
            )
            return int(gone.rowcount)  # type: ignore[attr-defined]


def _held(job_id: str, runner: str) -> ColumnElement[bool]:
    """The parts of a job that ``runner`` runs now."""
    return (JobPart.job_id == job_id) & (JobPart.status == "running") & (JobPart.runner == runner)


def _part_view(part: JobPart) -> PartView:
    return PartView(part.job_id, part.index, part.spec, part.weight, part.attempts, part.runner)


def _due(moment: dt.datetime) -> ColumnElement[bool]:
    """A queued job may run now: it is not waiting out a retry's backoff."""
    return Job.run_after.is_(None) | (Job.run_after <= moment)


def _running(runner: str, moment: dt.datetime) -> dict[str, Any]:
    """The values of a job that ``runner`` takes at ``moment`` — never started before it was
    created: a job stored after ``moment`` was read, and before the update, is taken too."""
    started = case((Job.created_at > moment, Job.created_at), else_=moment)
    return {
        "status": "running",
        "runner": runner,
        "started_at": started,
        "heartbeat_at": started,
        "run_after": None,
        "attempts": Job.attempts + 1,
    }


@lru_cache(maxsize=8)
def store_for(url: str) -> JobStore:
    """One store (engine and connection pool) per database URL and process."""
    return JobStore(url)
