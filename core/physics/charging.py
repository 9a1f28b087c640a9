"""Charging at a plug: the power a battery takes as it fills, how long a charge takes, and how
far a charge of a given length gets.

The charging power ``P(s)`` [W, drawn from the charger] at state of charge ``s`` is the van's
charging curve (:class:`core.params.BatteryParams.charging_curve`; by default
``max_charge_power_kw`` to 80 %, then falling linearly to 20 % of it at full, the CC-CV shape
of lithium-ion cells) capped by the charger's power and the van's ``max_charge_power_kw``. The
battery stores ``η·P(s)`` (``charging_efficiency``), so with ``C`` the usable capacity [J]

    ds/dt = η·P(s) / C,   t(s₀ → s₁) = C/η · ∫ ds / P(s).

``P`` is piecewise linear in ``s``: on a piece from ``(s_a, P_a)`` to ``(s_b, P_b)`` the
integral is ``(s_b − s_a)/P_a`` when the power is flat and
``(s_b − s_a)/(P_b − P_a) · ln(P_b/P_a)`` when it tapers; both are inverted in closed form for
the state of charge after ``t`` seconds. The cab and the refrigeration unit run from the grid
while plugged in (as when pre-conditioning at the depot): they do not draw on the battery.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from core.arrays import FloatArray
from core.params import BatteryParams
from core.params.van import FULL_POWER_SHARE, TAPER_SOC
from core.physics.battery import JOULES_PER_KWH

WATTS_PER_KW = 1000.0


@dataclass(frozen=True)
class ChargeCurve:
    """The power a battery takes at a charger by state of charge: ``power_w[k]`` at
    ``soc[k]``, linear between, from 0 to 1, non-increasing and positive."""

    soc: FloatArray
    power_w: FloatArray
    capacity_j: float
    efficiency: float

    def power_at_w(self, soc: ArrayLike) -> FloatArray:
        """Charging power drawn from the charger at ``soc`` [W]."""
        return np.interp(np.asarray(soc, dtype=float), self.soc, self.power_w)

    def time_s(self, soc_from: float, soc_to: float) -> float:
        """Seconds to charge from ``soc_from`` to ``soc_to`` (0 when not above)."""
        if soc_to <= soc_from:
            return 0.0
        total = 0.0
        for a, b, p_a, p_b in self._pieces(soc_from, soc_to):
            total += _piece_time(b - a, p_a, p_b)
        return total * self.capacity_j / self.efficiency

    def soc_after(self, soc_from: float, seconds: ArrayLike) -> FloatArray:
        """The state of charge after charging ``seconds`` from ``soc_from`` (never above 1)."""
        elapsed = np.asarray(seconds, dtype=float)
        out = np.full(elapsed.shape, min(soc_from, 1.0))
        spent = 0.0
        for a, b, p_a, p_b in self._pieces(soc_from, 1.0):
            span_s = _piece_time(b - a, p_a, p_b) * self.capacity_j / self.efficiency
            inside = (elapsed > spent) & (elapsed <= spent + span_s)
            t = (elapsed[inside] - spent) * self.efficiency / self.capacity_j
            out[inside] = a + _piece_soc(t, b - a, p_a, p_b)
            spent += span_s
            out[elapsed > spent] = b
        return out

    def stored_j(self, soc_from: float, seconds: float) -> float:
        """Energy stored in ``seconds`` of charging from ``soc_from`` [J]."""
        after = float(self.soc_after(soc_from, np.array([seconds]))[0])
        return (after - soc_from) * self.capacity_j

    def _pieces(self, soc_from: float, soc_to: float) -> list[tuple[float, float, float, float]]:
        """The linear pieces of the curve between two states of charge: (a, b, P(a), P(b))."""
        inner = self.soc[(self.soc > soc_from) & (self.soc < soc_to)]
        edges = np.concatenate(([soc_from], inner, [soc_to]))
        power = self.power_at_w(edges)
        return [
            (float(edges[k]), float(edges[k + 1]), float(power[k]), float(power[k + 1]))
            for k in range(edges.size - 1)
        ]


def _piece_time(span: float, p_a: float, p_b: float) -> float:
    """∫ ds / P(s) over a linear piece of ``span`` from power ``p_a`` to ``p_b``."""
    if math.isclose(p_a, p_b, rel_tol=1e-12):
        return span / p_a
    return span / (p_b - p_a) * math.log(p_b / p_a)


def _piece_soc(tau: FloatArray, span: float, p_a: float, p_b: float) -> FloatArray:
    """How far into a linear piece the state of charge gets after ``tau = t·η/C`` [1/W]: the
    inverse of :func:`_piece_time` (``P_a·(e^{k·tau} − 1)/k`` with ``k`` the piece's slope)."""
    if math.isclose(p_a, p_b, rel_tol=1e-12):
        return np.minimum(tau * p_a, span)
    slope = (p_b - p_a) / span
    return np.minimum((p_a * np.exp(slope * tau) - p_a) / slope, span)


def charge_curve(
    battery: BatteryParams, charger_power_w: float, usable_share: float = 1.0
) -> ChargeCurve:
    """The van's charging curve at a charger of ``charger_power_w`` [W]: its own curve (or the
    default CC-CV shape) capped by the charger and by ``max_charge_power_kw``; ``usable_share``
    scales the capacity as on the day (temperature derating)."""
    top_w = battery.max_charge_power_kw * WATTS_PER_KW
    if battery.charging_curve is None:
        soc = np.array([0.0, TAPER_SOC, 1.0])
        power = np.array([top_w, top_w, FULL_POWER_SHARE * top_w])
    else:
        soc = np.array([p.soc for p in battery.charging_curve])
        power = np.array([p.power_kw * WATTS_PER_KW for p in battery.charging_curve])
        soc, power = (
            np.concatenate(([0.0], soc, [1.0])),
            np.concatenate(([power[0]], power, [power[-1]])),
        )
    cap_w = min(charger_power_w, top_w)
    # Where the capped curve bends: the curve's own points and where it crosses the cap.
    crossings = [
        soc[k] + (cap_w - power[k]) * (soc[k + 1] - soc[k]) / (power[k + 1] - power[k])
        for k in range(soc.size - 1)
        if (power[k] - cap_w) * (power[k + 1] - cap_w) < 0
    ]
    points = np.unique(np.concatenate((soc, crossings)))
    return ChargeCurve(
        soc=points,
        power_w=np.minimum(np.interp(points, soc, power), cap_w),
        capacity_j=battery.usable_capacity_kwh * usable_share * JOULES_PER_KWH,
        efficiency=battery.charging_efficiency,
    )
