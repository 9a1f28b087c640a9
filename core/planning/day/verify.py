"""A route verified by the full simulation of its day: the timeline
(:mod:`core.planning.day.timeline`) simulated in one vectorised pass
(:func:`core.physics.simulate.simulate`), split per leg and per stop into a
:class:`core.planning.model.PlanResult`, and the rules it breaks, if any
(:func:`route_failure`): a window missed, back after the shift, the charge below the reserve.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from core.clock import at, check_representable
from core.params import Location, Place
from core.physics.battery import JOULES_PER_KWH
from core.physics.cycles import trace_distance_m
from core.physics.simulate import CONSUMERS, SimulationResult, simulate
from core.planning.day.box import cold_chain, deliveries, refrigeration, temperatures
from core.planning.day.scene import Scene, charge_points
from core.planning.day.start_state import box_start_c, product_start_c, start_payload_kg
from core.planning.day.timeline import (
    Timeline,
    build_timeline,
    later_departure_s,
    rest_after,
)
from core.planning.itinerary import Itinerary, Windows
from core.planning.model import (
    DEPOT_CHARGER_ID,
    PLAN_DT_S,
    BreakResult,
    ChargeResult,
    ColdChainResult,
    DayProfile,
    LegResult,
    PlanProblem,
    PlanResult,
    ReloadResult,
    Solved,
    StopResult,
    UnassignedReason,
    VisitKindName,
    VisitResult,
)
from core.routing.roads import LegRoute

#: Spacing of the day profile's points [s].
PROFILE_STEP_S = 60.0


#: The road of each leg of an order of places (place indices) from a router; None: traces.
Roads = Callable[[list[int]], list[LegRoute] | None]
#: When every point of a charger is taken by other vans, by the charger's place index.
Busy = Mapping[int, Sequence[tuple[dt.datetime, dt.datetime]]]


@dataclass(frozen=True)
class Drive:
    """One van's round as every simulation of it sees it.

    Parameters
    ----------
    problem
        The van, the stops and the conditions.
    scene
        The places, their legs, the zone and the weather.
    start
        Departure (zone-aware).
    roads
        The road of each leg of an order of places from a router, or None to generate the
        traces.
    solved
        How the order was found (reported as it is).
    windows_s
        Each place's time windows [s after ``start``]. The van waits at a stop for its window,
        and leaves the depot as much later as saves waiting without missing a window or
        ``latest_return_s``. Stops reached after their last window closes are served at once
        and listed in ``late_stops``.
    latest_return_s
        When the van must be back [s after ``start``], if ever.
    busy
        When other vans take every point of a charger (place index: spans), for the charges
        placed on the round (:mod:`core.planning.day.recharge`).
    """

    problem: PlanProblem
    scene: Scene
    start: dt.datetime
    roads: Roads
    solved: Solved
    windows_s: Sequence[Windows] | None = None
    latest_return_s: float | None = None
    busy: Busy = field(default_factory=dict)


def simulate_route(drive: Drive, itinerary: Itinerary) -> PlanResult:
    """Drive the ``itinerary`` (the places in driving order and the charges between them) as
    ``drive`` says, and simulate the day."""
    problem, scene, start = drive.problem, drive.scene, drive.start
    windows_s, latest_return_s = drive.windows_s, drive.latest_return_s
    roads = drive.roads(list(itinerary.order))

    def laid_out(departure: dt.datetime, windows: Sequence[Windows] | None) -> Timeline:
        places, legs, rest = scene.places, scene.legs, rest_after(problem, departure)
        return build_timeline(problem, places, legs, itinerary, roads, windows, rest)

    timeline = laid_out(start, windows_s)
    if windows_s is not None and problem.start_state is None:  # under way: it drives on now
        delay_s = later_departure_s(timeline, itinerary.order, windows_s, latest_return_s)
        if delay_s > 0:  # every span after the departure comes as much nearer
            start = at(start, delay_s)
            windows_s = [[(a - delay_s, b - delay_s) for a, b in place] for place in windows_s]
            itinerary = itinerary.shifted(delay_s)
            timeline = laid_out(start, windows_s)
    check_representable(start, timeline.duration_s, "date")
    problem.van.cargo_box.check_day(timeline.duration_s)
    weather, warnings = scene.weather_for(start, timeline.duration_s)
    warnings = [*warnings, *_long_day(problem, start, timeline)]
    result = simulate(
        timeline.speed,
        PLAN_DT_S,
        start,
        Location(lat=problem.depot.lat, lon=problem.depot.lon),
        problem.van,
        weather,
        timeline.along(box_start_c(problem), product_start_c(problem)),
    )
    timeline = timeline.driven(result.sample_at)
    return _Split(problem, scene, itinerary, result, timeline, start).result(drive.solved, warnings)


def _long_day(problem: PlanProblem, start: dt.datetime, timeline: Timeline) -> list[str]:
    """What the answer must say of a day that ends on a later date, or that the motor's
    power cap makes slower than the traffic."""
    warnings = []
    back = at(start, timeline.duration_s)
    if back.date() > start.date():
        days = (back.date() - start.date()).days
        warnings.append(
            f"the round ends on {back:%Y-%m-%d} at {back:%H:%M}, {days} day{'s' * (days > 1)} "
            "after it starts: its drives, services, waits, charges and breaks take that long"
        )
    if timeline.capped_s > 0:
        cap_kw = (problem.van.vehicle.max_motor_power_w or 0.0) / 1000
        warnings.append(
            f"the motor's {cap_kw:g} kW cap makes the van slower than the traffic: the drives "
            f"take {timeline.capped_s / 60:,.1f} min longer in all (the times include it)"
        )
    return warnings


class _Split:
    """One simulated day split per leg, per stop and per minute."""

    def __init__(
        self,
        problem: PlanProblem,
        scene: Scene,
        itinerary: Itinerary,
        result: SimulationResult,
        timeline: Timeline,
        start: dt.datetime,
    ) -> None:
        self.problem, self.scene, self.itinerary = problem, scene, itinerary
        self.order = itinerary.order
        self.simulated, self.timeline, self.start = result, timeline, start
        self.cumulative_j = {
            name: np.concatenate(([0.0], np.cumsum(power) * PLAN_DT_S))
            for name, power in result.power_w.items()
        }
        self.door_j = np.concatenate(([0.0], np.cumsum(result.box.door_heat_w) * PLAN_DT_S))

    def moment(self, sample: int) -> dt.datetime:
        return at(self.start, float(sample) * PLAN_DT_S)

    def span_kwh(self, a: int, b: int) -> dict[str, float]:
        """Energy per consumer and total between samples a and b [kWh]."""
        energy = {
            name: float(c[b] - c[a]) / JOULES_PER_KWH for name, c in self.cumulative_j.items()
        }
        energy["total"] = sum(energy.values())
        return energy

    def legs(self) -> list[LegResult]:
        places, legs, soc = self.scene.places, self.scene.legs, self.simulated.soc
        out = []
        for k, (i, j) in enumerate(itertools.pairwise(self.order)):
            a, b = int(self.timeline.depart[k]), int(self.timeline.arrive[k])
            out.append(
                LegResult(
                    from_id=places[i].id,
                    to_id=places[j].id,
                    depart=self.moment(a),
                    arrive=self.moment(b),
                    distance_m=trace_distance_m(self.simulated.speed_mps[a : b + 1], PLAN_DT_S),
                    duration_s=(b - a) * PLAN_DT_S,
                    street_type=self.timeline.street_types[k],
                    grade=float(legs.grade[i, j]),
                    energy_kwh=self.span_kwh(a, b),
                    soc_start=float(soc[a]),
                    soc_end=float(soc[b]),
                    geometry=self.timeline.geometry[k],
                )
            )
        return out

    def stops(self) -> list[StopResult]:
        places, soc, snap = self.scene.places, self.simulated.soc, self.scene.legs.snap_distance_m
        out = []
        payload = start_payload_kg(self.problem)
        reloads = set(self.timeline.reloaded_at)
        goods = deliveries(
            self.problem.van.cargo_box,
            self.simulated.box,
            [
                int(self.timeline.leave[k])
                for k in range(len(self.order) - 2)
                if self.itinerary.kind(k + 1, len(self.problem.stops)) == "stop"
            ],
        )
        handed = iter(goods or [])
        for k, j in enumerate(self.order[1:-1]):
            if k + 1 in reloads:
                payload = self.problem.van.payload_kg
            if self.itinerary.kind(k + 1, len(self.problem.stops)) != "stop":
                continue
            b, c = int(self.timeline.arrive[k]), int(self.timeline.leave[k])
            served = int(self.timeline.serve[k])
            payload = max(payload - self.problem.stops[j - 1].delivery_kg, 0.0)
            out.append(
                StopResult(
                    id=places[j].id,
                    arrival=self.moment(b),
                    service_start=self.moment(served),
                    wait_s=(served - b) * PLAN_DT_S,
                    departure=self.moment(c),
                    door_heat_kwh=float(self.door_j[c] - self.door_j[b]) / JOULES_PER_KWH,
                    payload_after_kg=payload,
                    energy_kwh=self.span_kwh(b, c),
                    soc_arrival=float(soc[b]),
                    soc_departure=float(soc[c]),
                    snap_distance_m=None if snap is None else float(snap[j]),
                    lat=places[j].lat,
                    lon=places[j].lon,
                    air_temperature_c=temperatures(self.simulated.box.temperature_c, b, c),
                    product_temperature_c=(
                        None
                        if self.simulated.box.product_c is None
                        else temperatures(self.simulated.box.product_c, b, c)
                    ),
                    goods=next(handed, None),
                )
            )
        return out

    def cold_chain(self) -> ColdChainResult | None:
        """The goods held to their band; the stop driven to or served when it first breaks."""
        stops = len(self.problem.stops)
        leaving = [
            (int(self.timeline.leave[k]), self.scene.places[j].id)
            for k, j in enumerate(self.order[1:-1])
            if self.itinerary.kind(k + 1, stops) == "stop"
        ]
        return cold_chain(self.problem.van.cargo_box, self.simulated.box, leaving)

    def charges(self) -> list[ChargeResult]:
        """The charges between stops, with what the simulation made of them."""
        points = charge_points(self.problem, self.scene.places)
        out = []
        for position, spell, done in zip(
            self.timeline.charged_at, self.timeline.charging, self.simulated.charges, strict=True
        ):
            j = self.order[position]
            b, c = int(self.timeline.arrive[position - 1]), int(self.timeline.leave[position - 1])
            grid_kwh = (done.charge_grid_j + done.consumers_grid_j) / JOULES_PER_KWH
            out.append(
                ChargeResult(
                    charger_id=DEPOT_CHARGER_ID if j == 0 else self.scene.places[j].id,
                    arrive=self.moment(b),
                    depart=self.moment(c),
                    soc_before=done.soc_before,
                    soc_after=done.soc_after,
                    grid_kwh=grid_kwh,
                    battery_kwh=done.stored_j / JOULES_PER_KWH,
                    minutes=spell.duration_s / 60,
                    cost=grid_kwh * points[j].price_per_kwh,
                    lat=self.scene.places[j].lat,
                    lon=self.scene.places[j].lon,
                )
            )
        return out

    def reloads(self) -> list[ReloadResult]:
        """The returns to the depot to reload."""
        return [
            ReloadResult(
                arrive=self.moment(int(self.timeline.arrive[q - 1])),
                depart=self.moment(int(self.timeline.leave[q - 1])),
                payload_kg=self.problem.van.payload_kg,
            )
            for q in self.timeline.reloaded_at
        ]

    def visits(self) -> list[VisitResult]:
        """The day's visits and breaks in time order."""
        soc, places, timeline = self.simulated.soc, self.scene.places, self.timeline
        driven = np.concatenate(([0], np.cumsum(timeline.arrive - timeline.depart)))
        out = []

        def visit(kind: VisitKindName, place: int, b: int, s: int, c: int, k: int) -> None:
            out.append(
                VisitResult(
                    kind=kind,
                    id=DEPOT_CHARGER_ID if kind == "charge" and place == 0 else places[place].id,
                    arrive=self.moment(b),
                    start=self.moment(s),
                    depart=self.moment(c),
                    soc_arrival=float(soc[b]),
                    soc_departure=float(soc[c]),
                    payload_after_kg=float(timeline.payload[c]),
                    energy_kwh=self.span_kwh(b, c),
                    driving_s=float(driven[k]) * PLAN_DT_S,
                )
            )

        for k, place in enumerate(self.order[1:-1]):
            kind = self.itinerary.kind(k + 1, len(self.problem.stops))
            if kind in ("stop", "charge", "reload"):
                b, c = int(timeline.arrive[k]), int(timeline.leave[k])
                visit(kind, place, b, int(timeline.serve[k]), c, k + 1)
        for rest in timeline.breaks:
            b, c = round(rest.start_s / PLAN_DT_S), round(rest.end_s / PLAN_DT_S)
            k = int(np.searchsorted(timeline.depart, c))  # the leg it comes before
            visit("break", self.order[min(k, len(self.order) - 1)], b, b, c, k)
        return sorted(out, key=lambda v: (v.arrive, v.depart))

    def result(self, solved: Solved, warnings: list[str]) -> PlanResult:
        simulated, places, legs = self.simulated, self.scene.places, self.scene.legs
        total = simulated.energy_kwh["total"]
        first_bad = simulated.battery.first_infeasible_index
        dynamic = self.problem.van.cargo_box.mode == "dynamic"
        snap = legs.snap_distance_m
        return PlanResult(
            tour=[places[i].id for i in self.order],
            legs=self.legs(),
            stops=self.stops(),
            distance_m=simulated.distance_m,
            duration_s=simulated.duration_s,
            energy_kwh=dict(simulated.energy_kwh),
            energy_share={
                name: (simulated.energy_kwh[name] / total if total > 0 else 0.0)
                for name in CONSUMERS
            },
            battery=simulated.battery,
            battery_loss_kwh=simulated.battery_loss_kwh,
            grid_kwh=simulated.grid_kwh,
            first_infeasible_leg=(
                None
                if first_bad is None
                else int(np.searchsorted(self.timeline.leave, first_bad, side="left"))
            ),
            max_box_temperature_c=simulated.box.max_temperature_c if dynamic else None,
            minutes_above_product_limit=simulated.box.minutes_above_limit if dynamic else None,
            product_limit_c=self.problem.van.cargo_box.product_limit_c,
            weather=simulated.weather,
            weather_days=simulated.weather_days,
            weather_source=simulated.weather_source,
            warnings=[*warnings, *simulated.warnings, *self.scene.notes],
            timezone=self.scene.timezone_name,
            distance_source=legs.source,
            depot_snap_distance_m=None if snap is None else float(snap[0]),
            solved=solved,
            objective=self.problem.objective,
            profile=_profile(self),
            late_stops=[places[j].id for j in self.timeline.late],
            itinerary=self.itinerary,
            charges=self.charges(),
            reloads=self.reloads(),
            visits=self.visits(),
            cold_chain=self.cold_chain(),
            refrigeration=refrigeration(self.problem.van, simulated, self.moment),
            breaks=[
                BreakResult(
                    start=self.moment(round(b.start_s)),
                    end=self.moment(round(b.end_s)),
                    kind=b.kind,
                )
                for b in self.timeline.breaks
            ],
        )


