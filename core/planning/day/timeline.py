"""One van's day sample by sample (paper §4, Fig. 7): from the order of its stops, depart,
drive each leg (the router's road speed profile, or a generated trace lasting the leg's
duration), arrive, wait for the stop's time window, park, open the door within the service
time, unload (the payload and so the mass drop), go on, return.

Time windows are in seconds after the day's departure; :func:`next_window` is the one rule for
when a van that arrives may start its service.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from core.arrays import FloatArray
from core.params import (
    STREET_TYPES,
    ChargingSpell,
    DoorOpening,
    Interval,
    Place,
    Stop,
    StreetTypeName,
)
from core.physics.cycles import (
    drive_profile,
    fastest_s,
    generate_leg,
    rest_to_rest,
    stretch_to_duration,
    trace_distance_m,
)
from core.physics.motor import power_limited
from core.physics.simulate import MAX_SPEED_MPS, Along
from core.planning.day.start_state import start_payload_kg
from core.planning.itinerary import ChargeVisit, Itinerary, Windows
from core.planning.model import PLAN_DT_S, PlanProblem
from core.routing.geo import STREET_TYPE_NAMES, Legs, street_type_by_speed
from core.routing.roads import LegRoute, bearing_deg


def next_window(arrival_s: float, windows_s: Windows) -> tuple[float, float] | None:
    """The window a van arriving at ``arrival_s`` is served in: the first that has not closed
    (it may open later: the van waits), ``(−inf, inf)`` for a place without windows, None when
    every window has closed."""
    if not windows_s:
        return (-math.inf, math.inf)
    return next(((a, b) for a, b in windows_s if arrival_s <= b), None)


def charge_window(
    arrival_s: float, windows_s: Windows, needed_s: float
) -> tuple[float, float] | None:
    """The window a van arriving at a charger at ``arrival_s`` charges in: the first with room
    for the ``needed_s`` it stands there (it waits for it: a point another van takes before
    the charge is done is no place to start it), else the first that has not closed (the
    charge cut short at its close); :func:`next_window`'s rule otherwise."""
    roomy = (w for w in windows_s if w[1] - max(w[0], arrival_s) >= needed_s)
    return next(roomy, None) or next_window(arrival_s, windows_s)


def seconds_after(date: dt.date, clock: dt.time, reference: dt.datetime) -> float:
    """The local ``clock`` time on ``date`` in ``reference``'s zone, in seconds after
    ``reference`` (elapsed time: daylight saving counted)."""
    moment = dt.datetime.combine(date, clock, tzinfo=reference.tzinfo)
    return moment.timestamp() - reference.timestamp()


def windows_after(
    stops: Sequence[Stop], date: dt.date, reference: dt.datetime
) -> list[list[tuple[float, float]]]:
    """Each place's time windows (depot first, none) in seconds after ``reference``
    (:func:`seconds_after`)."""
    return [[]] + [
        [
            (seconds_after(date, w.start, reference), seconds_after(date, w.end, reference))
            for w in stop.time_windows
        ]
        for stop in stops
    ]


def rest_after(problem: PlanProblem, reference: dt.datetime) -> Rest:
    """The round's breaks, fixed ones in seconds after ``reference``."""
    state = problem.start_state
    driven_s = 0.0 if state is None else state.driving_since_break_s
    if not isinstance(problem.breaks, list):
        return Rest(eu_561=problem.breaks == "eu-561", driven_s=driven_s)
    return Rest(
        fixed=tuple(
            (
                seconds_after(problem.date, b.earliest, reference),
                seconds_after(problem.date, b.latest, reference),
                b.minutes * 60.0,
            )
            for b in problem.breaks
        ),
        driven_s=driven_s,
    )


#: Regulation (EC) No 561/2006, art. 7: after at most 4 h 30 min of driving a driver takes a
#: break of at least 45 minutes [s].
MAX_DRIVING_S = 4.5 * 3600
EU_BREAK_S = 45 * 60.0


