"""The problems and the results of planning, each defined once: the fields every round shares
(:class:`RoundFields`), one round (:class:`PlanProblem`), a fleet (:class:`FleetProblem`), and
what comes back — a simulated round (:class:`PlanResult`) and a fleet's day
(:class:`FleetResult`). The web layer's request models inherit these fields.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, Discriminator, Field, Tag, ValidationInfo, field_validator

from core.exceptions import InvalidParameterError, InvalidStopsError
from core.params import (
    BRANCH_TAG,
    MAX_CHARGERS,
    MAX_STOPS,
    NORMAL_DRIVER,
    Charger,
    ClockTime,
    Depot,
    IsoDate,
    IsoDateTime,
    Objective,
    Params,
    Place,
    ProductBand,
    Result,
    RoadMatrix,
    Stop,
    StreetTypeName,
    TrafficDensity,
    VanParams,
    Weather,
    clock_field,
)
from core.physics.battery import BatteryVerdict
from core.physics.cold_chain import ColdChainCheck
from core.physics.weather import DayWeather, WeatherSource
from core.planning.itinerary import Itinerary
from core.routing.effort import Effort, SearchEnd
from core.routing.geo import DistanceSource, build_legs
from core.routing.tsp import SolverStatus

#: How the answers name the depot's charger.
DEPOT_CHARGER_ID = "depot"
#: The id of the van's position in the tour and the legs (a day planned from where it is).
START_ID = "start"
#: Sampling interval of a planned day's simulation [s].
PLAN_DT_S = 1.0
#: Longest round the planner simulates [s] (a week): longer inputs are mistakes.
MAX_ROUND_S = 7 * 86_400.0
#: Most vans in one fleet plan (the server's setting may allow fewer).
MAX_VEHICLES = 1000
#: Longest a problem may ask its search to run, and most work it may ask for [s].
MAX_TIME_LIMIT_S = 600.0
#: Least search time [s]: less is no search at all (and 1e-300 s is not a time).
MIN_TIME_LIMIT_S = 0.01
#: The search's work when the request gives none: this share of ``time_limit_s``, in
#: reference seconds (:mod:`core.routing.effort`). The rest of the limit is for what is not
#: counted as work — the simulations that verify the routes, the answer — and for a machine
#: a little busier than the reference: on the reference machine, idle, a default fleet of 25
#: to 1,000 stops uses 60–90 % of its limit (``benchmarks/bench_limits.py``).
WORK_SHARE = 0.85
#: What a search's answer takes besides its work, whatever its size [s]: the matrix, the
#: estimates, the weather, the first simulations (0.2–0.3 s on the reference machine): the
#: work is :data:`WORK_SHARE` of the limit less this, and at least :data:`LEAST_WORK_SHARE`
#: of the limit.
SETUP_S = 0.3
LEAST_WORK_SHARE = 0.1


def default_work_s(time_limit_s: float) -> float:
    """The work of a search given ``time_limit_s`` and no work [reference s]: what the
    reference machine fills the limit with (:data:`WORK_SHARE`, :data:`SETUP_S`), to the
    millisecond."""
    work_s = max(WORK_SHARE * (time_limit_s - SETUP_S), LEAST_WORK_SHARE * time_limit_s)
    return round(work_s, 3)  # as a client reads and sends it back


@dataclass(frozen=True)
class DefaultLimit:
    """The time limit of a request that gives none: ``per_stop_s`` a stop, at least
    ``least_s`` and at most ``most_s`` [s] — small rounds answer in about a second, large
    fleets get the time a good plan of their size takes."""

    per_stop_s: float
    least_s: float
    most_s: float

    def __call__(self, data: dict[str, Any]) -> float:
        """The limit for the request's fields validated so far (its ``stops`` among them)."""
        stops = len(data.get("stops") or ())
        return min(max(self.per_stop_s * stops, self.least_s), self.most_s)

    def describe(self) -> str:
        return (
            f"absent: {self.per_stop_s:g} s a stop, at least {self.least_s:g} s and at most "
            f"{self.most_s:g} s"
        )


#: A round's default limit: up to 20 stops in a second, 40 (and their charges) in 2 s, 200
#: and more in 10 s.
PLAN_TIME_LIMIT = DefaultLimit(per_stop_s=0.05, least_s=1.0, most_s=10.0)
#: A fleet's: 6 s for 100 stops, a minute for 1,000 (what the Gehring–Homberger days and
#: PyVRP at the same limit are measured at).
FLEET_TIME_LIMIT = DefaultLimit(per_stop_s=0.06, least_s=1.0, most_s=60.0)


def time_limit_field(default: DefaultLimit) -> float:
    """The ``time_limit_s`` field of a problem with its default by size [s]."""
    return Field(
        default_factory=default,
        ge=MIN_TIME_LIMIT_S,
        le=MAX_TIME_LIMIT_S,
        description="The most the search may take [s], at least 0.01 s (capped by the server's "
        f"setting); {default.describe()}. Its work, unless work_s is given, is "
        f"{WORK_SHARE:.0%} of it less {SETUP_S:g} s (a search that does all its work gives the "
        "same answer every time). A search the limit stops first says so (solver.stopped_by: "
        "time_limit) and may answer otherwise on a retry; its solver.replay, sent back, gives "
        "the same answer.",
    )


