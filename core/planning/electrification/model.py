"""The electrification study's request (the routes as driven, the candidate vans, the charges
a day may take) and its answer (per route and candidate: the days covered, the battery that
covers them, the worst days; per candidate: the fleet)."""

from __future__ import annotations

import datetime as dt
from typing import Literal

from pydantic import Field, field_validator, model_validator

from core.params import (
    ClockTime,
    Depot,
    IsoDate,
    Location,
    Params,
    Product,
    Result,
    Stop,
    VanParams,
)

Weekday = Literal["mon", "tue", "wed", "thu", "fri", "sat", "sun"]
WEEKDAYS: tuple[Weekday, ...] = ("mon", "tue", "wed", "thu", "fri", "sat", "sun")
WeatherSourceName = Literal["climatology", "archive"]
#: Most routes, candidates, stops of a route and days of a route a study takes (the server's
#: limit on route-days, ``COLDROUTE_MAX_ROUTE_DAYS``, is its own).
MAX_ROUTES = 1000
MAX_CANDIDATES = 20
MAX_ROUTE_STOPS = 500
MAX_DAYS = 366


class Weekdays(Params):
    """Every date of the year on these days of the week."""

    weekdays: list[Weekday] = Field(
        ..., min_length=1, max_length=7, description="Days of the week: mon, tue, … sun."
    )

    @field_validator("weekdays")
    @classmethod
    def _once_each(cls, value: list[Weekday]) -> list[Weekday]:
        if len(set(value)) != len(value):
            raise ValueError("each day of the week at most once")
        return value


class DrivenDay(Params):
    """One day of a route as it was driven: its own stops, in the order driven, from its own
    departure (a telematics export's day)."""

    date: IsoDate = Field(..., description="The date, YYYY-MM-DD in the study's year.")
    start_time: ClockTime = Field(..., description="Departure from the depot, local HH:MM.")
    stops: list[Stop] = Field(
        ...,
        min_length=1,
        max_length=MAX_ROUTE_STOPS,
        description="The stops that day, in the order driven, as in /v1/plans.",
    )


Days = list[dt.date] | Weekdays | list[DrivenDay]


class DrivenRoute(Params):
    """One route as the fleet drives it: its stops in the order driven, from its start time,
    on the days it is driven."""

    id: str = Field(..., min_length=1, max_length=64, description="The route's id, unique.")
    depot: Depot = Field(..., description="Where it starts and ends.")
    stops: list[Stop] | None = Field(
        None,
        min_length=1,
        max_length=MAX_ROUTE_STOPS,
        description="The stops in the order driven, as in /v1/plans (their windows aside: the "
        "route is driven as it was); needed unless each day gives its own.",
    )
    start_time: ClockTime | None = Field(
        None,
        description="Departure from the depot, local HH:MM; needed unless each day gives its own.",
    )
    product: Product | None = Field(
        None,
        description="The goods it carries (a class or a band, as a cargo box's product): each "
        "candidate's box carries them, at its own set-point when that is inside their band, "
        "else at the band's middle. Absent: each candidate's box as it is.",
    )
    days: list[IsoDate] | Weekdays | list[DrivenDay] = Field(
        ...,
        description="The dates it is driven (YYYY-MM-DD in the study's year, in order, each "
        'once), {"weekdays": ["mon", …]}: every such day of the year, or the days as driven, '
        "each with its own start_time and stops.",
    )

    @field_validator("days")
    @classmethod
    def _in_order(cls, value: Days) -> Days:
        if isinstance(value, list):
            if not value or len(value) > MAX_DAYS:
                raise ValueError(f"between 1 and {MAX_DAYS} dates")
            dates = [d.date if isinstance(d, DrivenDay) else d for d in value]
            for k in range(1, len(dates)):
                if dates[k] <= dates[k - 1]:
                    raise ValueError(f"days[{k}] ({dates[k]}) is not after days[{k - 1}]")
        return value

    @model_validator(mode="after")
    def _each_day_has_its_stops(self) -> DrivenRoute:
        own = isinstance(self.days, list) and isinstance(self.days[0], DrivenDay)
        if not own and (self.stops is None or self.start_time is None):
            raise ValueError("stops and start_time are needed unless each day gives its own")
        return self


class Candidate(Params):
    """A van the routes might be driven with: its vehicle, battery and box."""

    id: str = Field(..., min_length=1, max_length=64, description="The candidate's id, unique.")
    van: VanParams = Field(..., description="The van, as in a plan.")


class ChargeOption(Params):
    """A charge a day may take: at the depot at lunch, or on the way — at most ``minutes`` at a
    charger of ``power_kw``, along the van's charging curve from its reserve (capped by the
    charger and the van, at its efficiency: :func:`core.physics.charging.charge_curve`)."""

    where: Literal["depot", "on_the_way"] = Field(
        ..., description="At the depot (back at lunch) or at a charger on the way."
    )
    power_kw: float = Field(..., ge=1, le=1000, description="The charger's power [kW].")
    minutes: float = Field(
        ..., ge=1, le=600, description="The longest charge a day allows there [min], at least 1."
    )


class StudyFields(Params):
    """What a study's request and its core problem share: the year, the zone, the routes as
    driven, the place of the climate, the charges a day may take, whether every day is listed."""

    year: int = Field(..., ge=1901, le=2199, description="The year studied.")
    timezone: str | None = Field(
        None,
        max_length=64,
        description="IANA zone of the routes' clocks; null: from the depot's longitude.",
    )
    routes: list[DrivenRoute] = Field(
        ..., min_length=1, max_length=MAX_ROUTES, description="The routes, as driven."
    )
    location: Location | None = Field(
        None, description="The place whose climate each date's weather is; null: each depot's."
    )
    chargers: list[ChargeOption] = Field(
        default_factory=list,
        max_length=10,
        description="The charges a day may take, together (at the depot at lunch, on the way); "
        "empty: a day is covered on one charge alone.",
    )
    include_days: bool = Field(
        False,
        description="Every route-day's figures in the answer (candidates[].days[]: the viewer's "
        "heat map and coverage curve).",
    )