def _profile(split: _Split) -> DayProfile:
    """The day minute by minute: each consumer's energy since departure, the state of
    charge, the box's air and the goods, the unit's set-point."""
    size = split.simulated.time_s.size
    every = max(round(PROFILE_STEP_S / PLAN_DT_S), 1)
    picks = np.unique(np.append(np.arange(0, size, every), size - 1))
    kwh = {name: (c[picks] / JOULES_PER_KWH).tolist() for name, c in split.cumulative_j.items()}
    kwh["total"] = np.sum([kwh[name] for name in CONSUMERS], axis=0).tolist()
    simulated_box = split.simulated.box
    # the box's temperatures are at the end of each step: sample i ends step i - 1
    steps = np.maximum(picks - 1, 0)
    box: list[float] | None = None
    if split.problem.van.cargo_box.mode == "dynamic":
        box = simulated_box.temperature_c[steps].tolist()
    goods = simulated_box.product_c
    setpoint = simulated_box.setpoint_c
    return DayProfile(
        time=[split.moment(int(i)) for i in picks],
        energy_kwh=kwh,
        soc=split.simulated.soc[picks].tolist(),
        box_temperature_c=box,
        product_temperature_c=None
        if goods is None
        else [None if math.isnan(v) else v for v in goods[steps].tolist()],
        air_setpoint_c=None if setpoint is None else setpoint[steps].tolist(),
    )


