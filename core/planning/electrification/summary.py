"""The simulated days summed up: per route and candidate, the days covered, the battery that
covers 95 % and all of them, the worst days and what made them worst; per candidate, the fleet
(how many routes go electric, what the depot must recharge)."""

from __future__ import annotations

import datetime as dt
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.physics.battery import BatteryVerdict
from core.planning.electrification.model import (
    CandidateOutcome,
    ChargeOption,
    DaySummary,
    FleetOutcome,
    Reason,
    RouteOutcome,
    WorstDay,
)

#: Worst days listed per route and candidate.
WORST_DAYS = 5
#: Share of the days the battery of ``required_kwh_p95`` covers.
COVERED_SHARE = 0.95
#: Consumers whose energy changes with the weather (the battery's loss in the cold or heat too).
THERMAL = ("cabin", "refrigeration", "battery_loss")
#: Least time a van is parked at the depot between two days, for its recharge's power [h].
MIN_PARKED_H = 1.0


@dataclass(frozen=True)
class DayOutcome:
    """One route-day of one candidate: energy per consumer (``battery_loss``, ``total``)
    [kWh], the battery's verdict, the cold chain's, the day's coldest and warmest moments
    [°C], its distance [m] and duration [s], and whether the chargers' charges cover it."""

    date: dt.date
    energy_kwh: dict[str, float]
    battery: BatteryVerdict
    cold_chain_holds: bool
    t_min_c: float
    t_max_c: float
    distance_m: float
    duration_s: float
    covered_with_charging: bool


def route_outcome(
    route_id: str,
    year: dict[str, list[DayOutcome]],
    chargers: Sequence[ChargeOption],
    include_days: bool = False,
) -> RouteOutcome:
    """One route: each candidate's ``year`` of days (by candidate id) summed up, with every
    day's figures when ``include_days``."""
    first = next(iter(year.values()))[0]
    return RouteOutcome(
        id=route_id,
        distance_km=first.distance_m / 1000.0,
        candidates=[
            candidate_outcome(cid, days, chargers).model_copy(
                update={"days": [summary(d) for d in days] if include_days else None}
            )
            for cid, days in year.items()
        ],
    )


def summary(day: DayOutcome) -> DaySummary:
    """One day's figures as the answer lists them."""
    return DaySummary(
        date=day.date,
        min_soc=day.battery.min_soc,
        margin_kwh=day.battery.margin_kwh,
        required_kwh=day.battery.required_capacity_kwh,
        energy_kwh=day.energy_kwh["total"],
        covered_with_charging=day.covered_with_charging,
        cold_chain_holds=day.cold_chain_holds,
    )


def candidate_outcome(
    candidate_id: str, days: Sequence[DayOutcome], chargers: Sequence[ChargeOption]
) -> CandidateOutcome:
    """One candidate's days on one route summed up."""
    required = np.array([d.battery.required_capacity_kwh for d in days])
    feasible = sum(d.battery.feasible for d in days)
    topped = None if not chargers else sum(d.covered_with_charging for d in days)
    return CandidateOutcome(
        id=candidate_id,
        days_total=len(days),
        days_feasible=feasible,
        share_feasible=feasible / len(days),
        days_feasible_with_charging=topped,
        share_feasible_with_charging=None if topped is None else topped / len(days),
        # the smallest capacity that at least this share of the days needs no more than
        required_kwh_p95=float(np.quantile(required, COVERED_SHARE, method="inverted_cdf")),
        required_kwh_max=float(required.max()),
        lacking_kwh_max=max(max(-d.battery.margin_kwh, 0.0) for d in days),
        energy_kwh_mean={
            k: float(np.mean([d.energy_kwh[k] for d in days])) for k in days[0].energy_kwh
        },
        cold_chain_days_broken=sum(not d.cold_chain_holds for d in days),
        worst_days=worst_days(days),
    )


def _tenths(value: float) -> float:
    """``value`` to a tenth, never −0.0."""
    return round(value, 1) + 0.0


def _whole(value: float) -> str:
    """``value`` to the unit, never "-0"."""
    return f"{round(value) + 0:d}"


def _thermal_kwh(day: DayOutcome) -> float:
    return sum(day.energy_kwh[name] for name in THERMAL)


def _mean_c(day: DayOutcome) -> float:
    return (day.t_min_c + day.t_max_c) / 2.0


