"""Solving off the server's process: worker processes behind a bounded queue.

OR-Tools' search and the simulation hold Python's GIL, so they run in a pool of worker
*processes* (Pebble's ``ProcessPool``, spawned, niced below the server so that the event loop,
``/healthz`` and the queue keep answering while every worker is busy). In front of the pool an
asyncio queue holds the requests that wait for a worker:

* at most ``queue_size`` wait; beyond, and after ``queue_deadline_s`` of waiting, a request is
  answered 503 with ``Retry-After`` (:class:`UnavailableError`), never left hanging;
* a client that disconnects while waiting gives up its place;
* on SIGTERM (:meth:`Executor.drain`) waiting requests are answered 503 at once, the ones under
  way may finish within ``shutdown_grace_s``, then their workers are stopped and they are
  answered 503 too.

Jobs (:mod:`app.jobs`) share the pool through :meth:`Executor.start`, which hands back the
worker's future so that a running job can be stopped (Pebble terminates its process).
"""

from __future__ import annotations

import asyncio
import contextlib
import ctypes
import logging
import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Awaitable, Callable
from concurrent.futures import CancelledError as FutureCancelledError
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeoutError
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

from pebble import ProcessExpired, ProcessPool
from pydantic import BaseModel
from starlette.responses import Response

from app.logs import configure_logging
from app.operations.encoded import Encoded, answered
from app.settings import Settings
from core.arrays import keep_heap

T = TypeVar("T")
_log = logging.getLogger("coldroute.workers")
#: Nice increment of the workers: the server's event loop comes first on a busy machine.
WORKER_NICENESS = 5
#: How often a waiting request checks for a free worker, its client and the shutdown [s].
_POLL_S = 0.05


class UnavailableError(Exception):
    """The service cannot take this request now: 503 with ``Retry-After``.

    Parameters
    ----------
    reason
        Why, for the client.
    retry_after_s
        When to try again [s].
    """

    def __init__(self, reason: str, retry_after_s: int) -> None:
        super().__init__(reason)
        self.reason = reason
        self.retry_after_s = retry_after_s


#: ``PR_SET_PDEATHSIG`` of Linux's ``prctl`` (linux/prctl.h).
_PR_SET_PDEATHSIG = 1


def _die_with_parent(parent_pid: int) -> None:
    """Have the kernel kill this worker when the process that started it dies, even by SIGKILL
    and in the middle of a C++ search that holds the GIL; where the kernel cannot (not Linux),
    a thread that watches the parent (it may lag behind a search that holds the GIL)."""
    with contextlib.suppress(AttributeError, OSError):
        if ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL) == 0:
            if os.getppid() != parent_pid:  # the parent died before the request took effect
                os._exit(1)
            return
    threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True).start()


def _watch_parent(parent_pid: int) -> None:
    """Exit when the server that started this worker is gone."""
    while True:
        time.sleep(1.0)
        if os.getppid() != parent_pid:
            os._exit(1)


def _initialize_worker(parent_pid: int, log_level: str) -> None:
    keep_heap()
    configure_logging(log_level)
    with contextlib.suppress(OSError):  # not permitted: keep the default priority
        os.nice(WORKER_NICENESS)
    # Stopping a worker must be instant even inside OR-Tools' C++ search (a Python-level
    # handler would only run when the search returns): the operating system's default.
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_parent(parent_pid)


def pool_broke(error: BaseException) -> bool:
    """Whether ``error`` is Pebble's word that its pool broke under the task (a worker that died
    while idle), not the task's own: another run, on a new pool, may succeed."""
    return isinstance(error, BrokenProcessPool) or (
        type(error) is RuntimeError and str(error) == "Unexpected error within the Pool"
    )


def ping() -> int:
    """A worker's process id: what a warm-up runs when it is given nothing to load."""
    return os.getpid()


def sent(made: Encoded) -> Response:
    """The response that sends an answer a worker wrote out: the event loop builds nothing."""
    return Response(made.body, media_type=made.media_type)