@dataclass(frozen=True)
class Rest:
    """The driver's breaks on the day: whether the EU rule holds, the fixed breaks as
    ``(earliest, latest, duration)`` [s after the departure], and the driving since the last
    break at the departure [s]."""

    eu_561: bool = False
    fixed: tuple[tuple[float, float, float], ...] = ()
    driven_s: float = 0.0


@dataclass(frozen=True)
class Break:
    """A break the timeline holds: from ``start_s`` to ``end_s`` after the departure, and
    why — "eu-561" (the driving limit; a wait or a charge long enough counts) or "fixed"."""

    start_s: float
    end_s: float
    kind: str


@dataclass(frozen=True)
class Drive:
    """One leg as the van drives it: speed every :data:`PLAN_DT_S` [m/s], the heading of each
    sample [°], the street type, and how much longer the motor's cap made it [s]."""

    speed_mps: FloatArray
    heading_deg: FloatArray
    street_type: StreetTypeName
    capped_s: float = 0.0


def drive(
    problem: PlanProblem,
    legs: Legs,
    i: int,
    j: int,
    route: LegRoute | None,
    straight_heading_deg: float = 0.0,
    payload_kg: float | None = None,
) -> Drive:
    """The leg from place i to place j: the road's speed profile from a router, or the paper's
    trace for the leg's street type (stretched to the client's duration for a client matrix),
    driven as the van's motor allows (:func:`core.physics.motor.power_limited`, at the van's
    mass with ``payload_kg``, the departure payload if None)."""
    vehicle = problem.van.vehicle
    mass_kg = vehicle.mass_kg + (problem.van.payload_kg if payload_kg is None else payload_kg)
    if route is None:
        street_type = legs.street_type_name(i, j)
        trace = generate_leg(
            float(legs.distance_m[i, j]),
            STREET_TYPES[street_type],
            problem.driver_aggressiveness,
            vehicle.max_acceleration_mps2,
            problem.traffic_density,
            PLAN_DT_S,
        )
        if legs.source == "client":  # the client's router knows how long the leg takes
            trace = _in_the_clients_time(vehicle.max_acceleration_mps2, trace, legs, i, j)
        driven = power_limited(vehicle, trace, PLAN_DT_S, mass_kg, float(legs.grade[i, j]))
        if driven is None:
            return Drive(trace, np.full(trace.size, straight_heading_deg), street_type)
        speed = driven.speed_mps
        return Drive(speed, np.full(speed.size, straight_heading_deg), street_type, driven.lost_s)
    free_flow_s = float(np.sum(route.segment_distance_m / route.segment_speed_mps))
    street_type = STREET_TYPE_NAMES[int(street_type_by_speed(route.distance_m, free_flow_s))]
    trace, _ = drive_profile(
        route.segment_distance_m,
        route.segment_speed_mps,
        STREET_TYPES[street_type],
        problem.driver_aggressiveness,
        vehicle.max_acceleration_mps2,
        problem.traffic_density,
        PLAN_DT_S,
    )
    driven = power_limited(vehicle, trace, PLAN_DT_S, mass_kg, float(legs.grade[i, j]))
    speed = trace if driven is None else driven.speed_mps
    travelled = np.concatenate(([0.0], np.cumsum(0.5 * (speed[:-1] + speed[1:]) * PLAN_DT_S)))
    ends = np.cumsum(route.segment_distance_m)
    segment = np.minimum(np.searchsorted(ends, travelled), ends.size - 1)
    lost_s = 0.0 if driven is None else driven.lost_s
    return Drive(speed, route.segment_heading_deg[segment], street_type, lost_s)


def _in_the_clients_time(
    accel_mps2: float, trace: FloatArray, legs: Legs, i: int, j: int
) -> FloatArray:
    """A generated leg stretched to the client's duration; where that asks more than the van's
    acceleration or top speed, the plainest trace that lasts as long (or, for a duration no
    van can drive from rest to rest, as short as the van can: :func:`client_legs_too_fast`
    says so in the answer)."""
    distance_m, duration_s = float(legs.distance_m[i, j]), float(legs.duration_s[i, j])
    stretched = stretch_to_duration(trace, PLAN_DT_S, duration_s)
    steepest = float(np.abs(np.diff(stretched)).max()) / PLAN_DT_S if stretched.size > 1 else 0.0
    covered = trace_distance_m(stretched, PLAN_DT_S)
    if (
        stretched.max() <= MAX_SPEED_MPS
        and steepest <= accel_mps2 * (1 + 1e-9)
        and covered >= distance_m * (1 - 1e-9)
    ):
        return stretched
    return rest_to_rest(distance_m, duration_s, accel_mps2, MAX_SPEED_MPS, PLAN_DT_S)


