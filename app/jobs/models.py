"""The ``jobs`` table."""

from __future__ import annotations

import datetime as dt
from typing import Any, Literal, get_args

from sqlalchemy import JSON, ForeignKey, Integer, String
from sqlalchemy.orm import Mapped, mapped_column

from app.database import Base, UtcDateTime

JobStatus = Literal["queued", "running", "succeeded", "failed", "cancelled"]
#: Every status, in the order a job goes through them.
STATUSES: tuple[JobStatus, ...] = get_args(JobStatus)
#: A job that may still run; one that has ended.
ACTIVE: tuple[JobStatus, ...] = ("queued", "running")
FINISHED: tuple[JobStatus, ...] = ("succeeded", "failed", "cancelled")


class Job(Base):
    """One accepted job, its state and its answer."""

    __tablename__ = "jobs"

    id: Mapped[str] = mapped_column(String(36), primary_key=True)
    type: Mapped[str] = mapped_column(String(32))
    status: Mapped[str] = mapped_column(String(16), index=True)
    request: Mapped[dict[str, Any]] = mapped_column(JSON)
    request_hash: Mapped[str] = mapped_column(String(64))
    idempotency_key: Mapped[str | None] = mapped_column(String(255), unique=True, nullable=True)
    result: Mapped[dict[str, Any] | None] = mapped_column(JSON, nullable=True)
    error: Mapped[dict[str, Any] | None] = mapped_column(JSON, nullable=True)
    attempts: Mapped[int] = mapped_column(Integer, default=0)
    time_limit_s: Mapped[float] = mapped_column(default=0.0)
    runner: Mapped[str | None] = mapped_column(String(255), nullable=True)
    created_at: Mapped[dt.datetime] = mapped_column(UtcDateTime, index=True)
    dispatched_at: Mapped[dt.datetime | None] = mapped_column(UtcDateTime, nullable=True)
    run_after: Mapped[dt.datetime | None] = mapped_column(UtcDateTime, nullable=True)
    started_at: Mapped[dt.datetime | None] = mapped_column(UtcDateTime, nullable=True)
    heartbeat_at: Mapped[dt.datetime | None] = mapped_column(UtcDateTime, nullable=True)
    finished_at: Mapped[dt.datetime | None] = mapped_column(UtcDateTime, nullable=True, index=True)
    #: A job run in parts (:mod:`app.jobs.fanout`): what its parts share (its plan).
    context: Mapped[dict[str, Any] | None] = mapped_column(JSON, nullable=True)


PartStatus = Literal["queued", "running", "done"]


class JobPart(Base):
    """One part of a job run in parts: what it covers, who runs it and, once done, its
    result. Each part is done once (a conditional ``UPDATE`` claims it); a part whose runner
    went silent is queued again."""

    __tablename__ = "job_parts"

    job_id: Mapped[str] = mapped_column(
        String(36), ForeignKey("jobs.id", ondelete="CASCADE"), primary_key=True
    )
    index: Mapped[int] = mapped_column(Integer, primary_key=True)
    spec: Mapped[dict[str, Any]] = mapped_column(JSON)
    weight: Mapped[int] = mapped_column(Integer)
    status: Mapped[str] = mapped_column(String(16))
    runner: Mapped[str | None] = mapped_column(String(255), nullable=True)
    attempts: Mapped[int] = mapped_column(Integer, default=0)
    heartbeat_at: Mapped[dt.datetime | None] = mapped_column(UtcDateTime, nullable=True)
    result: Mapped[dict[str, Any] | None] = mapped_column(JSON, nullable=True)