@dataclass(frozen=True)
class Failure:
    """Why a simulated route does not hold: the rule and, for the stop-bound rules, the stop
    (its place index)."""

    reason: UnassignedReason
    node: int | None
    detail: str


def route_failure(
    van_id: str,
    problem: PlanProblem,
    places: list[Place],
    result: PlanResult,
    shift_end: dt.datetime | None,
    battery_enforced: bool,
) -> Failure | None:
    """The first rule the simulated route of van ``van_id`` breaks, if any: a stop reached
    after its last window closes, back after ``shift_end``, and — when the battery is a
    constraint (``battery_enforced``) — its charge below the reserve."""
    if result.late_stops:
        node = next(k for k, place in enumerate(places) if place.id == result.late_stops[0])
        return Failure("time_window", node, f"{van_id} would reach it after its last window closes")
    back = result.legs[-1].arrive
    if shift_end is not None and back > shift_end:
        return Failure(
            "shift",
            None,
            f"{van_id} would be back at {back:%H:%M}, after its shift ends at {shift_end:%H:%M}",
        )
    if battery_enforced and not result.battery.feasible:
        return Failure(
            "battery",
            None,
            f"the simulated day of {van_id} would take its battery to "
            f"{result.battery.min_soc:.0%}, below its reserve of "
            f"{problem.van.battery.min_soc:.0%}",
        )
    return None


def traced_seconds(order: list[int], result: PlanResult) -> list[tuple[tuple[int, int], float]]:
    """Each arc of ``order`` and how long the simulation drove it [s]."""
    return [
        ((i, j), leg.duration_s)
        for (i, j), leg in zip(itertools.pairwise(order), result.legs, strict=True)
    ]