def cut_short(stopped_by: SearchEnd) -> list[str]:
    """The warning of an answer whose search the time limit stopped before its work was done."""
    if stopped_by != "time_limit":
        return []
    return [
        "the search was stopped by its time limit (time_limit_s) before its work (work_s) was "
        "done: on a busy or slower machine the same request may give another plan; sending "
        "it again with this answer's solver.replay as its replay gives this plan again"
    ]


class ReplayStop(Params):
    """Where the clock stopped one search of a request."""

    watch: int = Field(
        ..., ge=0, le=10**9, description="Which look at the clock, in the order they were made."
    )
    at: int = Field(
        ...,
        ge=0,
        le=2**53,
        description="The count of its search's units (iterations, kicks, moves, solutions) "
        "after which it stopped.",
    )


class Replay(Params):
    """The work a request's searches did: sent back as the request's ``replay``, the same
    searches do the same work again without looking at the clock — the same answer to the
    byte (but its timing fields) on any machine, even one the time limit cut."""

    request: str = Field(
        ...,
        pattern="^[0-9a-f]{64}$",
        description="SHA-256 of the request it belongs to (every field but replay and "
        "time_limit_s, as the server understood them): a replay of another request is refused.",
    )
    seed: int = Field(..., ge=0, le=2**31 - 1, description="The searches' seed.")
    work_s: float = Field(
        ...,
        ge=0,
        le=MAX_TIME_LIMIT_S,
        description="The work the searches were given [reference s].",
    )
    stops: list[ReplayStop] = Field(
        [],
        max_length=100_000,
        description="Each search the clock stopped before its work was done, and where "
        "(empty: every search did all its work; the answer is then the same without replay).",
    )


class SearchFields(Params):
    """How much the search does, from which seed: the same request gives the same answer."""

    work_s: float | None = Field(
        None,
        ge=MIN_TIME_LIMIT_S,
        le=MAX_TIME_LIMIT_S,
        description="The search's work in reference seconds (what one core of the reference "
        "machine does in that time; kicks, iterations and deterministic time in each solver): "
        "the same amount of search on any machine and under any load, so the same answer. "
        f"Absent: {WORK_SHARE:.0%} of time_limit_s less {SETUP_S:g} s (at least "
        f"{LEAST_WORK_SHARE:.0%} of it), what the reference machine fills the limit with. "
        "Searches end earlier on a proof.",
    )
    seed: int = Field(0, ge=0, le=2**31 - 1, description="Seed of every search's randomness.")
    replay: Replay | None = Field(
        None,
        description="An earlier answer's solver.replay, to do its searches' work again to "
        "the byte without the clock (sent with the same request; time_limit_s does not cap it). "
        "A replay running longer than 3 times the server's cap on time_limit_s and 10 s is "
        "refused (413, naming replay).",
    )

    def fingerprint(self) -> str:
        """SHA-256 of the problem as the search sees it: every field but ``replay`` and
        ``time_limit_s`` (which only caps the work) [hex] (0.2 s for 1,000 stops and their
        matrix)."""
        text = self.model_dump_json(exclude={"replay", "time_limit_s", "replay_limit_s"})
        return hashlib.sha256(text.encode()).hexdigest()

    def work(self, time_limit_s: float) -> float:
        """The search's work [reference s]: ``work_s``, or :func:`default_work_s`."""
        return self.work_s if self.work_s is not None else default_work_s(time_limit_s)

    def check_replay(self, time_limit_s: float, fingerprint: str | None = None) -> None:
        """A ``replay`` of this very request (its ``fingerprint``, when known): the same
        fingerprint, seed and work; raises :class:`core.exceptions.InvalidParameterError`
        naming the field."""
        replay = self.replay
        if replay is None:
            return
        if replay.request != (fingerprint or self.fingerprint()):
            raise InvalidParameterError(
                "replay belongs to another request (its fingerprint differs): send it with the "
                "request whose answer gave it, unchanged (time_limit_s too, unless work_s is "
                "given: the work is a share of it)",
                "replay.request",
            )
        if replay.seed != self.seed:
            raise InvalidParameterError(f"replay.seed must equal seed ({self.seed})", "replay.seed")
        if replay.work_s != self.work(time_limit_s):
            raise InvalidParameterError(
                f"replay.work_s must equal the request's work ({self.work(time_limit_s):g} s)",
                "replay.work_s",
            )
        watches = [stop.watch for stop in replay.stops]
        if len(set(watches)) != len(watches):
            raise InvalidParameterError("replay.stops names a watch twice", "replay.stops")

    def effort(self, time_limit_s: float, replay_limit_s: float | None = None) -> Effort:
        """The search's effort from now: its work (:meth:`work`), capped ``time_limit_s`` from
        now, with the seed; replaying, stopped where the replay says instead, and refused
        beyond ``replay_limit_s`` [s] from now (None: never). Its clock knows the request's
        fingerprint (:func:`replay_of`)."""
        fingerprint = self.fingerprint()
        self.check_replay(time_limit_s, fingerprint)
        replayed = None if self.replay is None else {s.watch: s.at for s in self.replay.stops}
        return Effort.starting_now(
            self.work(time_limit_s),
            time_limit_s,
            self.seed,
            replayed,
            fingerprint,
            math.inf if replay_limit_s is None else replay_limit_s,
        )


