"""POST /v1/studies/*: the speed sweep and the scenario grid."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from app.schemas.base import ApiModel, ConsumptionWhPerKm, EnergyKwh, VanRequest
from app.schemas.plans import PlanRequest
from core.params import (
    ClockTime,
    IsoDate,
    Location,
    RefrigerationStrategy,
    TrafficDensity,
    Weather,
    clock_field,
)
from core.planning.electrification.model import (
    MAX_CANDIDATES,
    ElectrificationResult,
    StudyFields,
)
from core.planning.studies import ScenarioCell, Season, SpeedPoint


class SpeedSweepRequest(VanRequest):
    """Constant-speed trips on a flat road at several speeds (paper Fig. 11)."""

    speeds_kmh: list[Annotated[float, Field(ge=1, le=200)]] = Field(
        default_factory=lambda: [float(v) for v in range(20, 121, 10)],
        min_length=1,
        max_length=100,
        description="Mean speeds to try [km/h], each 1–200. A driver who is not passive "
        "swings around each speed in the highway's waves, narrower near 200 km/h so that no "
        "swing exceeds 250 km/h.",
    )
    distance_m: float = Field(
        20_000.0, ge=100, le=500_000, description="Trip length [m], at least 100 m."
    )
    date: IsoDate = Field(..., description="Day of the trips, YYYY-MM-DD.")
    start_time: ClockTime = clock_field("12:00", "Departure, local HH:MM.")
    timezone: str | None = Field(
        None, max_length=64, description="IANA time zone; absent: local mean solar time."
    )
    location: Location = Field(..., description="Where (sun, climatology).")
    weather: Weather | None = Field(
        None, description="The day's forecast; absent: the climatology for date and latitude."
    )
    traffic_density: TrafficDensity | None = Field(None, description="ε_t [–], 0.01–0.99.")
    driver_aggressiveness: float = Field(
        0.0, ge=0, le=1, description="ε_d [–]; 0 holds each speed exactly (paper Fig. 11)."
    )


class SpeedPointOut(ApiModel, SpeedPoint):
    """One speed of the sweep."""

    energy_wh_per_km: ConsumptionWhPerKm = Field(  # type: ignore[assignment]
        ..., description="Energy per km of each consumer at that speed [Wh/km]."
    )


class SpeedSweepResponse(ApiModel):
    """Energy per km at each speed, and the speed with the lowest total."""

    points: list[SpeedPointOut] = Field(
        ..., description="One point per requested speed, in request order."
    )
    optimum_speed_kmh: float = Field(
        ..., description="The speed with the lowest total energy per km [km/h]."
    )


class ScenariosRequest(ApiModel):
    """One round over seasons × driver aggressiveness × traffic density (paper Figs. 9, 10)."""

    plan: PlanRequest = Field(..., description="The round and its baseline conditions.")
    seasons: list[Season] | None = Field(
        None,
        min_length=1,
        max_length=12,
        description="Absent: winter (15 Jan) and summer (15 Jul) of the plan's year.",
    )
    driver_aggressiveness: list[Annotated[float, Field(ge=0, le=1)]] | None = Field(
        None,
        min_length=1,
        max_length=10,
        description="ε_d values [–]; absent: calm 0.3, normal 0.5, aggressive 1.0.",
    )
    traffic_density: list[TrafficDensity] | None = Field(
        None,
        min_length=1,
        max_length=10,
        description="ε_t values [–]; absent: light 0.2, heavy 0.8.",
    )


class ScenarioCellOut(ApiModel, ScenarioCell):
    """One cell of the grid."""

    energy_kwh: EnergyKwh = Field(  # type: ignore[assignment]
        ..., description="Energy of each consumer in this cell [kWh]."
    )


class ScenariosResponse(ApiModel):
    """The grid, one row per cell, on the baseline's tour."""

    tour: list[str] = Field(
        ..., description="The baseline's tour, driven in every cell: ids, depot first and last."
    )
    baseline_energy_kwh: EnergyKwh = Field(
        ..., description="Energy of the round in its own conditions [kWh]."
    )
    cells: list[ScenarioCellOut] = Field(
        ..., description="One row per season × driver × traffic combination."
    )


class CandidateRequest(VanRequest):
    """A van the routes might be driven with, as in a plan: a preset or profile and the
    parameters to change (its battery, its box, its refrigeration strategy)."""

    id: str = Field(..., min_length=1, max_length=64, description="The candidate's id, unique.")


class StudyWeather(ApiModel):
    """Where each date's weather comes from."""

    source: Literal["climatology", "archive"] = Field(
        "climatology",
        description="climatology: the typical day of each date at the place (the depot's, or "
        "location); archive: the configured weather service's hours of the year "
        "(COLDROUTE_WEATHER_URL / COLDROUTE_WEATHER_ARCHIVE_URL; the climatology, said in "
        "the answer's warnings, where none is configured or it fails).",
    )


class ElectrificationRequest(ApiModel, StudyFields):
    """The fleet's routes as driven over a year, and the vans they might be driven with."""

    candidates: list[CandidateRequest] = Field(
        ..., min_length=1, max_length=MAX_CANDIDATES, description="The vans to try."
    )
    refrigeration: RefrigerationStrategy | None = Field(
        None,
        description="The refrigeration unit's strategy for each candidate that does not say "
        "its own; absent: each candidate's (the thermostat by default).",
    )
    weather: StudyWeather = Field(
        default_factory=StudyWeather, description="Where each date's weather comes from."
    )


class ElectrificationResponse(ApiModel, ElectrificationResult):
    """Per route and candidate, the days covered and the battery that covers them; per
    candidate, the fleet."""
