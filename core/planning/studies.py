"""What-if studies of the paper's section 4: best constant speed (Fig. 11), seasons × drivers ×
traffic over one round (Figs. 9, 10) and the energy over the day (Fig. 8, ``PlanResult.profile``).
"""

from __future__ import annotations

import datetime as dt
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from pydantic import Field

from core.exceptions import CoreError, InvalidParameterError, TooMuchToWaitForError
from core.params import (
    AGGRESSIVE_DRIVER,
    CALM_DRIVER,
    NORMAL_DRIVER,
    STREET_TYPES,
    IsoDate,
    Location,
    Params,
    Result,
    RoadMatrix,
    StreetType,
    VanParams,
    Weather,
)
from core.physics.cycles import generate_leg
from core.physics.simulate import CONSUMERS, MAX_SPEED_MPS, simulate
from core.physics.weather import WeatherService
from core.planning.model import PlanProblem, PlanResult
from core.planning.round.planner import plan, round_start
from core.routing.roads import RememberingRouter, RoadRouter

#: Shortest swept trip [m]: shorter ones are all ramp and say nothing about a cruising speed.
MIN_SWEEP_DISTANCE_M = 100.0
#: Street type whose wave shape a swept speed borrows when the driver is not passive.
SWEEP_SHAPE = "highway"


class SpeedPoint(Result):
    """One speed of the sweep."""

    speed_kmh: float = Field(..., description="The trip's mean speed [km/h].")
    energy_wh_per_km: dict[str, float] = Field(
        ..., description="Energy per km of each consumer and the total at that speed [Wh/km]."
    )


@dataclass(frozen=True)
class SpeedSweep:
    """A sweep and its optimum (the speed with the lowest total energy per km)."""

    points: list[SpeedPoint]
    optimum_speed_kmh: float


def sweep_street(speed_kmh: float) -> StreetType:
    """The street a swept speed is driven on: the highway's waves around it, narrowed near the
    top speed so that the fastest swing stays within the simulator's 250 km/h (a driver at
    200 km/h does not swing by ±30 %)."""
    shape = STREET_TYPES[SWEEP_SHAPE]
    mean_speed_mps = speed_kmh / 3.6
    return StreetType(
        mean_speed_mps=mean_speed_mps,
        speed_variation=min(shape.speed_variation, MAX_SPEED_MPS / mean_speed_mps - 1),
        period_divisor=shape.period_divisor,
        traffic_density=shape.traffic_density,
    )


@dataclass(frozen=True)
class SweepTrips:
    """The trips of a speed sweep: each starts and ends at rest and covers ``distance_m``
    [m], at least :data:`MIN_SWEEP_DISTANCE_M`. A passive driver (``driver_aggressiveness`` 0,
    the paper's Fig. 10/11 setting) holds the speed; otherwise the speed swings in the highway
    street type's trapezoid waves around it (paper §2.2), denser with more traffic
    (``traffic_density`` ε_t; None: the street type's)."""

    distance_m: float
    driver_aggressiveness: float = 0.0
    traffic_density: float | None = None


def speed_sweep(
    speeds_kmh: Sequence[float],
    trips: SweepTrips,
    start: dt.datetime,
    location: Location,
    van: VanParams,
    weather: Weather | None = None,
) -> SpeedSweep:
    """Energy per km of flat trips at each mean speed (paper Fig. 11).

    Parameters
    ----------
    speeds_kmh
        Mean speeds [km/h], each 1–200.
    trips
        Their length, driver and traffic.
    start, location, van, weather
        As for :func:`core.physics.simulate.simulate`.
    """
    distance_m = trips.distance_m
    if not speeds_kmh:
        raise InvalidParameterError("speeds_kmh must hold at least one speed", "speeds_kmh")
    if not distance_m >= MIN_SWEEP_DISTANCE_M:
        raise InvalidParameterError(
            f"distance_m must be at least {MIN_SWEEP_DISTANCE_M:g} m, got {distance_m}",
            "distance_m",
        )
    points = []
    for index, speed_kmh in enumerate(speeds_kmh):
        if not 1 <= speed_kmh <= 200:
            raise InvalidParameterError(
                f"speeds_kmh[{index}] = {speed_kmh} must be within 1–200 km/h",
                f"speeds_kmh[{index}]",
            )
        trace = generate_leg(
            distance_m,
            sweep_street(speed_kmh),
            trips.driver_aggressiveness,
            van.vehicle.max_acceleration_mps2,
            trips.traffic_density,
        )
        result = simulate(trace, 1.0, start, location, van, weather=weather)
        per_km = {k: v * 1e6 / result.distance_m for k, v in result.energy_kwh.items()}
        points.append(SpeedPoint(speed_kmh=speed_kmh, energy_wh_per_km=per_km))
    best = min(points, key=lambda p: p.energy_wh_per_km["total"])
    return SpeedSweep(points, best.speed_kmh)