def worst_days(days: Sequence[DayOutcome]) -> list[WorstDay]:
    """The :data:`WORST_DAYS` days the battery ran lowest, lowest first, each with its reason,
    against the route's median day: distance when even the route's best day falls below the
    reserve, or when the day's drives (traction) exceed the median day's by more than its
    weather-driven energy (cab, refrigeration, the battery's temperature loss) does; else heat
    or cold, as the day is warmer or colder than the median day."""
    best = max(days, key=lambda d: d.battery.min_soc)
    median_kwh = float(np.median([_thermal_kwh(d) for d in days]))
    median_traction_kwh = float(np.median([d.energy_kwh["traction"] for d in days]))
    median_c = float(np.median([_mean_c(d) for d in days]))
    out = []
    for day in sorted(days, key=lambda d: (d.battery.min_soc, d.date))[:WORST_DAYS]:
        energy = day.energy_kwh
        driven_kwh = energy["traction"] - median_traction_kwh
        weather_kwh = _thermal_kwh(day) - median_kwh
        reason: Reason = (
            "distance"
            if not best.battery.feasible or driven_kwh > max(weather_kwh, 0)
            else ("heat" if _mean_c(day) >= median_c else "cold")
        )
        detail = (
            f"{day.distance_m / 1000:.0f} km ({_tenths(driven_kwh):+.1f} kWh of traction over the "
            f"route's median day), {_whole(day.t_min_c)} to {_whole(day.t_max_c)} °C: cab "
            f"{energy['cabin']:.1f} kWh, "
            f"refrigeration {energy['refrigeration']:.1f} kWh, battery loss "
            f"{energy['battery_loss']:.1f} kWh ({_tenths(weather_kwh):+.1f} kWh over "
            f"the route's median day); {energy['total']:.1f} kWh in all, lowest charge "
            f"{day.battery.min_soc:.0%}"
        )
        out.append(
            WorstDay(
                date=day.date,
                reason=reason,
                min_soc=day.battery.min_soc,
                required_kwh=day.battery.required_capacity_kwh,
                t_min_c=day.t_min_c,
                t_max_c=day.t_max_c,
                detail=detail,
            )
        )
    return out


ByDate = dict[str, dict[dt.date, float]]


@dataclass(frozen=True)
class DepotRecharge:
    """What the depot recharges on each date [kWh], and at what power [kW], by candidate:
    each van back to full from the grid (:attr:`BatteryVerdict.recharge_kwh`), evenly while
    parked until the same time the next day, on the days it covers on one charge (it drives
    no other electric). Parts of a study add up (:meth:`plus`)."""

    kwh: ByDate
    kw: ByDate

    @classmethod
    def of(cls, year: dict[str, list[DayOutcome]]) -> DepotRecharge:
        """The depot's recharge of one route's ``year`` (by candidate id)."""
        kwh: ByDate = {}
        kw: ByDate = {}
        for candidate_id, days in year.items():
            kwh[candidate_id], kw[candidate_id] = {}, {}
            for day in days:
                if not day.battery.feasible:
                    continue
                parked_h = max((86_400.0 - day.duration_s) / 3600.0, MIN_PARKED_H)
                kwh[candidate_id][day.date] = day.battery.recharge_kwh
                kw[candidate_id][day.date] = day.battery.recharge_kwh / parked_h
        return cls(kwh, kw)

    def plus(self, other: DepotRecharge) -> DepotRecharge:
        def added(a: ByDate, b: ByDate) -> ByDate:
            out = {k: dict(v) for k, v in a.items()}
            for candidate_id, dates in b.items():
                mine = out.setdefault(candidate_id, {})
                for date, value in dates.items():
                    mine[date] = mine.get(date, 0.0) + value
            return out

        return DepotRecharge(added(self.kwh, other.kwh), added(self.kw, other.kw))


def fleet_outcome(
    candidate_id: str,
    routes: Sequence[RouteOutcome],
    depot: DepotRecharge,
    chargers: Sequence[ChargeOption],
) -> FleetOutcome:
    """One candidate across the fleet: ``routes`` summed up, and the ``depot``'s recharge."""
    mine = [next(c for c in r.candidates if c.id == candidate_id) for r in routes]
    return FleetOutcome(
        id=candidate_id,
        routes_all_year=sum(c.days_feasible == c.days_total for c in mine),
        routes_p95=sum(c.share_feasible >= COVERED_SHARE for c in mine),
        routes_all_year_with_charging=None
        if not chargers
        else sum(c.days_feasible_with_charging == c.days_total for c in mine),
        depot_kwh_max_day=max(depot.kwh.get(candidate_id, {}).values(), default=0.0),
        depot_kw_peak=max(depot.kw.get(candidate_id, {}).values(), default=0.0),
    )