def client_legs_too_fast(legs: Legs, accel_mps2: float) -> str | None:
    """A warning when the client's matrix gives legs less time than a van with this
    acceleration needs from rest to rest at 250 km/h at most (those legs take what it needs),
    naming the first such cell; None when every leg can be driven in its time."""
    if legs.source != "client":
        return None
    least = np.asarray(fastest_s(legs.distance_m, accel_mps2, MAX_SPEED_MPS))
    short = np.argwhere((legs.distance_m > 0) & (legs.duration_s < least - 1e-9))
    if not short.size:
        return None
    i, j = (int(k) for k in short[0])
    count = len(short)
    return (
        f"matrix.durations_s[{i}][{j}]: {legs.duration_s[i, j]:g} s for "
        f"{legs.distance_m[i, j]:g} m is faster than a van can drive from rest to rest (at least "
        f"{least[i, j]:.1f} s); {count} such leg{'s' if count > 1 else ''} of the matrix take "
        "what the van needs"
    )


def drive_time_s(problem: PlanProblem, legs: Legs, i: int, j: int, route: LegRoute | None) -> float:
    """How long the van takes from place i to place j in the simulation [s] (the generated or
    road-profile trace, which may differ from the matrix's duration)."""
    return (drive(problem, legs, i, j, route).speed_mps.size - 1) * PLAN_DT_S


@dataclass(frozen=True)
class Timeline:
    """The day sample by sample, and the marks that split it: leg k drives from depart[k] to
    arrive[k]; the stop after it (if any) waits for its window until serve[k] and lasts until
    leave[k]; ``late`` lists the places reached after their last window closed; ``capped_s``
    is how much longer the motor's cap made the drives [s]."""

    speed: FloatArray
    grade: FloatArray
    payload: FloatArray
    heading: FloatArray
    doors: list[DoorOpening]
    parked: list[Interval]
    depart: NDArray[np.int_]
    arrive: NDArray[np.int_]
    serve: NDArray[np.int_]
    leave: NDArray[np.int_]
    late: list[int]
    street_types: list[StreetTypeName]
    geometry: list[list[tuple[float, float]]]
    capped_s: float = 0.0
    charging: list[ChargingSpell] = field(default_factory=list)
    charged_at: list[int] = field(default_factory=list)
    reloaded_at: list[int] = field(default_factory=list)
    breaks: list[Break] = field(default_factory=list)

    @property
    def duration_s(self) -> float:
        """From departure to return [s]."""
        return (self.speed.size - 1) * PLAN_DT_S

    def along(
        self, box_start_c: float | None = None, product_start_c: float | None = None
    ) -> Along:
        """What the simulation drives along the day besides its speed (the box's start as
        :class:`core.physics.simulate.Along` says)."""
        return Along(
            grade=self.grade,
            payload_kg=self.payload,
            door_openings=self.doors,
            parked=self.parked,
            heading_deg=self.heading,
            charging=self.charging,
            box_start_c=box_start_c,
            product_start_c=product_start_c,
        )

    def driven(self, sample_at: Callable[[ArrayLike], Any]) -> Timeline:
        """The marks moved to the samples of the trace the van drove (``sample_at``: a
        sample of this timeline → the driven trace's, where a motor's cap slowed it)."""

        def moved(marks: NDArray[np.int_]) -> NDArray[np.int_]:
            return np.asarray(sample_at(marks), dtype=int)

        def at_s(moment_s: float) -> float:
            return float(sample_at(np.array([moment_s / PLAN_DT_S]))[0]) * PLAN_DT_S

        return replace(
            self,
            depart=moved(self.depart),
            arrive=moved(self.arrive),
            serve=moved(self.serve),
            leave=moved(self.leave),
            breaks=[replace(b, start_s=at_s(b.start_s), end_s=at_s(b.end_s)) for b in self.breaks],
        )