class Season(Params):
    """A season of a scenario grid: a day and, optionally, its forecast."""

    name: str = Field(..., min_length=1, max_length=40, description="Label, e.g. 'winter'.")
    date: IsoDate = Field(..., description="The day the round is driven, YYYY-MM-DD.")
    weather: Weather | None = Field(None, description="Forecast; absent: the climatology.")


class ScenarioCell(Result):
    """One cell of the grid."""

    season: str = Field(..., description="The season's name.")
    driver_aggressiveness: float = Field(..., description="ε_d of the cell [–].")
    traffic_density: float | None = Field(
        ..., description="ε_t of the cell [–]; null: each street type's default."
    )
    energy_kwh: dict[str, float] = Field(
        ..., description="Energy of each consumer in this cell [kWh]."
    )
    change_vs_baseline_pct: float = Field(..., description="Total energy against the baseline.")
    feasible: bool = Field(..., description="The battery holds out with its reserve.")


@dataclass(frozen=True)
class ScenarioGrid:
    """A round evaluated over seasons × drivers × traffic, on the baseline's tour."""

    tour: list[str]
    baseline_energy_kwh: dict[str, float]
    cells: list[ScenarioCell]


def default_seasons(year: int) -> list[Season]:
    """Winter (15 January) and summer (15 July) of ``year``, weather from the climatology."""
    return [
        Season(name="winter", date=dt.date(year, 1, 15)),
        Season(name="summer", date=dt.date(year, 7, 15)),
    ]


DEFAULT_DRIVERS = (CALM_DRIVER, NORMAL_DRIVER, AGGRESSIVE_DRIVER)
DEFAULT_TRAFFIC = (0.2, 0.8)


@dataclass(frozen=True)
class GridAxes:
    """The axes of a scenario grid; None takes winter and summer of the round's year
    (:func:`default_seasons`), calm/normal/aggressive drivers (ε_d 0.3, 0.5, 1.0) and
    light/heavy traffic (ε_t 0.2, 0.8)."""

    seasons: Sequence[Season] | None = None
    drivers: Sequence[float] | None = None
    traffic: Sequence[float | None] | None = None