def replay_of(effort: Effort) -> Replay:
    """What the searches under ``effort`` (:meth:`SearchFields.effort`) did, to replay them."""
    clock = effort.clock
    stops = clock.stops if clock.replayed is None else clock.replayed
    return Replay(
        request=clock.request,
        seed=effort.seed,
        work_s=effort.work_s,
        stops=[ReplayStop(watch=k, at=at) for k, at in sorted(stops.items())],
    )


class RoundFields(Params):
    """What every round shares: the day, the places and the conditions."""

    date: IsoDate = Field(..., description="Day of the round, YYYY-MM-DD.")
    timezone: str | None = Field(
        None,
        max_length=64,
        description="IANA time zone (Europe/Vienna); absent: local mean solar time at the depot.",
    )
    depot: Depot = Field(..., description="Where the round starts and ends.")
    stops: list[Stop] = Field(
        ..., min_length=1, max_length=MAX_STOPS, description="The stops, in any order."
    )
    weather: Weather | None = Field(
        None, description="The day's forecast; absent: the climatology for date and latitude."
    )
    driver_aggressiveness: float = Field(
        NORMAL_DRIVER, ge=0, le=1, description="ε_d [–]: 0.2 calm, 0.5 normal, 1 aggressive."
    )
    traffic_density: TrafficDensity | None = Field(
        None, description="ε_t [–], 0.01–0.99; absent: the street type's default."
    )
    objective: Objective = Field("distance", description="What the tour minimises.")
    matrix: RoadMatrix | None = Field(
        None, description="Road distances/durations from your router: depot first, then stops."
    )
    chargers: list[Charger] = Field(
        default_factory=list,
        max_length=MAX_CHARGERS,
        description="Charge points on the way (besides depot.charger): a round whose battery "
        "would not last visits them between stops, as often as it needs, and charges what the "
        "rest of its day needs. Rounds without time windows and without a client matrix.",
    )

    @property
    def places(self) -> list[Place]:
        """The depot, then the stops in request order (index 0 is the depot)."""
        return [self.depot, *self.stops]


def fields_of(source: Params, fields: type[Params]) -> dict[str, Any]:
    """The values of the fields that ``fields`` declares, from a model that has them too (a
    round's fields from a fleet, a plan's from a request)."""
    return {name: getattr(source, name) for name in fields.model_fields}


#: Most trips of one round, and the longest reload [min].
MAX_TRIPS = 20
MAX_RELOAD_MINUTES = 240.0
#: Longest fixed break [min]: half a day.
MAX_BREAK_MINUTES = 720.0


class FixedBreak(Params):
    """A break the driver takes at a set time of the day (lunch): it begins between
    ``earliest`` and ``latest``, as soon as the van is free (between two stops)."""

    earliest: ClockTime = Field(..., description="Earliest start, local HH:MM.")
    latest: ClockTime = Field(..., description="Latest start, local HH:MM, not before earliest.")
    minutes: float = Field(
        ..., ge=1, le=MAX_BREAK_MINUTES, description="How long it lasts [min], 1–720."
    )

    @field_validator("latest")
    @classmethod
    def _not_before_earliest(cls, value: dt.time, info: ValidationInfo) -> dt.time:
        if "earliest" in info.data and value < info.data["earliest"]:
            raise ValueError("latest must not be before earliest")
        return value


#: Most fixed breaks of one driver's day.
MAX_FIXED_BREAKS = 12


def _break_branch(value: object) -> str:
    return BRANCH_TAG + ("list" if isinstance(value, list) else "rule")


def _one_after_another(breaks: list[FixedBreak]) -> list[FixedBreak]:
    """Fixed breaks a driver can take in their order: each begins by its ``latest`` after the
    one before it ends (the earliest each can begin, one after another)."""
    free_min = 0.0
    for k, rest in enumerate(breaks):
        earliest = rest.earliest.hour * 60 + rest.earliest.minute
        latest = rest.latest.hour * 60 + rest.latest.minute
        begins = max(earliest, free_min)
        if begins > latest:
            raise ValueError(
                f"breaks[{k}] must begin by {rest.latest:%H:%M}, but the breaks before it last "
                f"until {int(free_min) // 60:02d}:{int(free_min) % 60:02d} at the earliest"
            )
        free_min = begins + rest.minutes
    return breaks


#: Drivers' breaks: EU Regulation (EC) No 561/2006 (art. 7), none, or fixed breaks.
Breaks = Annotated[
    Annotated[Literal["eu-561", "none"], Tag(BRANCH_TAG + "rule")]
    | Annotated[
        list[FixedBreak],
        Field(max_length=MAX_FIXED_BREAKS),
        AfterValidator(_one_after_another),
        Tag(BRANCH_TAG + "list"),
    ],
    Discriminator(_break_branch),
]


def breaks_field(default: str) -> Any:
    """The ``breaks`` field of a round or a van with its default."""
    return Field(
        default,
        description='"eu-561": a 45-minute break before driving more than 4 h 30 min since '
        "the last one (Regulation (EC) No 561/2006, art. 7; a wait or a charge of 45 min "
        'counts); "none"; or a list of fixed breaks ({"earliest", "latest", "minutes"}). '
        "Parked during a break: the cab and the refrigeration keep drawing.",
    )