class ElectrificationProblem(StudyFields):
    """The fleet's routes over a year and the vans they might be driven with."""

    candidates: list[Candidate] = Field(
        ..., min_length=1, max_length=MAX_CANDIDATES, description="The vans to try."
    )
    weather_source: WeatherSourceName = Field(
        "climatology",
        description="climatology: each date's typical day at the place; archive: the weather "
        "service's hourly archive of the year (the climatology, said in the answer, where "
        "none is configured or it fails).",
    )


Reason = Literal["heat", "cold", "distance"]


class WorstDay(Result):
    """A day the battery ran lowest, and what made it so."""

    date: dt.date = Field(..., description="The date.")
    reason: Reason = Field(
        ...,
        description="heat or cold (the cab's and the unit's energy above the route's median "
        "day, on a warmer or a colder day), or distance (the day's drives take more above the "
        "median day's than the weather does, or even the mildest day falls short).",
    )
    min_soc: float = Field(..., description="Lowest state of charge [–]; negative: empty.")
    required_kwh: float = Field(
        ..., description="Smallest usable capacity that keeps the reserve that day [kWh]."
    )
    t_min_c: float = Field(..., description="Coldest moment of the route's day [°C].")
    t_max_c: float = Field(..., description="Warmest moment of the route's day [°C].")
    detail: str = Field(..., description="The figures behind the reason, in a sentence.")


class DaySummary(Result):
    """One day of one candidate on one route."""

    date: dt.date = Field(..., description="The date.")
    min_soc: float = Field(..., description="Lowest state of charge [–]; negative: empty.")
    margin_kwh: float = Field(
        ..., description="Energy above the reserve at the lowest point [kWh]; negative: lacking."
    )
    required_kwh: float = Field(
        ..., description="Smallest usable capacity that keeps the reserve that day [kWh]."
    )
    energy_kwh: float = Field(..., description="The day's energy, the battery's loss in [kWh].")
    covered_with_charging: bool = Field(
        ..., description="Covered on one charge, or with the chargers' charges."
    )
    cold_chain_holds: bool = Field(..., description="The goods stayed in their band.")


class CandidateOutcome(Result):
    """One candidate on one route over its days."""

    id: str = Field(..., description="The candidate's id.")
    days_total: int = Field(..., description="Days the route is driven.")
    days_feasible: int = Field(..., description="Days the battery keeps its reserve all day.")
    share_feasible: float = Field(..., description="days_feasible / days_total [–].")
    days_feasible_with_charging: int | None = Field(
        ..., description="Days covered with the chargers' charges; null: no charger given."
    )
    share_feasible_with_charging: float | None = Field(
        ..., description="days_feasible_with_charging / days_total [–]; null: no charger."
    )
    required_kwh_p95: float = Field(
        ..., description="Smallest usable capacity that covers 95 % of the days [kWh]."
    )
    required_kwh_max: float = Field(
        ..., description="Smallest usable capacity that covers every day [kWh]."
    )
    lacking_kwh_max: float = Field(
        ..., description="Most charge a day lacks to keep its reserve [kWh] (0: none lacks)."
    )
    energy_kwh_mean: dict[str, float] = Field(
        ...,
        description="Mean energy of a day per consumer, the battery's temperature loss "
        "(battery_loss) and the total [kWh].",
    )
    cold_chain_days_broken: int = Field(
        ..., description="Days the goods left their band (0 without a product)."
    )
    worst_days: list[WorstDay] = Field(..., description="The days it ran lowest, lowest first.")
    days: list[DaySummary] | None = Field(
        None, description="Every day, in date order, when include_days asks; else null."
    )


class RouteOutcome(Result):
    """One route, each candidate."""

    id: str = Field(..., description="The route's id.")
    distance_km: float = Field(..., description="A day's distance [km].")
    candidates: list[CandidateOutcome] = Field(..., description="Each candidate, as asked.")


class FleetOutcome(Result):
    """One candidate across the fleet."""

    id: str = Field(..., description="The candidate's id.")
    routes_all_year: int = Field(..., description="Routes it covers on every day driven.")
    routes_p95: int = Field(..., description="Routes it covers on at least 95 % of the days.")
    routes_all_year_with_charging: int | None = Field(
        ..., description="Routes covered every day with the chargers; null: no charger given."
    )
    depot_kwh_max_day: float = Field(
        ...,
        description="Most energy from the grid on one date to recharge the vans that drove "
        "that day on one charge back to full at the depot [kWh].",
    )
    depot_kw_peak: float = Field(
        ...,
        description="Its power when each van charges evenly while parked until the same time "
        "the next day [kW]: the depot's chargers must supply at least this.",
    )


class ElectrificationResult(Result):
    """The study's answer."""

    routes: list[RouteOutcome] = Field(..., description="Each route, as asked.")
    fleet: list[FleetOutcome] = Field(..., description="Each candidate across the routes.")
    route_days: int = Field(..., description="Route-days studied (each for every candidate).")
    route_days_per_s: float = Field(
        ..., description="Route-days × candidates simulated per second of the study."
    )
    runtime_s: float = Field(..., description="How long the study took [s].")
    weather_source: WeatherSourceName = Field(
        ...,
        description="Where each date's weather came from: climatology (the place's typical "
        "day of that date) or archive (the weather service's hours of the year).",
    )
    warnings: list[str] = Field(
        default_factory=list, description="What the answer must say of itself (the weather)."
    )
