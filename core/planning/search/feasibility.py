"""What the solver's current estimates say a van can do: the rules a route breaks
(:meth:`Feasibility.violations`) and why a stop cannot be served even on a round of its own
(:meth:`Feasibility.alone`)."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from core.clock import at
from core.physics.battery import JOULES_PER_KWH
from core.planning.day.timeline import next_window
from core.planning.day.verify import Failure
from core.planning.model import UnassignedReason
from core.planning.search.day import FleetDay


@dataclass(frozen=True)
class Feasibility:
    """The rules as the estimates see them now: the driving times learned so far and each
    van's energy budget [J] (``None`` where the battery is only reported)."""

    day: FleetDay
    travel_s: NDArray[np.int64]
    budgets_j: Sequence[float | None]

    def violations(self, v: int, route: Sequence[int]) -> list[UnassignedReason]:
        """The rules van ``v`` breaks on ``route`` (stops, a 0 between them a return to
        reload; the depot around it)."""
        day = self.day
        problem = day.shifts[v].problem
        broken: list[UnassignedReason] = []
        if not day.carries(v, route):
            broken.append("capacity")
        budget = self.budgets_j[v]
        if budget is not None and day.estimates[v].route_energy_j(route) > budget:
            broken.append("battery")
        clock, end = day.shift_s[v]
        for k, (i, j) in enumerate(itertools.pairwise(day.order(v, route))):
            clock += day.service_s[i] + self.travel_s[i, j]
            if j == 0 and k == len(route):
                break
            if j == 0:  # back to reload
                clock += problem.reload_minutes * 60
                continue
            window = next_window(clock, day.windows_s[j])
            if window is None:
                broken.append("time_window")
                return broken
            clock = max(clock, window[0])
        if clock > end:
            broken.append("shift")
        return broken

    def alone(self, v: int, node: int) -> Failure | None:
        """Why van ``v`` (one that may serve it) could not serve the stop at ``node`` even on a
        round of its own, if it could not."""
        day = self.day
        stop = day.shifts[v].problem.stops[node - 1]
        vans = day.vans_for(node)
        payloads = [day.shifts[u].problem.van.payload_kg for u in vans]
        if stop.delivery_kg > day.shifts[v].problem.van.payload_kg:
            return Failure(
                "capacity",
                node,
                f"it takes {stop.delivery_kg:g} kg; no van that may serve it carries that much "
                f"(largest payload {max(payloads):g} kg)",
            )
        end_s = day.shift_s[v][1]
        window = next_window(self._reach_s(v, node), day.windows_s[node])
        if window is None:
            latest = at(day.reference, day.windows_s[node][-1][1])
            return Failure(
                "time_window",
                node,
                f"the earliest any van gets there is {day.clock(self.earliest(node))}, "
                f"after its last window closes at {latest:%H:%M}",
            )
        if self._back_s(v, node) > end_s:
            return Failure(
                "shift",
                node,
                "even on a round of its own no van would be back before its shift ends "
                f"(earliest return {day.clock(self.earliest_back(node))})",
            )
        budget = self.budgets_j[v]
        need_j = day.estimates[v].route_energy_j([node])
        if budget is not None and need_j > budget:
            most_j = max(b for u in vans if (b := self.budgets_j[u]) is not None)
            return Failure(
                "battery",
                node,
                f"a round to it alone needs about {need_j / JOULES_PER_KWH:.1f} kWh; the "
                f"most any van has above its reserve is about {most_j / JOULES_PER_KWH:.1f} "
                "kWh",
            )
        return None

    def _reach_s(self, v: int, node: int) -> float:
        """When van ``v`` reaches ``node`` on a round to it alone [s]."""
        return self.day.shift_s[v][0] + self.travel_s[self.day.starts[v], node]

    def _back_s(self, v: int, node: int) -> float:
        """Van ``v``'s return to the depot from a round to ``node`` alone [s]; infinite when
        its windows have all closed."""
        come_s = self._reach_s(v, node)
        window = next_window(come_s, self.day.windows_s[node])
        if window is None:
            return math.inf
        serve = max(come_s, window[0])
        return serve + self.day.service_s[node] + self.travel_s[node, 0]

    def earliest(self, node: int) -> float:
        """The earliest any van that may serve ``node`` reaches it [s]."""
        return min(self._reach_s(v, node) for v in self.day.vans_for(node))

    def earliest_back(self, node: int) -> float:
        """The earliest any van that may serve ``node`` is back from a round to it alone [s]."""
        return min(self._back_s(v, node) for v in self.day.vans_for(node))