class StartState(Params):
    """Where a van is when the rest of its day is planned again (at noon, say): it drives
    from here through the stops left and back to the depot."""

    lat: float = Field(..., ge=-90, le=90, description="Latitude [°], north positive.")
    lon: float = Field(..., ge=-180, le=180, description="Longitude [°], east positive.")
    time: IsoDateTime = Field(
        ..., description="When it leaves from here, ISO 8601 with UTC offset, on the date."
    )
    soc: float = Field(..., ge=0, le=1, description="State of charge now [–], 0–1.")
    box_temperature_c: float | None = Field(
        None, ge=-40, le=60, description="The box's temperature now [°C]; absent: the set-point."
    )
    product_temperature_c: float | None = Field(
        None,
        ge=-40,
        le=60,
        description="The goods' temperature now [°C] (a box with a product); absent: as "
        "loaded (cargo_box.load_temperature_c).",
    )
    payload_kg: float | None = Field(
        None, ge=0, le=40_000, description="Payload aboard now [kg]; absent: the van's payload_kg."
    )
    driving_since_break_s: float = Field(
        0.0, ge=0, le=86_400, description="Driving since the driver's last break [s] (EU 561)."
    )


class TripFields(Params):
    """How often a van may come back to the depot to reload, and how long that takes."""

    max_trips: int = Field(
        1,
        ge=1,
        le=MAX_TRIPS,
        description="Most trips from the depot (1–20): with more than 1, the van comes back to "
        "reload (its payload back to payload_kg) when its stops take more than it carries; "
        "every return to the depot reloads then, one to charge too (the van stands the longer "
        "of the two), and returns only to charge do not count. With start_state the first "
        "trip carries what is aboard.",
    )
    reload_minutes: float = Field(
        15.0, ge=0, le=MAX_RELOAD_MINUTES, description="Minutes to reload at the depot, 0–240."
    )


class StartFields(Params):
    """Where a van's day starts: the depot, or where it is now."""

    start_state: StartState | None = Field(
        None,
        description="Plan the rest of a day from where the van is (its position, time, charge, "
        "box temperature, payload, driving since the last break) to the depot, leaving at "
        "its time; without a client matrix (in fleets: its time within the van's shift, its "
        "payload at most payload_kg, its first trip what it has aboard). Absent: from the "
        "depot at the start of the day.",
    )


class PlanFields(RoundFields, TripFields, StartFields, SearchFields):
    """One round: when it leaves, and whether its order is the client's."""

    start_time: ClockTime = clock_field(
        "08:00",
        "Departure, local HH:MM (with time windows: the earliest; the van leaves later when the "
        "first stop's window opens later).",
    )
    keep_order: bool = Field(False, description="Drive the stops in the given order.")
    time_limit_s: float = time_limit_field(PLAN_TIME_LIMIT)
    breaks: Breaks = breaks_field("none")


class ServedFields(Params):
    """What the server adds to a problem it was sent."""

    replay_limit_s: float | None = Field(
        None,
        gt=0,
        description="The most a replay's searches may take [s] (a replay's work is not capped "
        "by time_limit_s): beyond it the replay is refused, naming replay. None: no limit.",
    )


class PlanProblem(PlanFields, ServedFields):
    """Everything a round needs: its fields and the van."""

    van: VanParams = Field(default_factory=VanParams, description="The van.")


def shift_in_order(start: dt.time | None, end: dt.time) -> dt.time:
    """``end`` when it is after ``start`` (shifts end on the day they start)."""
    if start is not None and end <= start:
        raise ValueError("shift_end must be after shift_start (shifts end on the same day)")
    return end


class ShiftFields(TripFields, StartFields):
    """One van of a fleet without its parameters: its id, its driver's shift and its trips."""

    id: str = Field(
        ..., min_length=1, max_length=64, description="Identifier of the van, unique in the fleet."
    )
    shift_start: ClockTime = clock_field("08:00", "Earliest departure from the depot, local HH:MM.")
    shift_end: ClockTime = clock_field(
        "18:00", "Latest return to the depot, local HH:MM, after shift_start (same day)."
    )
    breaks: Breaks = breaks_field("eu-561")
    pinned_stops: list[Annotated[str, Field(min_length=1, max_length=64)]] = Field(
        default_factory=list,
        max_length=MAX_STOPS,
        description="Ids of the stops pinned to this van: no other van serves them (the search "
        "gives each to this van or leaves it out, saying why). Empty: none; a stop pinned to no "
        "van goes to whichever van the search finds best.",
    )

    @field_validator("shift_end")
    @classmethod
    def _after_start(cls, value: dt.time, info: ValidationInfo) -> dt.time:
        return shift_in_order(info.data.get("shift_start"), value)

    @field_validator("breaks")
    @classmethod
    def _within_shift(cls, value: Breaks, info: ValidationInfo) -> Breaks:
        start, end = info.data.get("shift_start"), info.data.get("shift_end")
        if isinstance(value, list) and start is not None and end is not None:
            shift_min = (end.hour * 60 + end.minute) - (start.hour * 60 + start.minute)
            for k, fixed in enumerate(value):
                if fixed.minutes > shift_min:
                    raise ValueError(
                        f"breaks[{k}] lasts {fixed.minutes:g} min, longer than the "
                        f"{shift_min} min shift"
                    )
        return value


class FleetVehicle(ShiftFields):
    """One van of the fleet and its driver's shift."""

    van: VanParams = Field(default_factory=VanParams, description="The van, as in a plan.")


