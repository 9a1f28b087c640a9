"""The jobs' store on its own: a job stored while a runner is claiming is never started before
it was created (CI saw started_at 6 ms before created_at: the runner read the clock, the job
was stored, then the runner's UPDATE took it)."""

from __future__ import annotations

import datetime as dt

import pytest

from app.jobs import store as store_module
from app.jobs.store import JobStore


@pytest.mark.parametrize("claim", ["next", "by_id"])
def test_a_job_stored_after_the_claims_clock_starts_when_it_was_created(
    tmp_path, monkeypatch, claim
):
    store = JobStore(f"sqlite:///{tmp_path}/jobs.db")
    job, _ = store.create("plan", {"stops": []}, 1.0)
    # the runner's clock read a little before the job was stored
    before = job.created_at - dt.timedelta(milliseconds=6)
    monkeypatch.setattr(store_module, "now", lambda: before)
    taken = store.claim_next("runner") if claim == "next" else store.claim(job.id, "runner")
    assert taken is not None and taken.id == job.id and taken.status == "running"
    assert taken.started_at == job.created_at
    # taken at a later clock, the clock is the start
    later = job.created_at + dt.timedelta(seconds=2)
    other, _ = store.create("plan", {"stops": [1]}, 1.0)
    monkeypatch.setattr(store_module, "now", lambda: later)
    second = store.claim_next("runner") if claim == "next" else store.claim(other.id, "runner")
    assert second is not None and second.started_at == later
