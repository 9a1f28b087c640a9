"""How much a search may do: an amount of *work*, the same on any machine and under any load,
and a deadline that only caps it.

The same request gives the same answer only when its searches stop on work, not on the clock.
The work is counted in *reference seconds*: what the solvers do in one second of one idle core
of the project's reference machine (2 cores, x86-64), converted into each solver's own
deterministic unit by the rates below — kicks of the round trip's local search, iterations of
PyVRP, CP-SAT's deterministic time. A search that reaches the deadline first stops there and
says so (``time_limit``): its answer may then differ on a retry.

Rates, measured on the reference machine (uniform and clustered instances):

- the round trip's local search (:mod:`core.routing.ils`): kicks per second by the number of
  places, interpolated log-log in :data:`KICKS_PER_S`;
- PyVRP's iterated local search: ``3400 · (25 / clients)^0.6`` iterations per second with
  every stop required (25 clients: 3,400; 100: 1,480; 1,000: 372), ``1800 · (25 /
  clients)^0.6`` with every stop optional (25: 1,800; 100: 690; 1,000: 206), the marginal
  rates over random VRPTW instances with tight and wide windows (the lower);
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
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

#: How a search ended: its work done, its optimum proven, or cut short by the deadline.
SearchEnd = Literal["work", "proof", "time_limit"]

#: Kicks per reference second of the round trip's local search, by places.
KICKS_PER_S = ((20, 14_000), (40, 9_700), (80, 8_900), (150, 6_400), (300, 3_800),
               (600, 2_500), (1_000, 1_800))  # fmt: skip
#: PyVRP's iterations per reference second: ``PYVRP_RATE · (PYVRP_SIZE / clients)^PYVRP_EXPONENT``
#: with every stop required, ``PYVRP_OPTIONAL_RATE · …`` with every stop optional.
PYVRP_RATE = 3_400.0
PYVRP_OPTIONAL_RATE = 1_800.0
PYVRP_SIZE = 25.0
PYVRP_EXPONENT = 0.6
#: OR-Tools' routing solutions per reference second:
#: ``ORTOOLS_RATE · (ORTOOLS_SIZE / places)^ORTOOLS_EXPONENT``.
ORTOOLS_RATE = 500.0
ORTOOLS_SIZE = 20.0
ORTOOLS_EXPONENT = 1.4
#: CP-SAT's deterministic time per reference second.
CPSAT_DETERMINISTIC_PER_S = 0.3


@dataclass(frozen=True)
class Effort:
    """A search's work [reference s], the deadline that caps it (a ``time.perf_counter``
    value) and its seed."""

    work_s: float
    deadline: float
    seed: int = 0

    @classmethod
    def starting_now(cls, work_s: float, time_limit_s: float, seed: int = 0) -> Effort:
        """``work_s`` of work, capped ``time_limit_s`` from now."""
        return cls(work_s, time.perf_counter() + time_limit_s, seed)

    def share(self, fraction: float) -> Effort:
        """A part of the work, under the same deadline."""
        return replace(self, work_s=self.work_s * fraction)

    def keeping(self, reserve_s: float) -> Effort:
        """The same work with ``reserve_s`` [s] kept before the deadline for what follows."""
        return replace(self, deadline=self.deadline - reserve_s)

    def left_s(self) -> float:
        """Time to the deadline [s]."""
        return self.deadline - time.perf_counter()

    def out_of_time(self) -> bool:
        return time.perf_counter() >= self.deadline

    def kicks(self, places: int) -> int:
        """The round trip's local search: kicks in this work."""
        table = np.log(np.asarray(KICKS_PER_S, dtype=float))
        rate = float(np.exp(np.interp(math.log(max(places, 2)), table[:, 0], table[:, 1])))
        return max(int(self.work_s * rate), 0)

    def pyvrp_iterations(self, clients: int, optional: bool = False) -> int:
        """PyVRP's iterations in this work, its stops required or ``optional``."""
        rate = (PYVRP_OPTIONAL_RATE if optional else PYVRP_RATE) * (
            PYVRP_SIZE / max(clients, 1)
        ) ** PYVRP_EXPONENT
        return max(int(self.work_s * rate), 1)

    def ortools_solutions(self, places: int) -> int:
        """OR-Tools' routing solutions in this work."""
        rate = ORTOOLS_RATE * (ORTOOLS_SIZE / max(places, 1)) ** ORTOOLS_EXPONENT
        return max(int(self.work_s * rate), 1)

    def cpsat_deterministic_time(self) -> float:
        """CP-SAT's deterministic time in this work."""
        return self.work_s * CPSAT_DETERMINISTIC_PER_S


def combined(ends: Iterable[SearchEnd]) -> SearchEnd:
    """How a search of several parts ended: cut short if any part was, proven if every part
    was, its work done otherwise (nothing run: its work done)."""
    found = set(ends)
    if "time_limit" in found:
        return "time_limit"
    if found == {"proof"}:
        return "proof"
    return "work"