class FleetFields(RoundFields, SearchFields):
    """A fleet's day: how the vans are chosen."""

    minimize_vehicles: bool = Field(
        True, description="Fewer vans first, then the objective; false: the objective alone."
    )
    time_limit_s: float = time_limit_field(FLEET_TIME_LIMIT)


def vehicles_field() -> list[FleetVehicle]:
    """The ``vehicles`` field of a fleet."""
    return Field(
        ...,
        min_length=1,
        max_length=MAX_VEHICLES,
        description="The vans that may drive, each with its van, battery, payload and shift; "
        "those listed first drive first when as good.",
    )


class FleetProblem(FleetFields, ServedFields):
    """The day's stops and the fleet that serves them from one depot."""

    vehicles: list[FleetVehicle] = vehicles_field()


def check_stop_ids(depot: Depot, stops: Sequence[Stop], chargers: Sequence[Charger] = ()) -> None:
    """Every stop's and charger's id is its own (not the depot's, and no charger is called
    "depot", the name of the depot's charger in the answers); else an error naming the
    second."""
    seen = {depot.id: "the depot"}
    for name, places in (("stops", stops), ("chargers", chargers)):
        for index, place in enumerate(places):
            other = seen.get(place.id)
            if other is None and name == "chargers" and place.id == DEPOT_CHARGER_ID:
                other = "the depot's charger"
            if other is not None:
                raise InvalidStopsError(
                    f"id '{place.id}' is used twice (also by {other}); ids must be unique",
                    f"{name}[{index}].id",
                )
            seen[place.id] = f"{name}[{index}]"


def check_places(problem: RoundFields) -> None:
    """Ids of the stops and the chargers their own (:func:`check_stop_ids`), and a client's
    matrix with a row and a column for each (:func:`matrix_places`)."""
    check_stop_ids(problem.depot, problem.stops, problem.chargers)
    if problem.matrix is not None:
        build_legs(matrix_places(problem), problem.matrix)


def matrix_places(problem: RoundFields) -> list[Place]:
    """The places a client's matrix has rows for, in its order: the depot, the stops, then the
    chargers on the way."""
    return [*problem.places, *problem.chargers]


def place_field(index: int) -> str:
    """The request field of place ``index`` (0 the depot)."""
    return "depot" if index == 0 else f"stops[{index - 1}]"


# --- results ------------------------------------------------------------------------------------


class LegResult(Result):
    """One driven leg of the round."""

    from_id: str = Field(..., description="Where the leg starts: the depot's or a stop's id.")
    to_id: str = Field(..., description="Where the leg ends: a stop's or the depot's id.")
    depart: dt.datetime = Field(..., description="Departure, local time with offset.")
    arrive: dt.datetime = Field(..., description="Arrival, local time with offset.")
    distance_m: float = Field(..., description="Distance [m].")
    duration_s: float = Field(..., description="Driving time [s].")
    street_type: StreetTypeName = Field(
        ...,
        description="urban, highway or expressway: by the leg's speeds (router or client) "
        "or its length (estimate).",
    )
    grade: float = Field(..., description="Mean grade, rise over run [–].")
    energy_kwh: dict[str, float] = Field(
        ..., description="Energy of each consumer while driving this leg [kWh]."
    )
    soc_start: float = Field(..., description="State of charge at departure [–].")
    soc_end: float = Field(..., description="State of charge on arrival [–].")
    geometry: list[tuple[float, float]] = Field(
        ...,
        description="The leg's road as [lon, lat] points: the router's, or the straight line "
        "between the two places when the distances are an estimate or the client's.",
    )


class Temperatures(Result):
    """A temperature on arrival and on departure."""

    arrival: float | None = Field(..., description="On arrival [°C]; null: nothing to measure.")
    departure: float | None = Field(
        ..., description="On departure [°C]; null: nothing to measure (no goods left aboard)."
    )


class ColdChainResult(Result):
    """Whether the goods stayed inside their band while aboard (a box with a product)."""

    verdict: Literal["holds", "breaks"] = Field(
        ...,
        description="holds: from their loading on, the goods were never below min_c, never "
        "above max_c + excursion_c, and never above max_c for longer than excursion_minutes "
        "at a time; breaks: they were (first_break_stop and reason say where and why). Goods "
        "loaded outside their band break it from the first minute.",
    )
    product_min_c: float | None = Field(
        ..., description="The coldest the goods were, as loaded included [°C]."
    )
    product_max_c: float | None = Field(
        ..., description="The warmest the goods were, as loaded included [°C]."
    )
    minutes_outside_band: float = Field(
        ...,
        description="Time with the goods outside [min_c, max_c], pre-cooling at the depot "
        "included [min].",
    )
    first_break_stop: str | None = Field(
        ...,
        description="The stop being driven to or served when the chain first breaks (null: "
        "it holds, or it breaks after the last stop).",
    )
    first_break_s: float | None = Field(
        None,
        description="When it first breaks, seconds after the start (0: before departure, as "
        "loaded or while pre-cooling at the depot); null: it holds.",
    )
    reason: str | None = Field(..., description="Why it breaks, in words; null: it holds.")
    min_c: float = Field(..., description="The band's floor [°C].")
    max_c: float = Field(..., description="The band's ceiling [°C].")
    excursion_c: float = Field(..., description="The brief rise above max_c tolerated [K].")
    excursion_minutes: float = Field(
        ..., description="How long one rise above max_c may last [min] (product.excursion_minutes)."
    )

    @classmethod
    def of(
        cls, band: ProductBand, check: ColdChainCheck, stop: str | None = None
    ) -> ColdChainResult:
        """The verdict of ``check`` on ``band``; ``stop``: where it first breaks."""
        return cls(
            verdict="holds" if check.holds else "breaks",
            product_min_c=check.product_min_c,
            product_max_c=check.product_max_c,
            minutes_outside_band=check.minutes_outside_band,
            first_break_stop=stop,
            first_break_s=check.first_break_s,
            reason=check.reason,
            min_c=band.min_c,
            max_c=band.max_c,
            excursion_c=band.excursion_c,
            excursion_minutes=band.excursion_minutes,
        )


