"""Jobs run in parts (:class:`app.operations.kinds.Fanout`: an electrification study's
routes), shared out over the workers — the server's own pool, or every Celery worker.

The job's runner is its *coordinator*: it has the request checked and cut into parts (in a
worker), stores the plan (:meth:`app.jobs.store.JobStore.set_parts`), runs parts itself and,
with Celery, calls *helpers* — one message each, taken by any worker — that run parts until
none is left. Each part is claimed with one conditional ``UPDATE`` and beaten like a job, so
it runs in one place at a time; its result is stored only by the runner that still holds it,
so nothing counts twice. A part whose runner goes silent (a worker killed) is queued again
and redone elsewhere; finished parts are kept, also when the coordinator itself is lost (the
job is queued again and its next coordinator finds them). When every part is done, the
coordinator merges their results into the answer — the same however the work was cut up and
wherever it ran. Results go to the database as parts finish: no process holds them all.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, CancelledError, Future, wait
from typing import Any

from sqlalchemy.exc import OperationalError

from app.errors import problem_body
from app.jobs.lifecycle import SWEEP_EVERY_S, Ending, Lifecycle, failure, time_limit_s
from app.jobs.models import ACTIVE
from app.jobs.store import JobView, PartView
from app.operations.kinds import merge_parts, plan_parts, run_part

_log = logging.getLogger("coldroute.jobs")
#: Runs ``fn(*args)`` in a worker process; its future (``cancel()`` stops the process).
Schedule = Callable[[Callable[..., Any], tuple[Any, ...]], "Future[Any]"]
#: Calls ``count`` helpers to the job (Celery: one message each).
Announce = Callable[[str, int], None]
#: The parts a runner holds: each part and the future of its run.
Held = dict[int, tuple[PartView, "Future[Any]"]]


class PartedRun:
    """One runner's share of jobs run in parts.

    Parameters
    ----------
    lifecycle
        The runner's lifecycle (its name, store and settings).
    schedule
        Where the parts run.
    width
        How many parts this runner runs at once.
    announce
        How to call helpers (Celery); None: this runner does every part.
    """

    def __init__(
        self, lifecycle: Lifecycle, schedule: Schedule, width: int, announce: Announce | None = None
    ) -> None:
        self.lifecycle = lifecycle
        self.store = lifecycle.store
        self.settings = lifecycle.settings
        self.runner = lifecycle.runner
        self.schedule = schedule
        self.width = width
        self.announce = announce
        self.finished = 0  # the parts this runner has done

    def coordinate(self, job: JobView) -> Ending:
        """Run the claimed ``job`` to its end: plan it (unless a previous run did), run its
        parts with the helpers, redo lost ones, merge, and record how it ended."""
        deadline = time.monotonic() + time_limit_s(job)
        context = job.context
        if context is None:
            planned = self._plan(job, deadline)
            if isinstance(planned, str):
                return planned
            context = planned
        parts = self.store.progress([job.id]).get(job.id)
        if self.announce is not None and parts is not None:
            self._call_helpers(job.id, parts.parts_total - parts.parts_done - 1)
        return self._run_parts(job, context, deadline, coordinating=True)

    def help(self, job_id: str) -> int:
        """Run parts of a job until none is left to take (a helper); how many it did."""
        job = self.store.get(job_id)
        if job is not None and job.status == "running" and job.context is not None:
            deadline = time.monotonic() + time_limit_s(job)
            self._run_parts(job, job.context, deadline, coordinating=False)
        return self.finished

    def _plan(self, job: JobView, deadline: float) -> dict[str, Any] | Ending:
        """The job checked and cut into parts, stored; or how the job ended meanwhile."""
        started = time.time()
        future = self.schedule(plan_parts, (job.type, job.request, self.settings))
        while True:
            try:
                plan, parts = future.result(timeout=self.settings.job_heartbeat_s)
                break
            except TimeoutError:
                pass
            except CancelledError:  # the server shuts down: another run, not counted
                self.lifecycle.stored(lambda: self.store.requeue(job.id, self.runner, count=False))
                return "interrupted"
            except Exception as error:
                return self.lifecycle.failed(job, error)
            ending = self._beat_job(job, deadline, {}, [future])
            if ending is not None:
                return ending
        context = {"plan": plan, "started_at": started}
        if not self.store.set_parts(job.id, self.runner, context, parts):
            return "interrupted"  # cancelled or taken over meanwhile
        return context

    def _run_parts(
        self, job: JobView, context: dict[str, Any], deadline: float, coordinating: bool
    ) -> Ending:
        """Take and run parts, ``width`` at a time, until the job ends (the coordinator: and
        merge it) or, for a helper, until none is left to take ("succeeded": its share). The
        database may be away meanwhile: the parts under way go on; a result it could not
        take is redone (the part's heartbeat stops)."""
        held: Held = {}
        self._last_sweep = time.monotonic()
        # when the database was last found back (at start: long enough for a sweep)
        self._reachable_since: float | None = self._last_sweep - self.settings.job_stale_after_s
        while True:
            try:
                ending = self._step(job, context, deadline, held, coordinating)
            except OperationalError as error:
                if self._reachable_since is not None:  # said once an outage
                    _log.warning(
                        "job %s: the database is away (%s); the parts go on", job.id, error
                    )
                self._reachable_since = None
                time.sleep(self.settings.job_heartbeat_s)
                continue
            if ending is not None:
                return ending

    def _step(
        self,
        job: JobView,
        context: dict[str, Any],
        deadline: float,
        held: Held,
        coordinating: bool,
    ) -> Ending | None:
        while len(held) < self.width:
            part = self.store.claim_part(job.id, self.runner)
            if part is None:
                break
            args = (job.type, job.request, self.settings, context["plan"], part.spec)
            held[part.index] = (part, self.schedule(run_part, args))
        if not held and not coordinating:
            return "succeeded"
        if held:
            futures = [future for _, future in held.values()]
            wait(futures, timeout=self.settings.job_heartbeat_s, return_when=FIRST_COMPLETED)
        else:  # the helpers run the last parts
            time.sleep(self.settings.job_heartbeat_s)
        for index, (part, future) in list(held.items()):
            if future.done():
                # held until its ending is recorded: a database away meanwhile keeps the
                # result for the next step (it was dropped and the part redone, an attempt)
                ending = self._ended(job, part, future, held, coordinating)
                held.pop(index, None)
                if ending is not None:
                    return ending
        if not coordinating:
            return self._beat_parts(job, held)
        ending = self._beat_job(job, deadline, held)
        if ending is not None:
            return ending
        if self._reachable_since is None:
            self._reachable_since = time.monotonic()
        reachable_s = time.monotonic() - self._reachable_since
        # parts judged lost only once every runner had the time to beat again after an outage
        if time.monotonic() - self._last_sweep >= SWEEP_EVERY_S and (
            reachable_s >= self.settings.job_stale_after_s
        ):
            self._last_sweep = time.monotonic()
            if not self._redo_lost(job):
                return self._stop(job, held, "failed")
        progress = self.store.progress([job.id])[job.id]
        if progress.parts_done == progress.parts_total:
            return self._merge(job, context)
        return None

    def _ended(
        self, job: JobView, part: PartView, future: Future[Any], held: Held, coordinating: bool
    ) -> Ending | None:
        """Record how a part's run ended; how the job ended, if it did."""
        try:
            result = future.result()
        except CancelledError:  # the server shuts down: the parts and the job wait for another
            self.store.release_part(job.id, part.index, self.runner, count=False)
            self._stop(job, held, "interrupted")
            if coordinating:
                self.lifecycle.stored(lambda: self.store.requeue(job.id, self.runner, count=False))
            return "interrupted"
        except Exception as error:
            problem, retryable = failure(error)
            if retryable and part.attempts < self.settings.job_max_attempts:
                _log.warning("job %s: part %d failed (%s); redone", job.id, part.index, error)
                self.store.release_part(job.id, part.index, self.runner)
                return None
            if retryable:
                problem = _exhausted(part)
            self.store.fail(job.id, problem)
            return self._stop(job, held, "failed")
        if self.store.finish_part(job.id, part.index, self.runner, result):
            self.finished += 1
        return None

    def _beat_job(
        self, job: JobView, deadline: float, held: Held, also: list[Future[Any]] | None = None
    ) -> Ending | None:
        """The coordinator's heartbeat (the job's and its parts'): stops the parts (and the
        futures ``also`` under way) when the job was cancelled, failed by a part elsewhere, or
        ran out of time."""
        self.store.heartbeat([job.id], self.runner)
        self.store.heartbeat_parts(job.id, list(held), self.runner)
        status = self.store.status_of(job.id)
        ending: Ending | None = None
        if status != "running":  # cancelled, failed by a part, or taken over
            ending = status if status in ("cancelled", "failed") else "interrupted"  # type: ignore[assignment]
        elif time.monotonic() > deadline:
            ending = self.lifecycle.out_of_time(job)
        if ending is not None:
            for future in also or []:
                future.cancel()
            self._stop(job, held, ending)
        return ending

    def _beat_parts(self, job: JobView, held: Held) -> Ending | None:
        """A helper's heartbeat (its parts'): stops them when the job has ended."""
        self.store.heartbeat_parts(job.id, list(held), self.runner)
        status = self.store.status_of(job.id)
        if status not in ACTIVE:
            return self._stop(job, held, "cancelled" if status == "cancelled" else "failed")
        return None

    def _stop(self, job: JobView, held: Held, ending: Ending) -> Ending:
        """Stop the parts under way here (Pebble terminates their processes); an interrupted
        run gives them back, not counted."""
        for index, (_, future) in list(held.items()):
            future.cancel()
            if ending == "interrupted":
                self.store.release_part(job.id, index, self.runner, count=False)
        held.clear()
        return ending

    def _redo_lost(self, job: JobView) -> bool:
        """Queue again the parts whose runner went silent and call helpers for them; False
        (the job failed) when one has lost its worker as often as a job may."""
        lost = self.store.requeue_lost_parts(job.id, self.settings.job_stale_after_s)
        for part in lost:
            _log.warning(
                "job %s: part %d lost its runner %s; redone", job.id, part.index, part.runner
            )
            if part.attempts >= self.settings.job_max_attempts:
                self.store.fail(job.id, _exhausted(part))
                return False
        if lost and self.announce is not None:
            self._call_helpers(job.id, len(lost))
        return True

    def _call_helpers(self, job_id: str, count: int) -> None:
        assert self.announce is not None
        if count <= 0:
            return
        try:
            self.announce(job_id, count)
        except Exception as error:  # the broker is away: this runner does the parts alone
            _log.warning("job %s: no helpers (%s); its parts run here", job_id, error)

    def _merge(self, job: JobView, context: dict[str, Any]) -> Ending:
        """The answer of every part, recorded."""
        results = self.store.part_results(job.id)
        runtime_s = time.time() - float(context["started_at"])
        try:
            answer = merge_parts(
                job.type, job.request, self.settings, context["plan"], results, runtime_s
            )
        except Exception as error:
            return self.lifecycle.failed(job, error)
        self.lifecycle.stored(lambda: self.store.finish(job.id, self.runner, result=answer))
        return "succeeded"


def _exhausted(part: PartView) -> dict[str, Any]:
    return problem_body(
        503,
        "Service unavailable",
        f"part {part.index} of the job failed {part.attempts} times; the job was given up",
        service="workers",
    )
