"""``make report``: reproduce the paper's Figs. 8–11 and its claims as docs/paper-reproduction.md.

Runs the studies of :mod:`core.planning.studies` on the paper's Table 1 van (preset
``paper-generic``) and, beside it, the real 3.5 t van (``ev-van-3.5t-reefer``), on an 8-stop
Vienna round starting at 09:00 (Fig. 8); draws the charts with matplotlib and writes a Markdown
page with each claim of the paper beside our numbers, and the winter share of auxiliaries and
comfort with the cab HVAC on and off at stops.
"""

from __future__ import annotations

import argparse
import copy
import datetime as dt
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from matplotlib import dates as mdates
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from tqdm import tqdm

from app.examples import PLAN_EXAMPLE
from app.operations.plan import plan_problem
from app.schemas.plans import PlanRequest
from app.settings import get_settings
from core.clock import departure
from core.params import (
    AGGRESSIVE_DRIVER,
    CALM_DRIVER,
    NORMAL_DRIVER,
    PRESETS,
    STREET_TYPES,
    Location,
    Weather,
)
from core.physics.cycles import generate_leg
from core.physics.simulate import CONSUMERS, simulate
from core.planning.model import PlanProblem, PlanResult
from core.planning.round.planner import plan
from core.planning.studies import GridAxes, Season, SweepTrips, scenario_grid, speed_sweep

COLORS = {
    "traction": "#4c72b0",
    "auxiliaries": "#8c8c8c",
    "cabin": "#dd8452",
    "refrigeration": "#55a868",
    "total": "#222222",
}
LABELS = {
    "traction": "traction",
    "auxiliaries": "auxiliaries",
    "cabin": "cab HVAC",
    "refrigeration": "refrigeration unit",
    "total": "total",
}
WINTER = Season(name="winter", date=dt.date(2026, 1, 15), weather=Weather(t_min_c=-10, t_max_c=-2))
SUMMER = Season(name="summer", date=dt.date(2026, 7, 15), weather=Weather(t_min_c=18, t_max_c=31))
VIENNA = Location(lat=48.21, lon=16.37)


PAPER_VAN = "paper-generic"
REAL_VAN = "ev-van-3.5t-reefer"


@dataclass(frozen=True)
class Claim:
    """One of the paper's statements beside our figures for both vans."""

    claim: str
    paper: str
    ours: str
    real_van: str
    agrees: bool
    why: str


def _round(
    season: Season,
    driver: float = NORMAL_DRIVER,
    preset: str = PAPER_VAN,
    cab_at_stops: str | None = None,
) -> PlanProblem:
    """A van on the 8-stop Vienna round, 09:00, in a season."""
    body: dict[str, Any] = copy.deepcopy(PLAN_EXAMPLE)
    vehicle: dict[str, Any] = {"preset": preset}
    if cab_at_stops is not None:
        vehicle["cab_hvac_at_stops"] = cab_at_stops
    body.update(
        date=season.date.isoformat(),
        start_time="09:00",
        objective="distance",
        vehicle=vehicle,
        driver_aggressiveness=driver,
        weather=season.weather.model_dump() if season.weather else None,
    )
    body.pop("battery", None)
    body.pop("payload_kg", None)
    return plan_problem(PlanRequest.model_validate(body), get_settings())


@dataclass(frozen=True)
class VanStudy:
    """What the claims need of one van."""

    grid: dict[tuple[str, float], dict[str, float]]
    winter_round: PlanResult
    urban_leg_extra_pct: float


def figure_8(out: Path, summer: PlanResult) -> Path:
    fig, ax = _figure()
    for name in (*CONSUMERS, "total"):
        ax.plot(
            mdates.date2num(summer.profile.time),  # type: ignore[no-untyped-call]
            summer.profile.energy_kwh[name],
            color=COLORS[name],
            label=LABELS[name],
            linewidth=2.2 if name == "total" else 1.6,
        )
    ax.set_xlabel("time of day (Europe/Vienna)")
    ax.set_ylabel("energy since departure [kWh]")
    ax.set_title("Fig. 8 — energy over a summer delivery round (8 stops, 09:00 start)")
    clock = mdates.DateFormatter("%H:%M", tz=summer.profile.time[0].tzinfo)  # type: ignore[no-untyped-call]
    ax.xaxis.set_major_formatter(clock)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    return _save(fig, out / "fig8-day-profile.png")