class DeliveredGoods(Result):
    """The goods handed over at a stop: what they went through from their loading on."""

    product_max_c: float | None = Field(
        ...,
        description="The warmest they were, as loaded included, until handed over [°C] (null: "
        "none were aboard).",
    )
    minutes_above_band: float = Field(
        ..., description="Time above the band's max_c until handed over [min]."
    )
    verdict: Literal["holds", "breaks"] = Field(
        ...,
        description="breaks: the cold chain broke before they were handed over (the day's "
        "cold_chain says where and why); holds: it had not.",
    )


class ScheduleInterval(Result):
    """A stretch of the refrigeration unit's schedule."""

    start: dt.datetime = Field(..., description="From, local time.")
    end: dt.datetime = Field(..., description="Until, local time.")
    power_w: float = Field(..., description="The unit's mean electric power [W].")
    air_setpoint_c: float = Field(
        ..., description="The air set-point the unit follows [°C] (its mean over the stretch)."
    )


class Baseline(Result):
    """A thermostat the day's unit is measured against: one set-point held all day."""

    name: Literal["thermostat", "best-constant"] = Field(
        ...,
        description="thermostat: the configured cargo_box.setpoint_c; best-constant: the "
        "constant set-point within the product's band that keeps the goods in it on this day "
        "for the least energy (the fair baseline of a strategy).",
    )
    setpoint_c: float = Field(..., description="Its set-point [°C].")
    battery_kwh: float = Field(..., description="What it draws from the battery [kWh].")
    grid_kwh: float = Field(..., description="What it draws from the grid, plugged in [kWh].")
    cost: float | None = Field(
        None, description="What its energy costs, as refrigeration.cost; null without a price."
    )
    cold_chain: Literal["holds", "breaks"] = Field(
        ..., description="Whether the goods keep to their band with it, by cold_chain's rules."
    )
    battery_saved: float = Field(
        ...,
        description="The share of its battery energy the day's unit does without [–] "
        "(negative: the unit draws more).",
    )
    total_saved: float = Field(
        ...,
        description="The share of its battery and grid energy together the day's unit does "
        "without [–] (negative: the unit draws more).",
    )


class RefrigerationResult(Result):
    """How the refrigeration unit ran, and what it drew."""

    strategy: Literal["thermostat", "optimal"] = Field(
        ..., description="The strategy the day was planned with (refrigeration.strategy)."
    )
    battery_kwh: float = Field(
        ..., description="The unit's energy from the battery (unplugged) [kWh]."
    )
    grid_kwh: float = Field(
        ...,
        description="The unit's energy from the grid: while plugged in, and pre-cooling at the "
        "depot before departure (optimal strategy) [kWh].",
    )
    thermostat_battery_kwh: float = Field(
        ...,
        description="What a thermostat at cargo_box.setpoint_c would have drawn from the "
        "battery on the same day [kWh] (the thermostat strategy: battery_kwh).",
    )
    objective: Literal["energy", "cost"] = Field(
        "energy", description="What the strategy spared (refrigeration.objective)."
    )
    cost: float | None = Field(
        None,
        description="What the unit's energy costs: the battery's kWh refilled at the depot's "
        "price over the charging efficiency, the grid's at the depot's and the chargers' "
        "price_per_kwh; null without a depot price.",
    )
    thermostat_cost: float | None = Field(
        None, description="What a thermostat's would have cost on the same day, alike."
    )
    schedule: list[ScheduleInterval] = Field(
        ...,
        description="The unit's set-point and power, stretch by stretch (a set-point schedule "
        "a unit's controller can load).",
    )
    followed: Literal["thermostat", "schedule", "best-constant"] = Field(
        "thermostat",
        description="What the unit follows: the thermostat at cargo_box.setpoint_c, the "
        "optimal strategy's schedule, or — where the schedule would not beat it — the best "
        "constant set-point (baselines).",
    )
    baselines: list[Baseline] = Field(
        default_factory=list,
        description="The day's unit against the configured thermostat and the best constant "
        "set-point (a box with a product).",
    )