@dataclass
class _Builder:
    """The day's samples as they are appended, part by part."""

    payload_kg: float
    clock: int = 0
    speed: list[FloatArray] = field(default_factory=lambda: [np.zeros(1)])
    grade: list[FloatArray] = field(default_factory=lambda: [np.zeros(1)])
    heading: list[FloatArray] = field(default_factory=lambda: [np.full(1, np.nan)])
    payload: list[FloatArray] = field(default_factory=list)
    doors: list[DoorOpening] = field(default_factory=list)
    parked: list[Interval] = field(default_factory=list)
    marks: dict[str, list[int]] = field(
        default_factory=lambda: {"depart": [], "arrive": [], "serve": [], "leave": []}
    )
    late: list[int] = field(default_factory=list)
    street_types: list[StreetTypeName] = field(default_factory=list)
    geometry: list[list[tuple[float, float]]] = field(default_factory=list)
    capped_s: float = 0.0
    charging: list[ChargingSpell] = field(default_factory=list)
    charged_at: list[int] = field(default_factory=list)
    reloaded_at: list[int] = field(default_factory=list)
    rest: Rest = field(default_factory=Rest)
    driving_s: float = 0.0
    breaks: list[Break] = field(default_factory=list)
    taken: set[int] = field(default_factory=set)

    def __post_init__(self) -> None:
        self.payload.append(np.array([self.payload_kg]))

    def drive(self, trace: FloatArray, heading: FloatArray, grade: float) -> None:
        """Append a leg's samples after its first (the van stands there already)."""
        samples = trace[1:]
        self.marks["depart"].append(self.clock)
        self.clock += samples.size
        self.driving_s += samples.size * PLAN_DT_S
        self.marks["arrive"].append(self.clock)
        self.speed.append(samples)
        self.heading.append(heading[1:])
        self.grade.append(np.full(samples.size, grade))
        self.payload.append(np.full(samples.size, self.payload_kg))

    def stand(self, samples: int, payload_kg: float) -> None:
        """Append ``samples`` parked samples at ``payload_kg``."""
        self.speed.append(np.zeros(samples))
        self.grade.append(np.zeros(samples))
        self.heading.append(np.full(samples, np.nan))
        self.payload.append(np.full(samples, payload_kg))
        self.clock += samples

    def rest_before(self, drive_s: float) -> None:
        """The breaks due before a leg of ``drive_s``: a fixed break whose time has come (or
        that would be missed during the leg; the van waits for its earliest start), and the EU
        break when the leg would take the driving since the last one past 4 h 30 min."""
        for k, (earliest, latest, duration) in enumerate(self.rest.fixed):
            now = self.clock * PLAN_DT_S
            if k not in self.taken and (now >= earliest or now + drive_s > latest):
                self.taken.add(k)
                self.stand_parked(math.ceil(max(earliest - now, 0.0) / PLAN_DT_S))
                self.take_break(duration, "fixed")
        if self.rest.eu_561 and self.driving_s > 0 and self.driving_s + drive_s > MAX_DRIVING_S:
            self.take_break(EU_BREAK_S, "eu-561")

    def take_break(self, duration_s: float, kind: str) -> None:
        start = self.clock
        self.stand_parked(math.ceil(duration_s / PLAN_DT_S))
        self.counts_as_break(start, kind)

    def counts_as_break(self, start: int, kind: str) -> None:
        """The van stood parked since sample ``start``: a break, and the EU one when long
        enough."""
        if self.clock - start <= 0:
            return
        long_enough = (self.clock - start) * PLAN_DT_S >= EU_BREAK_S
        if kind != "eu-561" or long_enough:
            self.breaks.append(Break(start * PLAN_DT_S, self.clock * PLAN_DT_S, kind))
        if long_enough:
            self.driving_s = 0.0

    def stand_parked(self, samples: int) -> None:
        """Stand ``samples`` parked with the door shut (the cab's duty while parked)."""
        if samples > 0:
            self.parked.append(
                Interval(start_s=self.clock * PLAN_DT_S, duration_s=samples * PLAN_DT_S)
            )
            self.stand(samples, self.payload_kg)

    def serve(self, place: int, stop: Stop, windows_s: Windows) -> None:
        """Wait for the stop's window, then serve it with the door open; the van leaves
        lighter by what it unloaded."""
        arrival_s = self.clock * PLAN_DT_S
        window = next_window(arrival_s, windows_s)
        if window is None:
            self.late.append(place)
        wait = math.ceil(max((window or (0.0, 0.0))[0] - arrival_s, 0.0) / PLAN_DT_S)
        dwell = math.ceil(stop.service_time_s / PLAN_DT_S)
        self.parked.append(Interval(start_s=arrival_s, duration_s=(wait + dwell) * PLAN_DT_S))
        self.stand(wait, self.payload_kg)
        if self.rest.eu_561 and wait * PLAN_DT_S >= EU_BREAK_S:  # the wait is the break
            self.counts_as_break(self.clock - wait, "eu-561")
        self.marks["serve"].append(self.clock)
        if stop.door_open_s > 0:
            self.doors.append(
                DoorOpening(start_s=self.clock * PLAN_DT_S, duration_s=stop.door_open_s)
            )
        # Unloading happens during the service: the lighter van drives away.
        self.payload_kg = max(self.payload_kg - stop.delivery_kg, 0.0)
        self.stand(dwell, self.payload_kg)

    def charge(
        self, position: int, visit: ChargeVisit, reload: tuple[float, float] | None = None
    ) -> None:
        """Stand at a charger (place ``position`` of the order): wait for it to open with room
        for the charge (:func:`charge_window`), plug in, charge for ``visit.charge_s`` (until
        it closes at the latest), unplug. A charger
        closed for the rest of the day charges nothing. ``reload`` (its duration [s] and the
        payload [kg]): the van is reloaded meanwhile, and stands at least that long."""
        plug = math.ceil(visit.plug_s / 2 / PLAN_DT_S)
        arrival = self.clock
        hours = charge_window(arrival * PLAN_DT_S, visit.open_s, visit.plug_s + visit.charge_s)
        wait, charge = 0, math.ceil(visit.charge_s / PLAN_DT_S)
        if hours is None:
            charge = 0
        else:
            wait = math.ceil(max(hours[0] / PLAN_DT_S - arrival, 0.0))
            if math.isfinite(hours[1]):
                left = math.floor(hours[1] / PLAN_DT_S - arrival - wait - 2 * plug)
                charge = max(min(charge, left), 0)
        self.parked.append(
            Interval(start_s=arrival * PLAN_DT_S, duration_s=(wait + 2 * plug + charge) * PLAN_DT_S)
        )
        self.stand(wait + plug, self.payload_kg)
        self.marks["serve"].append(self.clock)
        if charge:
            self.charged_at.append(position)
            self.charging.append(
                ChargingSpell(
                    start_s=self.clock * PLAN_DT_S,
                    duration_s=charge * PLAN_DT_S,
                    power_kw=visit.power_kw,
                    price_per_kwh=visit.price_per_kwh,
                )
            )
        self.stand(charge + plug, self.payload_kg)
        if reload is not None:
            duration_s, self.payload_kg = reload
            self.reloaded_at.append(position)
            self.stand_parked(math.ceil(duration_s / PLAN_DT_S) - (self.clock - arrival))
        if self.rest.eu_561 and (self.clock - arrival) * PLAN_DT_S >= EU_BREAK_S:
            self.counts_as_break(arrival, "eu-561")  # charged (or waited) during the break

    def reload(self, position: int, duration_s: float, payload_kg: float) -> None:
        """Stand at the depot (place ``position`` of the order) for ``duration_s``, parked,
        and leave with ``payload_kg`` aboard."""
        self.marks["serve"].append(self.clock)
        self.reloaded_at.append(position)
        self.payload_kg = payload_kg
        start = self.clock
        self.stand_parked(math.ceil(duration_s / PLAN_DT_S))
        if self.rest.eu_561 and duration_s >= EU_BREAK_S:  # reloaded during the break
            self.counts_as_break(start, "eu-561")

    def finish(self) -> Timeline:
        marks = {name: np.array(values) for name, values in self.marks.items()}
        return Timeline(
            speed=np.concatenate(self.speed),
            grade=np.concatenate(self.grade),
            payload=np.concatenate(self.payload),
            heading=np.concatenate(self.heading),
            doors=self.doors,
            parked=self.parked,
            depart=marks["depart"],
            arrive=marks["arrive"],
            serve=marks["serve"],
            leave=marks["leave"],
            late=self.late,
            street_types=self.street_types,
            geometry=self.geometry,
            capped_s=self.capped_s,
            charging=self.charging,
            charged_at=self.charged_at,
            reloaded_at=self.reloaded_at,
            breaks=self.breaks,
        )


