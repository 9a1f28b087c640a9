"""The jobs' store on its own: a job stored while a runner is claiming is never started before
it was created (CI saw started_at 6 ms before created_at: the runner read the clock, the job
was stored, then the runner's UPDATE took it)."""

from __future__ import annotations

import datetime as dt

import pytest

from app.jobs import store as store_module
from app.jobs.store import JobStore, Progress


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


def test_a_jobs_parts_are_each_done_once(tmp_path):
    """Two runners share a job's parts: each part is claimed by one, its result kept only
    from the runner that still holds it; a silent runner's part is queued again."""
    store = JobStore(f"sqlite:///{tmp_path}/jobs.db")
    job, _ = store.create("electrification", {"routes": []}, 1.0)
    assert store.claim(job.id, "coordinator") is not None
    context = {"plan": {"weather": "climatology"}, "started_at": 0.0}
    assert store.set_parts(job.id, "coordinator", context, [([0, 2], 10), ([2, 3], 5)])
    assert not store.set_parts(job.id, "another", context, [])  # not its job
    first = store.claim_part(job.id, "a")
    second = store.claim_part(job.id, "b")
    assert first is not None and second is not None and (first.index, second.index) == (0, 1)
    assert first.spec == [0, 2] and first.attempts == 1
    assert store.claim_part(job.id, "c") is None  # both taken
    assert store.progress([job.id])[job.id] == Progress(0, 15, 0, 2)
    # b goes silent (a beats): b's part is queued again and taken by c; b's late result
    # is dropped, so nothing counts twice
    later = store_module.now() + dt.timedelta(seconds=10)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(store_module, "now", lambda: later)
        store.heartbeat_parts(job.id, [0], "a")
        lost = store.requeue_lost_parts(job.id, stale_after_s=5)
    assert [(p.index, p.runner) for p in lost] == [(1, "b")]
    again = store.claim_part(job.id, "c")
    assert again is not None and again.index == 1 and again.attempts == 2
    assert not store.finish_part(job.id, 1, "b", {"late": True})
    assert store.finish_part(job.id, 1, "c", {"part": 1})
    assert store.finish_part(job.id, 0, "a", {"part": 0})
    assert store.part_results(job.id) == [{"part": 0}, {"part": 1}]
    assert store.progress([job.id])[job.id] == Progress(15, 15, 2, 2)
    assert store.get(job.id).context == context
    # a finished job's parts go with it
    assert store.finish(job.id, "coordinator", result={"done": True})
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(store_module, "now", lambda: later)
        assert store.purge(retention_s=1) == 1
    assert store.progress([job.id]) == {}
