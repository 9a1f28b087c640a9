"""PyVRP's iterated local search (Wouda, Lan & Kool 2024, :func:`pyvrp.solve`) counted in
work: its iterations *and* the moves its local search evaluates, so that a search's reference
seconds (:mod:`core.routing.effort`) follow what it does, not only how often it loops.

Iterations alone are a poor measure of PyVRP's work: an iteration of a clustered day with long
routes evaluates several times the moves of one with tight windows (per 1,000 clients,
C1_10_1's iterations ran 2.2 times as fast as R1_10_1's). Counted as iterations and moves,
the rate holds within about a fifth across Solomon's and Gehring–Homberger's classes
(:data:`core.routing.effort.PYVRP_ITERATION_S`, :data:`core.routing.effort.PYVRP_MOVE_S`).
"""

from __future__ import annotations

import numpy as np
import pyvrp
from pyvrp.search import LocalSearch, compute_neighbours

from core.routing.effort import Effort, SearchEnd

#: PyVRP's cost of a solution that breaks a constraint.
INFEASIBLE = 2**63 - 1


def above_routes(cost: np.ndarray, routes: int) -> int:
    """A cost above any routes' on ``cost`` (row and column 0 the depot; every place left
    once, the depot once a route, at most ``routes`` routes): a vehicle's fixed cost that puts
    fewer vehicles first. The least such bound, not a sum of all arcs: PyVRP evaluated moves
    2.5–3 times as slowly with that (E-VRPTW's rc104 as the fleet plan sends it, 10⁴ times the
    longest arc: 82 ns a move against 32)."""
    largest = cost.max(axis=1)
    return int(largest.sum() + largest[0] * routes) + 1


class _Counted(LocalSearch):
    """PyVRP's local search, counting the moves it evaluates over all its calls."""

    moves = 0

    def __call__(
        self,
        solution: pyvrp.Solution,
        cost_evaluator: pyvrp.CostEvaluator,
        exhaustive: bool = False,
    ) -> pyvrp.Solution:
        found = super().__call__(solution, cost_evaluator, exhaustive)
        self.moves += self.statistics.num_moves
        return found


class Stop:
    """PyVRP's stopping criterion: its work done (:meth:`Effort.pyvrp_spent_s` of its
    iterations and moves), or the deadline (a :class:`~core.routing.effort.Watch` on the
    iterations) — and which of them stopped it. With ``give_up`` (a share of the work and an
    effort whose deadline comes earlier), it also stops when either is reached and no
    solution keeps every constraint yet; ``gave_up``: it stopped without one, but for the
    deadline."""

    def __init__(
        self,
        effort: Effort,
        search: _Counted,
        clients: int,
        optional: bool,
        give_up: tuple[float, Effort] | None = None,
    ) -> None:
        self.effort, self.search, self.clients, self.optional = effort, search, clients, optional
        self.watch = effort.watch()
        self.give_up = None if give_up is None else (give_up[0], give_up[1].watch())
        self.done = 0
        self.ended: SearchEnd = "work"
        self.gave_up = False

    def spent_s(self) -> float:
        """The reference seconds its iterations and moves so far stand for."""
        return self.effort.pyvrp_spent_s(self.done, self.search.moves, self.clients, self.optional)

    def left_share(self) -> float:
        """The share of its work not yet spent."""
        if self.effort.work_s <= 0:
            return 0.0
        return max(1.0 - self.spent_s() / self.effort.work_s, 0.0)

    def __call__(self, best_cost: float) -> bool:
        self.done += 1
        if self.watch.passed(self.done):
            self.ended = "time_limit"
            return True
        spent_s = self.spent_s()
        if self.give_up is not None and best_cost >= INFEASIBLE:
            share, moment = self.give_up
            self.gave_up = spent_s >= self.effort.work_s * share or moment.passed(self.done)
            return self.gave_up
        return spent_s >= self.effort.work_s


def solve(
    data: pyvrp.ProblemData,
    effort: Effort,
    optional: bool = False,
    initial: pyvrp.Solution | None = None,
    give_up: tuple[float, Effort] | None = None,
) -> tuple[pyvrp.Result, Stop]:
    """:func:`pyvrp.solve` with its defaults, seeded by ``effort``, for ``effort``'s work
    (its stops ``optional`` or required: the rates differ) under its deadline; from
    ``initial`` when given (else a random solution, improved)."""
    params = pyvrp.SolveParams()
    rng = pyvrp.RandomNumberGenerator(seed=effort.seed)
    search = _Counted(
        data,
        rng,
        compute_neighbours(data, params.neighbourhood),
        pyvrp.search.PerturbationManager(params.perturbation),
    )
    for operator in params.operators:
        if operator.supports(data):
            search.add_operator(operator(data))
    penalties = pyvrp.PenaltyManager(params.penalty.midpoint_penalties(data), params.penalty)
    if initial is None:
        random = pyvrp.Solution.make_random(data, rng)
        initial = search(random, penalties.max_cost_evaluator(), exhaustive=True)
    stop = Stop(effort, search, data.num_clients, optional, give_up)
    result = pyvrp.IteratedLocalSearch(data, penalties, search, initial, params.ils).run(
        stop, collect_stats=False, display=False
    )
    return result, stop