def build_timeline(
    problem: PlanProblem,
    places: list[Place],
    legs: Legs,
    itinerary: Itinerary,
    routes: list[LegRoute] | None,
    windows_s: Sequence[Windows] | None = None,
    rest: Rest | None = None,
) -> Timeline:
    """Speed, grade, payload and heading of every sample of the day, the door openings, the
    stops and the marks, for the ``itinerary`` (its stops served, its charges made, its returns
    to the depot reloaded). With ``windows_s`` (each place's time windows, seconds after the
    departure) the van waits, parked with the door shut, for a stop's window to open; a stop
    reached after its last window closes is served at once and listed in ``late``. ``rest``:
    the driver's breaks, taken between stops (:meth:`_Builder.rest_before`)."""
    rest = rest or Rest()
    day = _Builder(start_payload_kg(problem), rest=rest, driving_s=rest.driven_s)
    reload = (problem.reload_minutes * 60, problem.van.payload_kg)
    for k, (i, j) in enumerate(itertools.pairwise(itinerary.order)):
        a, b = places[i], places[j]
        route = routes[k] if routes is not None else None
        leg = drive(
            problem, legs, i, j, route, bearing_deg(a.lat, a.lon, b.lat, b.lon), day.payload_kg
        )
        day.rest_before((leg.speed_mps.size - 1) * PLAN_DT_S)
        day.street_types.append(leg.street_type)
        day.capped_s += leg.capped_s
        day.geometry.append(
            [(float(x), float(y)) for x, y in route.coordinates]
            if route is not None
            else [(a.lon, a.lat), (b.lon, b.lat)]
        )
        day.drive(leg.speed_mps, leg.heading_deg, float(legs.grade[i, j]))
        kind = itinerary.kind(k + 1, len(problem.stops))
        if kind == "stop":
            day.serve(j, problem.stops[j - 1], windows_s[j] if windows_s is not None else ())
        elif kind == "charge":  # reloaded while it charges, when it came back for both
            visit = itinerary.charges[k + 1]
            day.charge(k + 1, visit, reload if itinerary.reloads_at(k + 1) else None)
        elif kind == "reload":
            day.reload(k + 1, *reload)
        else:
            day.marks["serve"].append(day.clock)
        day.marks["leave"].append(day.clock)
    return day.finish()


def later_departure_s(
    timeline: Timeline,
    order: Sequence[int],
    windows_s: Sequence[Windows],
    latest_return_s: float | None,
) -> float:
    """How much later the van can leave and wait less [s]: a delay is absorbed by the waits
    before each stop, and beyond them shifts the stop's service, which must stay inside its
    window (the forward time slack of Savelsbergh, *ORSA J. Computing* 4 (1992) 146)."""
    waited = 0.0
    slack = math.inf
    for k, j in enumerate(order[1:-1]):
        served_s = timeline.serve[k] * PLAN_DT_S
        waited += served_s - timeline.arrive[k] * PLAN_DT_S
        window = next_window(served_s, windows_s[j])
        closes = math.inf if window is None else window[1]
        slack = min(slack, waited + closes - served_s)
    if latest_return_s is not None:  # the return moves only by what the waits do not absorb
        slack = min(slack, waited + latest_return_s - timeline.leave[-1] * PLAN_DT_S)
    return float(max(min(waited, slack), 0.0) // PLAN_DT_S * PLAN_DT_S)
