"""How much a search may do: an amount of *work*, the same on any machine and under any load,
and a deadline that only caps it.

The same request gives the same answer when its searches stop on work, not on the clock.
The work is counted in *reference seconds*: what the solvers do in one second of one idle core
of the project's reference machine (2 cores, x86-64), converted into each solver's own
deterministic unit by the rates below — kicks of the round trip's local search, iterations of
PyVRP, CP-SAT's deterministic time. A search that reaches the deadline first stops there and
says so (``time_limit``). Every look at the clock that may stop a search is a :class:`Watch`:
the :class:`Clock` shared by a request's searches records where each one stopped (the *n*-th
watch, at the count of units its search had done), so that a replay — the same request with
those records — stops every search at the same place, without the clock, on any machine: the
same answer to the byte, even of a search the deadline cut.

Rates, measured on the reference machine (uniform and clustered instances):

- the round trip's local search (:mod:`core.routing.ils`): kicks per second by the number of
  places, interpolated log-log in :data:`KICKS_PER_S`;
- PyVRP's iterated local search (:mod:`core.routing.pyvrp_run`): a time per iteration and a
  time per move its local search evaluates, each linear in the number of clients
  (:data:`PYVRP_ITERATION_S`, :data:`PYVRP_MOVE_S`), fitted on the fleet's models of
  Solomon's instances (25 and 100 clients) and Gehring–Homberger's six classes (200, 400 and
  1,000): within −28 %…+27 % of the time each run took, where iterations alone were out by up
  to 2.5 times (an iteration of a clustered day, C1 or C2, evaluates half the moves of one of
  random places). Fitted on two runs at once (one per core, 20 % slower than one alone), then
  scaled to one alone: default requests of 25, 100 and 1,000 stops used 50–74 % of their limit
  with the fit as measured (``benchmarks/bench_limits.py``);
- OR-Tools' guided local search (:mod:`core.routing.vrp`): ``500 · (20 / places)^1.4``
  solutions per second (20 places: 500; 40: 190; 100: 52; 200: 20), on random instances with
  windows and an energy budget (long runs: the first solutions come faster);
- CP-SAT: 0.3 units of deterministic time per second (0.13–0.42 measured on round-trip
  models of 20–60 places; the lower end, so that the work ends within the reference time).
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from core.exceptions import ServerLimitError

#: How a search ended: its work done, its optimum proven, or cut short by the deadline.
SearchEnd = Literal["work", "proof", "time_limit"]

#: Kicks per reference second of the round trip's local search, by places.
KICKS_PER_S = ((20, 14_000), (40, 9_700), (80, 8_900), (150, 6_400), (300, 3_800),
               (600, 2_500), (1_000, 1_800))  # fmt: skip
#: PyVRP's reference seconds per iteration, ``a + b · clients`` (the loop around the local
#: search: perturbation, copies of the solution, the acceptance test).
PYVRP_ITERATION_S = (34e-6, 0.16e-6)
#: PyVRP's reference seconds per move its local search evaluates, ``a + b · clients``.
PYVRP_MOVE_S = (27e-9, 0.034e-9)
#: What those cost with every stop optional (each a prize): its moves are quicker to evaluate
#: (0.47–0.69 of the time the same count takes with every stop required, 100 and 1,000 clients).
PYVRP_OPTIONAL_COST = 0.57
#: OR-Tools' routing solutions per reference second:
#: ``ORTOOLS_RATE · (ORTOOLS_SIZE / places)^ORTOOLS_EXPONENT``.
ORTOOLS_RATE = 500.0
ORTOOLS_SIZE = 20.0
ORTOOLS_EXPONENT = 1.4
#: CP-SAT's deterministic time per reference second.
CPSAT_DETERMINISTIC_PER_S = 0.3


@dataclass
class Clock:
    """Where the deadline stopped a request's searches: ``stops`` maps the *n*-th watch made
    (in the order the searches made them, the same on every run of the same work) to the count
    of units its search had done when the clock stopped it. Replaying (``replayed`` given),
    the clock is never read: each watch stops where the replayed record says, and nowhere
    else. ``request``: what the searches solve (a fingerprint), for the record."""

    replayed: dict[int, int] | None = None
    request: str = ""
    stops: dict[int, int] = field(default_factory=dict)
    made: int = 0
    #: Replaying: when (a ``time.perf_counter`` value) the replay has run too long, and the
    #: time it had [s] — a replay's work is not capped by its request's clock, so this is
    #: what stops a replay whose work no answer of the server did.
    guard: float = math.inf
    guard_s: float = math.inf

    @property
    def replaying(self) -> bool:
        return self.replayed is not None

    def watch(self, deadline: float) -> Watch:
        """The next watch, on ``deadline`` (a ``time.perf_counter`` value)."""
        self.made += 1
        return Watch(self, self.made - 1, deadline)

    def guarded(self, cut: bool = False) -> None:
        """Replaying: raise :class:`core.exceptions.ServerLimitError` naming ``replay`` once
        the replay has run past its guard, or when a solver's own time limit (the guard's)
        ``cut`` it — either way its answer would not be the replayed one."""
        if cut or time.perf_counter() > self.guard:
            raise ServerLimitError(
                f"this replay's searches ran for more than the {self.guard_s:g} s this server "
                "gives a replay: its work (replay.work_s, replay.stops) is more than an answer "
                "of this server did — send an answer's solver.replay unchanged",
                "replay",
            )


@dataclass
class Watch:
    """One look at the clock that may stop a search, asked again as the search counts its
    units (iterations, kicks, moves, places): :meth:`passed` says whether to stop now."""

    clock: Clock
    index: int
    deadline: float

    def passed(self, count: int) -> bool:
        """Whether the search stops after ``count`` units (counts never go back): at the
        deadline, recorded; replaying, where the record says."""
        if self.clock.replayed is not None:
            self.clock.guarded()
            at = self.clock.replayed.get(self.index)
            return at is not None and count >= at
        if self.index in self.clock.stops:
            return True
        if time.perf_counter() < self.deadline:
            return False
        self.mark(count)
        return True

    def mark(self, count: int) -> None:
        """Record that the clock stopped the search after ``count`` units, where the search
        saw it itself (a solver's own time limit); replaying, that limit is the guard's
        (:meth:`Clock.guarded`)."""
        if self.clock.replayed is None:
            self.clock.stops.setdefault(self.index, count)
        else:
            self.clock.guarded(cut=True)

    def replayed_at(self) -> int | None:
        """Replaying: the count after which the record stops the search (None: it ran its
        work); None when not replaying — for a solver that counts and stops by itself."""
        if self.clock.replayed is None:
            return None
        return self.clock.replayed.get(self.index)


@dataclass(frozen=True)
class Effort:
    """A search's work [reference s], the deadline that caps it (a ``time.perf_counter``
    value), its seed and the request's :class:`Clock`."""

    work_s: float
    deadline: float
    seed: int = 0
    clock: Clock = field(default_factory=Clock, compare=False)

    @classmethod
    def starting_now(
        cls,
        work_s: float,
        time_limit_s: float,
        seed: int = 0,
        replayed: dict[int, int] | None = None,
        request: str = "",
        replay_limit_s: float = math.inf,
    ) -> Effort:
        """``work_s`` of work, capped ``time_limit_s`` from now; ``replayed``: where the
        deadline stopped the same work of the same ``request`` before (:class:`Clock`), the
        clock then unread but for the replay's own limit, ``replay_limit_s`` from now."""
        now = time.perf_counter()
        clock = Clock(replayed, request, guard=now + replay_limit_s, guard_s=replay_limit_s)
        return cls(work_s, now + time_limit_s, seed, clock)

    def watch(self) -> Watch:
        """A new look at this effort's deadline."""
        return self.clock.watch(self.deadline)

    def share(self, fraction: float) -> Effort:
        """A part of the work, under the same deadline."""
        return replace(self, work_s=self.work_s * fraction)

    def within(self, fraction: float) -> Effort:
        """The same work with its deadline at ``fraction`` of the time left from now."""
        return replace(self, deadline=time.perf_counter() + self.left_s() * fraction)

    def keeping(self, reserve_s: float) -> Effort:
        """The same work with ``reserve_s`` [s] kept before the deadline for what follows."""
        return replace(self, deadline=self.deadline - reserve_s)

    def left_s(self) -> float:
        """Time to the deadline [s]; replaying, to the replay's guard (its watches stop the
        searches): for solvers' own time limits and reserves, never to decide whether to
        stop."""
        if self.clock.replaying:
            return self.clock.guard - time.perf_counter()
        return self.deadline - time.perf_counter()

    def kicks(self, places: int) -> int:
        """The round trip's local search: kicks in this work."""
        return max(int(self.work_s * _interpolated(KICKS_PER_S, places)), 0)

    @staticmethod
    def pyvrp_spent_s(iterations: int, moves: int, clients: int, optional: bool = False) -> float:
        """The work [reference s] of PyVRP's ``iterations`` in which its local search
        evaluated ``moves``, on ``clients``, its stops required or ``optional``."""
        iteration_s = PYVRP_ITERATION_S[0] + PYVRP_ITERATION_S[1] * clients
        move_s = PYVRP_MOVE_S[0] + PYVRP_MOVE_S[1] * clients
        spent_s = iterations * iteration_s + moves * move_s
        return spent_s * (PYVRP_OPTIONAL_COST if optional else 1.0)

    def ortools_solutions(self, places: int) -> int:
        """OR-Tools' routing solutions in this work."""
        rate = ORTOOLS_RATE * (ORTOOLS_SIZE / max(places, 1)) ** ORTOOLS_EXPONENT
        return max(int(self.work_s * rate), 1)

    def cpsat_deterministic_time(self) -> float:
        """CP-SAT's deterministic time in this work."""
        return self.work_s * CPSAT_DETERMINISTIC_PER_S


def _interpolated(table: tuple[tuple[int, int], ...], size: int) -> float:
    """A rate of ``table`` (size, rate) at ``size``, log-log between its rows (its ends
    beyond them)."""
    logs = np.log(np.asarray(table, dtype=float))
    return float(np.exp(np.interp(math.log(max(size, 2)), logs[:, 0], logs[:, 1])))


def combined(ends: Iterable[SearchEnd]) -> SearchEnd:
    """How a search of several parts ended: cut short if any part was, proven if every part
    was, its work done otherwise (nothing run: its work done)."""
    found = set(ends)
    if "time_limit" in found:
        return "time_limit"
    if found == {"proof"}:
        return "proof"
    return "work"