def figure_9(
    out: Path, grid: dict[tuple[str, float], dict[str, float]], drivers: list[tuple[str, float]]
) -> Path:
    fig, ax = _figure()
    labels, bottoms = [], {}
    for season in ("winter", "summer"):
        for driver_name, _ in drivers:
            labels.append(f"{season}\n{driver_name}")
            bottoms[len(labels) - 1] = 0.0
    for name in CONSUMERS:
        values = [
            grid[(season, driver)][name] for season in ("winter", "summer") for _, driver in drivers
        ]
        ax.bar(
            labels,
            values,
            bottom=[bottoms[i] for i in range(len(values))],
            color=COLORS[name],
            label=LABELS[name],
        )
        for i, value in enumerate(values):
            bottoms[i] += value
    ax.set_ylabel("energy of the round [kWh]")
    ax.set_ylim(0, max(bottoms.values()) * 1.08)
    ax.set_title("Fig. 9 — seasons and driver aggressiveness (same 8-stop round)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    return _save(fig, out / "fig9-seasons-drivers.png")


def figure_10(out: Path, rows: list[tuple[str, dict[str, float]]]) -> Path:
    fig, ax = _figure()
    labels = [label for label, _ in rows]
    bottom = [0.0] * len(rows)
    for name in CONSUMERS:
        values = [energy[name] for _, energy in rows]
        ax.bar(labels, values, bottom=bottom, color=COLORS[name], label=LABELS[name])
        bottom = [b + v for b, v in zip(bottom, values, strict=True)]
    ax.set_ylabel("energy per distance [Wh/km]")
    ax.set_ylim(0, max(bottom) * 1.08)
    ax.set_title("Fig. 10 — 80 km/h highway trip: free flow vs dense traffic")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    return _save(fig, out / "fig10-traffic.png")


def figure_11(out: Path, sweep: Any) -> Path:
    fig, ax = _figure()
    speeds = [p.speed_kmh for p in sweep.points]
    for name in (*CONSUMERS, "total"):
        ax.plot(
            speeds,
            [p.energy_wh_per_km[name] for p in sweep.points],
            marker="o",
            color=COLORS[name],
            label=LABELS[name],
            linewidth=2.2 if name == "total" else 1.4,
        )
    ax.axvline(
        sweep.optimum_speed_kmh,
        color="#c44e52",
        linestyle="--",
        label=f"optimum {sweep.optimum_speed_kmh:.0f} km/h",
    )
    ax.set_xlabel("constant speed [km/h]")
    ax.set_ylabel("energy per distance [Wh/km]")
    ax.set_title("Fig. 11 — best constant speed with the cooling unit on (hot day, flat road)")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=8)
    return _save(fig, out / "fig11-speed-sweep.png")


def _urban_leg_extra_pct(preset: str) -> float:
    """Aggressive against calm driver on a 10 km urban leg in average traffic, hot day [%]:
    the physics of the acceleration and braking the street type's waves ask for."""
    van = PRESETS[preset].van()
    start, _ = departure(SUMMER.date, dt.time(12), "Europe/Vienna", VIENNA.lon)
    total = {}
    for driver in (CALM_DRIVER, AGGRESSIVE_DRIVER):
        trace = generate_leg(
            10_000, STREET_TYPES["urban"], driver, van.vehicle.max_acceleration_mps2, 0.5
        )
        total[driver] = simulate(trace, 1.0, start, VIENNA, van, weather=SUMMER.weather).energy_kwh[
            "total"
        ]
    return (total[AGGRESSIVE_DRIVER] / total[CALM_DRIVER] - 1) * 100