def scenario_grid(
    problem: PlanProblem,
    axes: GridAxes = GridAxes(),
    progress: Callable[[int, int], None] | None = None,
    router: RoadRouter | None = None,
    weather_service: WeatherService | None = None,
    max_simulated_s: float | None = None,
) -> ScenarioGrid:
    """The round of ``problem`` over every combination of season, driver and traffic.

    The tour is solved once for ``problem`` as given (the baseline) and kept for every cell, so
    that cells differ only in their conditions; each cell is a full simulation of that tour
    (the same as planning it with ``keep_order``). ``change_vs_baseline_pct`` compares a cell's
    total energy with the baseline's.

    Parameters
    ----------
    problem
        The round and its baseline conditions.
    axes
        The seasons, drivers and traffic.
    progress
        Called with (cells done, cells in all) after each cell.
    router, weather_service
        As for :func:`core.planning.round.planner.plan`; the router is asked once per leg for the
        whole grid. A season with its own weather keeps it; the others get the service's
        forecast.
    max_simulated_s
        Most time the cells may simulate together [s] (the baseline round's duration times
        the cells); beyond, :class:`core.exceptions.TooMuchToWaitForError`. None: no bound.
    """
    seasons = list(axes.seasons) if axes.seasons is not None else default_seasons(problem.date.year)
    drivers = list(axes.drivers) if axes.drivers is not None else list(DEFAULT_DRIVERS)
    traffic = list(axes.traffic) if axes.traffic is not None else list(DEFAULT_TRAFFIC)
    for name, axis in (
        ("seasons", seasons),
        ("driver_aggressiveness", drivers),
        ("traffic_density", traffic),
    ):
        if not axis:
            raise InvalidParameterError(f"{name} must hold at least one value", name)
    check_seasons(problem, seasons)
    remembering = None if router is None else RememberingRouter(router)
    baseline = plan(problem, remembering, weather_service)
    _check_cells(baseline, len(seasons) * len(drivers) * len(traffic), max_simulated_s)
    by_id = {stop.id: stop for stop in problem.stops}
    fixed = problem.model_copy(
        update={  # the stops in the baseline's order (its tour has the depot and chargers too)
            "stops": [by_id[i] for i in baseline.tour if i in by_id],
            "keep_order": True,
            "matrix": _reordered_matrix(problem, baseline),
        }
    )
    cells = []
    combos = list(itertools.product(seasons, drivers, traffic))
    for done, (season, driver, density) in enumerate(combos, start=1):
        result = plan(
            fixed.model_copy(
                update={
                    "date": season.date,
                    "weather": season.weather,
                    "driver_aggressiveness": driver,
                    "traffic_density": density,
                }
            ),
            remembering,
            weather_service,
        )
        cells.append(_cell(season.name, driver, density, result, baseline))
        if progress is not None:
            progress(done, len(combos))
    return ScenarioGrid(baseline.tour, baseline.energy_kwh, cells)


def _check_cells(baseline: PlanResult, n_cells: int, max_simulated_s: float | None) -> None:
    """Refuse a grid whose cells together simulate more than ``max_simulated_s`` [s]."""
    cells_s = baseline.duration_s * n_cells
    if max_simulated_s is not None and cells_s > max_simulated_s:
        raise TooMuchToWaitForError(
            f"{n_cells} cells of a {baseline.duration_s / 3600:,.1f} h round simulate "
            f"{cells_s / 86_400:,.0f} days; a synchronous study simulates at most "
            f"{max_simulated_s / 86_400:,.0f}: fewer cells, or submit it as a job "
            "(POST /v1/jobs, type scenarios)",
            "seasons",
        )


def check_seasons(problem: PlanProblem, seasons: Sequence[Season]) -> None:
    """Each season's day can be planned at the round's start time in its zone (a clock that
    skips the hour, a day at the end of the calendar): raises naming ``seasons[i].date``."""
    for index, season in enumerate(seasons):
        try:
            round_start(problem.model_copy(update={"date": season.date}))
        except CoreError as error:
            if error.field not in ("date", "start_time"):
                raise  # the round's own (its time zone), not the season's
            raise error.at(f"seasons[{index}].date") from None


def _reordered_matrix(problem: PlanProblem, baseline: PlanResult) -> RoadMatrix | None:
    """The client's matrices in the tour's stop order (None stays None)."""
    if problem.matrix is None:
        return None
    position = {stop.id: index + 1 for index, stop in enumerate(problem.stops)}
    order = [0] + [position[i] for i in baseline.tour[1:-1]]
    m = problem.matrix

    def pick(rows: list[list[float]]) -> list[list[float]]:
        return [[rows[i][j] for j in order] for i in order]

    return m.model_copy(
        update={
            "distances_m": pick(m.distances_m),
            "durations_s": pick(m.durations_s),
            "street_types": None
            if m.street_types is None
            else [[m.street_types[i][j] for j in order] for i in order],
        }
    )


def _cell(
    season: str, driver: float, density: float | None, result: PlanResult, baseline: PlanResult
) -> ScenarioCell:
    base = baseline.energy_kwh["total"]
    return ScenarioCell(
        season=season,
        driver_aggressiveness=driver,
        traffic_density=density,
        energy_kwh={name: result.energy_kwh[name] for name in (*CONSUMERS, "total")},
        change_vs_baseline_pct=(result.energy_kwh["total"] / base - 1) * 100 if base else 0.0,
        feasible=result.battery.feasible,
    )