class WorkerPool:
    """``workers`` spawned worker processes (Pebble), niced, started on first use.

    Parameters
    ----------
    workers
        How many processes.
    """

    def __init__(self, workers: int, log_level: str = "info") -> None:
        self.workers = workers
        self.log_level = log_level
        self._pool: ProcessPool | None = None

    @property
    def _processes(self) -> ProcessPool:
        if self._pool is None:
            self._pool = ProcessPool(
                max_workers=self.workers,
                context=multiprocessing.get_context("spawn"),
                initializer=_initialize_worker,
                initargs=(os.getpid(), self.log_level),
            )
        return self._pool

    def schedule(
        self, fn: Callable[..., T], args: tuple[Any, ...], timeout_s: float | None = None
    ) -> Future[T]:
        """Run ``fn(*args)`` in a worker; its future, which ``cancel()`` stops (Pebble
        terminates the process) and which fails with ``TimeoutError`` after ``timeout_s``.
        A pool a dead worker broke is replaced first (:meth:`repaired`)."""
        self.repaired()
        future: Future[T] = self._processes.schedule(fn, args=args, timeout=timeout_s)
        return future

    def repaired(self) -> bool:
        """Whether the pool runs or is yet to start, after replacing one that broke: Pebble
        marks its whole pool broken when a worker dies while idle (the kernel's out-of-memory
        killer, a kill -9), and every later task fails — so a broken pool is stopped and a new
        one starts in its place (its processes on first use)."""
        if self._pool is None or self._pool.active:
            return True
        _log.warning("a worker process died while idle; starting the worker pool again")
        self.stop()
        return self._processes.active

    def warm(self, load: Callable[[], object] = ping) -> None:
        """Start every process and have it run ``load`` (about 2 s, once): a worker that
        unpickles a function imports its module, so the first request does not pay for it."""
        for future in [self.schedule(load, ()) for _ in range(self.workers)]:
            future.result()

    @property
    def active(self) -> bool:
        """Whether the processes run and take work."""
        return self._pool is not None and bool(self._pool.active)

    def stop(self) -> None:
        """Stop the processes now (the pool's threads would keep the process alive)."""
        if self._pool is not None:
            self._pool.stop()  # type: ignore[no-untyped-call]
            self._pool.join(timeout=0.5)
            self._pool = None