class StopResult(Result):
    """One stop of the round, in visiting order."""

    id: str = Field(..., description="The stop's id.")
    arrival: dt.datetime = Field(..., description="Arrival, local time with UTC offset.")
    service_start: dt.datetime = Field(
        ..., description="Service begins (inside a time window), local time with UTC offset."
    )
    wait_s: float = Field(
        ..., description="Waiting for the stop's time window to open, parked [s]."
    )
    departure: dt.datetime = Field(
        ..., description="Departure after the service, local time with UTC offset."
    )
    door_heat_kwh: float = Field(..., description="Heat let in through the open door [kWh].")
    payload_after_kg: float = Field(..., description="Payload when leaving the stop [kg].")
    energy_kwh: dict[str, float] = Field(..., description="Energy used while standing here [kWh].")
    soc_arrival: float = Field(..., description="State of charge on arrival [–].")
    soc_departure: float = Field(..., description="State of charge when leaving [–].")
    snap_distance_m: float | None = Field(
        None,
        description="Distance from the stop to the road the router snapped it to [m]; null "
        "without a router.",
    )
    lat: float = Field(..., description="The stop's latitude, as requested [°].")
    lon: float = Field(..., description="The stop's longitude, as requested [°].")
    air_temperature_c: Temperatures = Field(
        ..., description="The box air on arrival and on departure [°C] (steady box: set-point)."
    )
    product_temperature_c: Temperatures | None = Field(
        None,
        description="The goods on arrival and on departure [°C]; null: the box has no product.",
    )
    goods: DeliveredGoods | None = Field(
        None,
        description="The goods handed over here and the cold chain until then; null: the box "
        "has no product.",
    )


class ChargeResult(Result):
    """One charge of the round, where it happens in the timeline."""

    charger_id: str = Field(
        ..., description="Where: a charger's id, or \"depot\" for the depot's charger."
    )
    arrive: dt.datetime = Field(..., description="Arrival at the charger, local time.")
    depart: dt.datetime = Field(
        ..., description="Departure, plugging in and out included, local time."
    )
    soc_before: float = Field(..., description="State of charge when the charge starts [–].")
    soc_after: float = Field(..., description="State of charge when it ends [–].")
    grid_kwh: float = Field(
        ...,
        description="Energy from the grid: the charge (battery_kwh / charging_efficiency) and "
        "the cab and refrigeration, which run from the grid while plugged in [kWh].",
    )
    battery_kwh: float = Field(..., description="Energy stored in the battery [kWh].")
    minutes: float = Field(..., description="Minutes charging (plugging in and out aside).")
    cost: float = Field(..., description="grid_kwh at the charger's price_per_kwh.")
    lat: float = Field(..., description="The charger's latitude [°].")
    lon: float = Field(..., description="The charger's longitude [°].")


class ReloadResult(Result):
    """A return to the depot to reload, where it happens in the timeline."""

    arrive: dt.datetime = Field(..., description="Arrival at the depot, local time.")
    depart: dt.datetime = Field(..., description="Departure with the new load, local time.")
    payload_kg: float = Field(..., description="Payload aboard when it leaves [kg].")


class BreakResult(Result):
    """A driver's break, parked (cab and refrigeration drawing)."""

    start: dt.datetime = Field(..., description="Start, local time.")
    end: dt.datetime = Field(..., description="End, local time.")
    kind: str = Field(
        ...,
        description='"eu-561": the driving limit of Regulation (EC) No 561/2006 (also a wait '
        'or a charge of 45 min that counts as the break); "fixed": one of the listed breaks.',
    )


#: What a van does at a visit of its day.
VisitKindName = Literal["stop", "charge", "reload", "break"]


class VisitResult(Result):
    """One visit of the day, in time order: a stop, a charge, a return to reload or a break."""

    kind: VisitKindName = Field(
        ...,
        description="stop; charge (at a charger, or the depot's — reloaded meanwhile when the "
        "van came back for both: see payload_after_kg); reload (back at the depot for the "
        "next trip's load); break (the driver's, parked where the van is).",
    )
    id: str = Field(
        ...,
        description="Where: the stop's id, the charger's (\"depot\" for the depot's), the "
        "depot's for a reload, the place the van stands at for a break.",
    )
    arrive: dt.datetime = Field(..., description="Arrival (a break: its start), local time.")
    start: dt.datetime = Field(
        ...,
        description="The service, the charge or the reload begins, after any wait for a window "
        "or a charger's opening (and half the plug-in), local time.",
    )
    depart: dt.datetime = Field(..., description="Departure (a break: its end), local time.")
    soc_arrival: float = Field(..., description="State of charge on arrival [–].")
    soc_departure: float = Field(..., description="State of charge when leaving [–].")
    payload_after_kg: float = Field(..., description="Payload aboard when leaving [kg].")
    energy_kwh: dict[str, float] = Field(
        ..., description="Energy of each consumer from arrival to departure [kWh]."
    )
    driving_s: float = Field(
        ..., description="Driving time since the day's departure, on arrival [s]."
    )


class DayProfile(Result):
    """The round minute by minute, from departure to return (the paper's Fig. 8)."""

    time: list[dt.datetime] = Field(..., description="Each minute, local time with UTC offset.")
    energy_kwh: dict[str, list[float]] = Field(
        ..., description="Energy of each consumer and the total since departure, cumulative [kWh]."
    )
    soc: list[float] = Field(..., description="State of charge at each moment [–].")
    box_temperature_c: list[float] | None = Field(
        ...,
        description="Cargo-air temperature at each moment [°C] (dynamic box; null in steady "
        "mode, where the unit holds the set-point).",
    )
    product_temperature_c: list[float | None] | None = Field(
        None,
        description="The goods' temperature at each moment [°C] (cargo_box.product; null "
        "while none are aboard, and without a product).",
    )
    air_setpoint_c: list[float] | None = Field(
        None,
        description="The air set-point the unit follows at each moment [°C] (the optimal "
        "strategy's schedule; null with the thermostat, which holds setpoint_c).",
    )