def _figure() -> tuple[Figure, Axes]:
    """A figure drawn off-screen (no pyplot, no display backend needed)."""
    fig = Figure(figsize=(8, 4.5))
    return fig, fig.subplots()


def _save(fig: Figure, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def _share(energy: dict[str, float]) -> float:
    """Auxiliaries and cab comfort as a share of the total [%] (the paper's §4 measure)."""
    return (energy["auxiliaries"] + energy["cabin"]) / energy["total"] * 100


def _driving(result: PlanResult) -> dict[str, float]:
    """Energy of the legs only, stops left out [kWh]."""
    return {
        name: sum(leg.energy_kwh[name] for leg in result.legs) for name in (*CONSUMERS, "total")
    }


def study(preset: str, drivers: list[float], progress: Any = None) -> VanStudy:
    """The seasons × drivers grid, the winter round and the urban leg of one van."""
    grid_result = scenario_grid(
        _round(SUMMER, preset=preset), GridAxes([WINTER, SUMMER], drivers, [None]), progress
    )
    return VanStudy(
        grid={(c.season, c.driver_aggressiveness): c.energy_kwh for c in grid_result.cells},
        winter_round=plan(_round(WINTER, preset=preset)),
        urban_leg_extra_pct=_urban_leg_extra_pct(preset),
    )


def claims(paper: VanStudy, real: VanStudy, optimum_kmh: float) -> list[Claim]:
    """The paper's §4 statements beside ours, for the paper's van and the real one."""

    def share_text(van: VanStudy) -> str:
        winter = van.grid[("winter", NORMAL_DRIVER)]
        return f"{_share(winter):.1f} % (legs only: {_share(_driving(van.winter_round)):.1f} %)"

    def driver_text(van: VanStudy) -> str:
        calm = van.grid[("summer", CALM_DRIVER)]["total"]
        aggressive = van.grid[("summer", AGGRESSIVE_DRIVER)]["total"]
        return (
            f"{(aggressive / calm - 1) * 100:+.1f} % on the round, "
            f"{van.urban_leg_extra_pct:+.1f} % on a 10 km urban leg"
        )

    def heating_text(van: VanStudy) -> tuple[str, bool]:
        winter, summer = van.grid[("winter", NORMAL_DRIVER)], van.grid[("summer", NORMAL_DRIVER)]
        heating = winter["cabin"] + winter["refrigeration"]
        cooling = summer["cabin"] + summer["refrigeration"]
        return f"{heating:.2f} kWh vs {cooling:.2f} kWh", heating > cooling

    winter = paper.grid[("winter", NORMAL_DRIVER)]
    round_h = paper.winter_round.duration_s / 3600
    standing_h = (
        sum((s.departure - s.arrival).total_seconds() for s in paper.winter_round.stops) / 3600
    )
    paper_heating, paper_heats_more = heating_text(paper)
    return [
        Claim(
            "Auxiliaries and comfort share of the energy in winter",
            "12–18 %",
            share_text(paper),
            share_text(real),
            12 <= _share(winter) <= 18,
            "Table 2 heats the cab with 2.6–3.2 kW at −10…−2 °C for the whole "
            f"{round_h:.1f} h round, {standing_h:.1f} h of it at stops, against "
            f"{winter['traction']:.1f} kWh of traction for "
            f"{paper.winter_round.distance_m / 1000:.0f} km of city driving. See the table "
            "below: the paper's 12–18 % needs far more driving per hour of heating than a "
            "delivery round has, whether the heater runs at stops or not.",
        ),
        Claim(
            "Aggressive driver against a calm one",
            "+10–12 %",
            driver_text(paper),
            driver_text(real),
            10 <= paper.urban_leg_extra_pct <= 12,
            f"ε_d {CALM_DRIVER} (calm, 0.6 m/s²) and {AGGRESSIVE_DRIVER} (aggressive, 2 m/s²) "
            "on the same street-type waves (paper §2.2). The extra is mostly braking: the "
            "motor regenerates down to 0.1 g (`max_regen_deceleration_mps2`), so the calm "
            "driver's braking all comes back as charge at 0.6, while the aggressive driver "
            "brakes harder and the friction brakes turn the rest into heat; the rest of the "
            "extra is the longer time at the waves' top speed, against the drag. With every "
            "braking regenerated (the first release) the same comparison gave +6 %; its +10 % "
            "was against ε_d 0.2, a driver gentler than economical driving. Over the whole round "
            "the energy that does not depend on driving style (stops, refrigeration, cab) "
            "dilutes it.",
        ),
        Claim(
            "Heating in winter costs more than cooling in summer",
            "yes",
            paper_heating,
            heating_text(real)[0],
            paper_heats_more,
            "Cab heating at −10…−2 °C (Table 2) outweighs cab cooling plus the refrigeration "
            "unit at 18…31 °C. The real van's box conducts a fifth of the paper's, so its "
            "refrigeration is small either way.",
        ),
        Claim(
            "Best constant speed with the cooling unit",
            "≈ 40 km/h",
            f"{optimum_kmh:.0f} km/h",
            "—",
            30 <= optimum_kmh <= 50,
            "Constant loads (auxiliaries, cab, refrigeration) per km fall with speed, drag "
            "rises with its square: their sum is flattest near 40 km/h.",
        ),
    ]


@dataclass(frozen=True)
class ShareRow:
    """The winter share of one van with one cab duty at stops."""

    van: str
    cab_at_stops: str
    share_pct: float
    driving_share_pct: float
    cabin_kwh: float
    total_kwh: float


def winter_shares() -> list[ShareRow]:
    """Winter auxiliaries + comfort share with the cab HVAC on and off at stops, both vans."""
    rows = []
    for preset in (PAPER_VAN, REAL_VAN):
        for duty in ("on", "off"):
            result = plan(_round(WINTER, preset=preset, cab_at_stops=duty))
            rows.append(
                ShareRow(
                    preset,
                    duty,
                    _share(result.energy_kwh),
                    _share(_driving(result)),
                    result.energy_kwh["cabin"],
                    result.energy_kwh["total"],
                )
            )
    return rows


def speed_for_share(result: PlanResult, share: float) -> float:
    """Mean driving speed [km/h] at which the round's auxiliaries + cab power would be
    ``share`` of the total, at the round's traction per km (refrigeration left out: winter)."""
    hours = result.duration_s / 3600
    comfort_kw = (result.energy_kwh["auxiliaries"] + result.energy_kwh["cabin"]) / hours
    traction_kwh_per_km = result.energy_kwh["traction"] / (result.distance_m / 1000)
    return comfort_kw * (1 / share - 1) / traction_kwh_per_km


def write_page(
    out: Path,
    figures: list[Path],
    rows: list[Claim],
    shares: list[ShareRow],
    needed_kmh: float,
    quick: bool,
) -> Path:
    lines = [
        "# Reproducing the paper's results",
        "",
        "Generated by `make report` (`python -m report.paper`) from the coldroute core: the "
        f"paper's Table 1 van (preset `{PAPER_VAN}`) and, beside it, a real 3.5 t electric "
        f"reefer van (preset `{REAL_VAN}`), on the 8-stop Vienna round of the API example "
        "starting at 09:00, winter −10…−2 °C on 15 January, summer 18…31 °C on 15 July."
        + (" **Reduced grid (--quick).**" if quick else ""),
        "",
        f"| claim (paper §4) | paper | {PAPER_VAN} | {REAL_VAN} | {PAPER_VAN} agrees | why / how |",
        "|---|---|---|---|---|---|",
        *(
            f"| {c.claim} | {c.paper} | {c.ours} | {c.real_van} | "
            f"{'yes' if c.agrees else 'no'} | {c.why} |"
            for c in rows
        ),
        "",
        "## The winter share, with the cab heater on and off at stops",
        "",
        "The paper keeps the cab at 20 °C all day (Table 2 power at every stop). A driver who "
        "switches the heater off while unloading saves the parked power but pays to bring the "
        "cab back afterwards (a lumped cab of 60 kJ/K drifting towards the outside air; "
        "`vehicle.cab_hvac_at_stops`).",
        "",
        "| van | cab HVAC at stops | auxiliaries + comfort share | on the legs only "
        "| cab energy [kWh] | total [kWh] |",
        "|---|---|---|---|---|---|",
        *(
            f"| {r.van} | {r.cab_at_stops} | {r.share_pct:.1f} % | {r.driving_share_pct:.1f} % "
            f"| {r.cabin_kwh:.2f} | {r.total_kwh:.2f} |"
            for r in shares
        ),
        "",
        "Why the paper's 12–18 % is out of reach on this round: its auxiliaries and cab energy "
        "is power × time, and a delivery round is mostly time — the 8 stops stand for about an "
        "hour and the legs cover 24 km of city streets in well under an hour. Turning the "
        "heater off at stops removes the parked heating but not the heating while driving, and "
        "the recovery after each stop gives part of it back; even the legs alone stay above "
        "the paper's share because Table 2's 2.6–3.2 kW is large against the few kW city "
        "driving needs. At this round's traction per km, a 15 % share would need the van to "
        f"drive all the time at about {needed_kmh:.0f} km/h on average: the paper's figure "
        "fits a day of long fast legs and short stops, which it does not describe, or a cab "
        "heater far smaller than Table 2's.",
        "",
    ]
    for path in figures:
        lines += [f"![{path.stem}]({path.name})", ""]
    page = out / "paper-reproduction.md"
    page.write_text("\n".join(lines), encoding="utf-8")
    return page


def main(argv: list[str] | None = None) -> Path:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("docs"), help="output folder")
    parser.add_argument("--quick", action="store_true", help="a reduced grid (tests)")
    args = parser.parse_args(argv)
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    drivers = [("calm", CALM_DRIVER), ("normal", NORMAL_DRIVER), ("aggressive", AGGRESSIVE_DRIVER)]

    summer_round = plan(_round(SUMMER))
    studies = {}
    for preset in (PAPER_VAN, REAL_VAN):
        with tqdm(total=1, desc=f"{preset}: seasons × drivers", unit="cell") as bar:

            def progress(done: int, total: int, bar: Any = bar) -> None:
                bar.total = total
                bar.update(done - bar.n)

            studies[preset] = study(preset, [d for _, d in drivers], progress)
    grid = studies[PAPER_VAN].grid

    van = PRESETS["paper-generic"].van()
    traffic_rows = []
    for season in (WINTER, SUMMER):
        start, _ = departure(season.date, dt.time(12), "Europe/Vienna", VIENNA.lon)
        for label, driver, density in (
            ("free flow", 0.0, None),
            ("dense traffic", NORMAL_DRIVER, 0.8),
        ):
            trips = SweepTrips(30_000, driver, density)
            point = speed_sweep([80.0], trips, start, VIENNA, van, season.weather).points[0]
            traffic_rows.append((f"{season.name}\n{label}", point.energy_wh_per_km))

    speeds = [20, 40, 60, 80, 100, 120] if args.quick else list(range(20, 121, 5))
    start, _ = departure(SUMMER.date, dt.time(12), "Europe/Vienna", VIENNA.lon)
    sweep = speed_sweep(
        [float(s) for s in tqdm(speeds, desc="speed sweep", unit="speed")],
        SweepTrips(20_000),
        start,
        VIENNA,
        van,
        Weather(t_min_c=20, t_max_c=32),
    )

    figures = [
        figure_8(out, summer_round),
        figure_9(out, grid, drivers),
        figure_10(out, traffic_rows),
        figure_11(out, sweep),
    ]
    page = write_page(
        out,
        figures,
        claims(studies[PAPER_VAN], studies[REAL_VAN], sweep.optimum_speed_kmh),
        winter_shares(),
        speed_for_share(studies[PAPER_VAN].winter_round, 0.15),
        args.quick,
    )
    print(f"wrote {page} and {len(figures)} charts")
    return page


if __name__ == "__main__":
    main()
