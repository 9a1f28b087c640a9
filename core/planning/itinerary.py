"""A van's planned day as every planning stage hands it on (:class:`Itinerary`): the places
in driving order and what the van does at each — serve a stop, charge, reload at the depot,
or both — before the timeline (:mod:`core.planning.day.timeline`) gives it its moments and
the simulation (:mod:`core.planning.day.verify`) its energies.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Literal

#: A place's time windows: ``(opens, closes)`` in seconds after a reference, sorted.
Windows = Sequence[tuple[float, float]]

#: What the van does at a position of its itinerary: set out or come back (``end``: the first
#: and the last), serve a stop, charge (at a charger, or at the depot between stops), come back
#: to the depot between stops to reload, or pass a charger without charging.
VisitKind = Literal["end", "stop", "charge", "reload", "pass"]


@dataclass(frozen=True)
class ChargeVisit:
    """A stop at a charger between stops (the depot's or one on the way): the minutes to plug
    in and out and the charge itself [s], at a point of ``power_kw``, open during ``open_s``
    (seconds after the departure; empty: always). The van waits for the opening; the charge
    ends at the closing at the latest. ``reloads``: at the depot, where the van comes back to
    reload as well (it stands the longer of the two)."""

    plug_s: float
    charge_s: float
    power_kw: float
    open_s: Windows = ()
    reloads: bool = False
    price_per_kwh: float = 0.0


@dataclass(frozen=True)
class Itinerary:
    """The places a van visits, in driving order, and its charges.

    Attributes
    ----------
    order
        Place indices (0 the depot; stops 1..n; the chargers after them): the start first (the
        depot, or the van's position when it is under way), the depot last. The depot between
        them is a return to reload, or a charge there.
    charges
        The charges, by position in ``order``; one at the depot with ``reloads`` is a return
        to reload as well.
    """

    order: tuple[int, ...]
    charges: Mapping[int, ChargeVisit] = field(default_factory=dict)

    @classmethod
    def of(
        cls, order: Sequence[int], charges: Mapping[int, ChargeVisit] | None = None
    ) -> Itinerary:
        """The itinerary of ``order`` with ``charges`` (none by default)."""
        return cls(tuple(order), dict(charges or {}))

    def kind(self, position: int, stops: int) -> VisitKind:
        """What the van does at ``position``, with places 1..``stops`` the stops."""
        place = self.order[position]
        if position in (0, len(self.order) - 1):
            return "end"
        if 0 < place <= stops:
            return "stop"
        if position in self.charges:
            return "charge"
        return "reload" if place == 0 else "pass"

    def reloads_at(self, position: int) -> bool:
        """Whether the van comes back to the depot at ``position`` to reload (and may charge
        meanwhile)."""
        if position in (0, len(self.order) - 1) or self.order[position] != 0:
            return False
        visit = self.charges.get(position)
        return visit is None or visit.reloads

    def stretch_ends(self) -> list[int]:
        """Where the stretches begin and end: the start, each charge, the end."""
        return [0, *sorted(self.charges), len(self.order) - 1]

    def served(self) -> list[int]:
        """The places between the ends that are not charges alone: the stops, and the depot
        for each return to reload."""
        return [
            place
            for q, place in enumerate(self.order)
            if 0 < q < len(self.order) - 1 and (q not in self.charges or self.reloads_at(q))
        ]

    def keeping(self, places: Collection[int]) -> Itinerary:
        """Only the stops in ``places`` (a return to reload too when the depot is among
        them), the ends and the charges kept where they are."""
        ends = (0, len(self.order) - 1)
        positions = [
            q
            for q in range(len(self.order))
            if q in self.charges or q in ends or self.order[q] in places
        ]
        return self._at(positions)

    def with_charge(self, after: int, place: int, visit: ChargeVisit) -> Itinerary:
        """A charge at ``place`` inserted after position ``after``."""
        order = [*self.order[: after + 1], place, *self.order[after + 1 :]]
        charges = {q + (q > after): c for q, c in self.charges.items()} | {after + 1: visit}
        return Itinerary.of(order, charges)

    def charged_at(self, position: int, visit: ChargeVisit) -> Itinerary:
        """A charge at ``position`` (the depot, where the van reloads), or the one there
        changed."""
        return Itinerary.of(self.order, {**self.charges, position: visit})

    def refitted(self, charges: Mapping[int, ChargeVisit]) -> Itinerary:
        """The same places with ``charges`` instead; a charge with nothing left to charge
        goes, with its detour (a return to reload stays, without its charge)."""
        idle = {q for q, visit in charges.items() if visit.charge_s <= 0}
        gone = {q for q in idle if not charges[q].reloads}
        kept = [q for q in range(len(self.order)) if q not in gone]
        return replace(self, charges={q: c for q, c in charges.items() if q not in idle})._at(kept)

    def reloading_while_charging(self, reloads: Collection[int]) -> Itinerary:
        """A return to reload at a position in ``reloads`` beside a charge at the depot made
        one stop: the charge, the van reloaded meanwhile."""
        charges = dict(self.charges)
        dropped = set()
        for q in reloads:
            beside = next((p for p in (q - 1, q + 1) if p in charges and self.order[p] == 0), None)
            if beside is not None:
                charges[beside] = replace(charges[beside], reloads=True)
                dropped.add(q)
        kept = [q for q in range(len(self.order)) if q not in dropped]
        return replace(self, charges=charges)._at(kept)

    def shifted(self, delay_s: float) -> Itinerary:
        """The charges' opening hours as seen from a departure ``delay_s`` later [s]."""
        if not delay_s or not self.charges:
            return self
        return replace(
            self,
            charges={
                q: replace(c, open_s=[(a - delay_s, b - delay_s) for a, b in c.open_s])
                for q, c in self.charges.items()
            },
        )

    def _at(self, positions: Sequence[int]) -> Itinerary:
        """The visits at ``positions`` (ascending), the charges renumbered."""
        charges = {n: self.charges[q] for n, q in enumerate(positions) if q in self.charges}
        return Itinerary(tuple(self.order[q] for q in positions), charges)