#: The parts of a plan a proof may cover: the order of its stops.
ProvenPart = Literal["order"]


class Solved(Result):
    """How the plan was found."""

    status: SolverStatus = Field(
        ...,
        description="optimal: the whole answer is proven optimal for its objective — the order "
        "proven over every arc, and no charge or reload placed by a heuristic; feasible: the "
        "best found (see proven for the parts that carry a proof); fixed_order: keep_order.",
    )
    objective_value: float = Field(..., description="Of the tour, in m, s or Wh (estimate).")
    runtime_s: float = Field(
        ..., description="Time the search took [s]. A timing field: it differs between runs."
    )
    stopped_by: SearchEnd = Field(
        "work",
        description="work: the search did all its work (work_s); proof: it proved its optimum "
        "first; time_limit: time_limit_s stopped it first — the answer may then differ on a "
        "retry (a warning says so). The same request gives the same answer unless time_limit.",
    )
    proven: tuple[ProvenPart, ...] = Field(
        (),
        description="The parts of the answer that carry a proof: order (the stops' order is "
        "the optimum of the round trip) — also when charges or reloads were placed after it.",
    )
    replay: Replay | None = Field(
        None,
        description="The work the searches did: sent back as the request's replay, the same "
        "answer to the byte but for runtime_s (null in a fleet's routes: the fleet's is in "
        "its solver).",
    )


@dataclass(frozen=True)
class PlanResult:
    """The solved and simulated round, and the itinerary it drove (its charges as planned, the
    opening hours from its departure)."""

    tour: list[str]
    legs: list[LegResult]
    stops: list[StopResult]
    distance_m: float
    duration_s: float
    energy_kwh: dict[str, float]
    energy_share: dict[str, float]
    battery: BatteryVerdict
    battery_loss_kwh: float
    grid_kwh: float
    first_infeasible_leg: int | None
    max_box_temperature_c: float | None
    minutes_above_product_limit: float | None
    product_limit_c: float
    weather: Weather
    weather_days: list[DayWeather]
    weather_source: WeatherSource
    warnings: list[str]
    timezone: str
    distance_source: DistanceSource
    depot_snap_distance_m: float | None
    solved: Solved
    objective: Objective
    profile: DayProfile
    late_stops: list[str]
    itinerary: Itinerary
    charges: list[ChargeResult] = field(default_factory=list)
    reloads: list[ReloadResult] = field(default_factory=list)
    breaks: list[BreakResult] = field(default_factory=list)
    visits: list[VisitResult] = field(default_factory=list)
    cold_chain: ColdChainResult | None = None
    refrigeration: RefrigerationResult | None = None


UnassignedReason = Literal[
    "time_window", "capacity", "battery", "shift", "unreachable", "time_limit"
]


class Unassigned(Result):
    """A stop no van serves."""

    id: str = Field(..., description="The stop's id.")
    reason: UnassignedReason = Field(
        ...,
        description="time_window (no van reaches it inside a window), capacity (no payload "
        "left or too heavy), battery (the charge would fall below a reserve), shift (no van "
        "back in time), unreachable (no road) or time_limit (the search ran out of time before "
        "it placed the stop; it may fit with more work: work_s or a longer time_limit_s).",
    )
    detail: str = Field(..., description="Why, in a sentence.")


@dataclass(frozen=True)
class FleetRoute:
    """The simulated day of one van that drives."""

    vehicle_id: str
    plan: PlanResult


#: How a fleet's search ended: routes that hold, or none that serves a stop.
FleetStatus = Literal["feasible", "no_solution"]


@dataclass(frozen=True)
class FleetResult:
    """The fleet's plan for the day.

    Attributes
    ----------
    routes
        One simulated day per van that drives, in the order of the request's vans.
    unassigned
        The stops no van serves, each with its reason.
    distance_m, duration_s
        Over every route: driven distance [m] and time from each departure to its return [s].
    energy_kwh
        Energy per consumer and ``total`` over every route [kWh].
    grid_kwh
        Pre-conditioning on grid power at the depot, over every route [kWh].
    vehicles_used
        Vans that drive.
    objective, objective_value
        What the solver minimised, and its value over the routes (m, s or Wh, estimated).
    runtime_s, verification_rounds
        The whole time taken [s], and how often the fleet was verified by simulation (and
        re-solved after a failed verification).
    stopped_by
        How the searches stopped: their work done, or cut short by the time limit.
    replay
        The work the searches did, to do it again (:class:`Replay`).
    timezone, distance_source, warnings
        As in a round's result.
    """

    routes: list[FleetRoute]
    unassigned: list[Unassigned]
    distance_m: float
    duration_s: float
    energy_kwh: dict[str, float]
    grid_kwh: float
    vehicles_used: int
    objective: Objective
    objective_value: float
    runtime_s: float
    verification_rounds: int
    timezone: str
    distance_source: DistanceSource
    warnings: list[str]
    stopped_by: SearchEnd = "work"
    replay: Replay | None = None

    @property
    def status(self) -> FleetStatus:
        """``feasible``: routes that hold (a fleet's search proves nothing); ``no_solution``:
        stops were asked for and no route serves any."""
        served = any(route.plan.stops for route in self.routes)
        return "feasible" if served or not self.unassigned else "no_solution"