class Executor:
    """The worker pool of one server and the queue in front of it."""

    def __init__(self, settings: Settings, load: Callable[[], object] = ping) -> None:
        self.settings = settings
        self.load = load
        self.waiting = 0
        self.running = 0
        self.draining = False
        self._free: asyncio.Semaphore | None = None
        self._underway: set[Future[Any]] = set()
        self._stopped = False
        self._draining: asyncio.Task[None] | None = None
        self.pool = WorkerPool(settings.workers, settings.log_level)

    def _slots(self) -> asyncio.Semaphore:
        if self._free is None:
            self._free = asyncio.Semaphore(self.settings.workers)
        return self._free

    async def warm_up(self) -> None:
        """Start every worker and have it import the work (``load``'s module; about 2 s,
        once). Scheduled from the event loop's thread: the kernel ties each worker's life to
        the thread that started it, and this one lives as long as the server."""
        futures = [self.pool.schedule(self.load, ()) for _ in range(self.settings.workers)]
        await asyncio.gather(*(asyncio.wrap_future(future) for future in futures))

    def alive(self) -> bool:
        """Whether the pool runs and takes work (a broken one replaced first)."""
        return not self._stopped and self.pool.repaired() and self.pool.active

    async def run(
        self,
        fn: Callable[..., T],
        *args: Any,
        disconnected: Callable[[], Awaitable[bool]] | None = None,
    ) -> T:
        """``fn(*args)`` in a worker, after waiting in the bounded queue.

        Raises :class:`UnavailableError` when the queue is full, the wait too long or the server
        shutting down; ``fn``'s own exceptions come back as they were raised.
        """
        if self.draining:
            raise UnavailableError("the server is shutting down", 1)
        if self.waiting >= self.settings.queue_size:
            raise UnavailableError(
                f"all {self.settings.workers} workers are busy and {self.waiting} requests "
                "wait; try again shortly",
                max(int(self.settings.queue_deadline_s / 4), 1),
            )
        await self._acquire(disconnected, self.settings.queue_deadline_s)
        try:
            try:
                return await self._await(self._schedule(fn, args))
            except RuntimeError as error:
                if not pool_broke(error):
                    raise
            # the pool broke under it (a worker died while idle): once more on a new one
            return await self._await(self._schedule(fn, args))
        finally:
            self._slots().release()

    async def answer(
        self,
        make: Callable[..., BaseModel],
        *args: Any,
        disconnected: Callable[[], Awaitable[bool]] | None = None,
    ) -> Response:
        """``make(*args)``'s answer, built and written out in a worker (:meth:`run`): the
        response that sends its bytes."""
        return sent(await self.run(answered, make, *args, disconnected=disconnected))

    async def reserve(self, wait_s: float) -> bool:
        """Hold a free worker for a job, waiting at most ``wait_s`` [s] in line with the
        requests; whether one is held (then :meth:`start` it, or :meth:`release` it). Not
        while the server shuts down: a job must not be claimed that could not run."""
        if self.draining:
            return False
        try:
            await asyncio.wait_for(self._slots().acquire(), wait_s)
        except TimeoutError:
            return False
        if self.draining:  # the shutdown began while this waited
            self.release()
            return False
        return True

    def release(self) -> None:
        """Give back a worker :meth:`reserve` held."""
        self._slots().release()

    def start(self, fn: Callable[..., T], *args: Any) -> Future[T]:
        """Start ``fn(*args)`` on the worker :meth:`reserve` held; the worker's future, which
        ``cancel()`` stops (a job). The worker is free again when it ends."""
        future = self._schedule(fn, args)
        future.add_done_callback(lambda _: self.release())
        return future

    def schedule(self, fn: Callable[..., T], args: tuple[Any, ...]) -> Future[T]:
        """Run ``fn(*args)`` in the pool beside the requests (a part of a job that holds a
        worker: it waits in the pool's own line when every worker is busy); its future, which
        ``cancel()`` stops and a shutdown cancels."""
        return self._schedule(fn, args)

    async def _acquire(
        self, disconnected: Callable[[], Awaitable[bool]] | None, deadline_s: float | None
    ) -> None:
        slots = self._slots()
        self.waiting += 1
        waited = time.monotonic()
        try:
            while True:
                if self.draining:
                    raise UnavailableError("the server is shutting down", 1)
                try:
                    await asyncio.wait_for(slots.acquire(), _POLL_S)
                    break
                except TimeoutError:
                    pass
                if deadline_s is not None and time.monotonic() - waited > deadline_s:
                    raise UnavailableError(
                        f"no worker became free within {deadline_s:g} s; try again shortly",
                        max(int(deadline_s / 4), 1),
                    )
                if disconnected is not None and await disconnected():
                    raise asyncio.CancelledError("the client went away while waiting")
        finally:
            self.waiting -= 1
        if self.draining:  # the shutdown began while this request got its worker
            slots.release()
            raise UnavailableError("the server is shutting down", 1)

    def _schedule(self, fn: Callable[..., T], args: tuple[Any, ...]) -> Future[T]:
        future = self.pool.schedule(fn, args)
        self.running += 1
        self._underway.add(future)

        def forget(done: Future[T]) -> None:
            self.running -= 1
            self._underway.discard(done)

        future.add_done_callback(forget)
        return future

    async def _await(self, future: Future[T]) -> T:
        try:
            return await asyncio.wrap_future(future)
        except (asyncio.CancelledError, FutureCancelledError):
            if future.cancelled() and self.draining:
                raise UnavailableError("the server shut down before this finished", 1) from None
            raise
        except ProcessExpired:
            raise UnavailableError("the worker running this was lost; try again", 1) from None
        except FutureTimeoutError:
            raise UnavailableError("the worker did not finish in time", 1) from None

    def begin_drain(self) -> asyncio.Task[None]:
        """SIGTERM: refuse new work at once, let running work finish within the grace, then
        stop the workers (their requests are answered 503); the drain, begun once."""
        if self._draining is None:
            self.draining = True
            self._draining = asyncio.get_running_loop().create_task(self._drain())
        return self._draining

    async def drain(self) -> None:
        """Drain (:meth:`begin_drain`) and wait until the workers have stopped."""
        await self.begin_drain()

    async def _drain(self) -> None:
        deadline = time.monotonic() + self.settings.shutdown_grace_s
        while self._underway and time.monotonic() < deadline:
            await asyncio.sleep(_POLL_S)
        for future in list(self._underway):
            future.cancel()
        await asyncio.sleep(0)  # let the cancelled requests answer before the pool is stopped
        await asyncio.to_thread(self.stop)

    def stop(self) -> None:
        """Stop the workers now."""
        if not self._stopped:
            self._stopped = True
            self.pool.stop()
