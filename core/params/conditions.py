"""The conditions a van drives in: the day's weather (paper §3.1), where, when, and the street
types and drivers of the generated speed traces (§2.2)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, ValidationInfo, field_validator

from core.params.base import Params


class Weather(Params):
    """Daily extremes of the ambient temperature (paper §3.1); t_min_c must not exceed t_max_c."""

    t_min_c: float = Field(
        ..., ge=-60, le=60, description="Lowest temperature of the day [°C]; at most t_max_c."
    )
    t_max_c: float = Field(
        ..., ge=-60, le=60, description="Highest temperature of the day [°C]; at least t_min_c."
    )

    @field_validator("t_max_c")
    @classmethod
    def _ordered(cls, value: float, info: ValidationInfo) -> float:
        if "t_min_c" in info.data and info.data["t_min_c"] > value:
            raise ValueError("t_min_c must not exceed t_max_c")
        return value


class Location(Params):
    """A point on the Earth (WGS 84)."""

    lat: float = Field(..., ge=-90, le=90, description="Latitude [°], north positive.")
    lon: float = Field(..., ge=-180, le=180, description="Longitude [°], east positive.")


#: Most door openings, or parked spells, of one simulated trace.
MAX_INTERVALS = 10_000


class Interval(Params):
    """A span of time within a simulated trace."""

    start_s: float = Field(..., ge=0, description="Start, seconds after the trace start [s].")
    duration_s: float = Field(..., ge=0, le=86_400, description="How long it lasts [s].")


class DoorOpening(Interval):
    """One opening of the cargo door during a simulated trace."""

    duration_s: float = Field(..., ge=0, le=86_400, description="How long it stays open [s].")


class SetpointSpan(Interval):
    """A stretch of a refrigeration unit's schedule to follow: its air set-point from
    ``start_s`` for ``duration_s`` (a plan's ``refrigeration.schedule``, in seconds)."""

    air_setpoint_c: float = Field(
        ..., ge=-60, le=30, description="The air set-point the unit follows [°C]."
    )


class ChargingSpell(Interval):
    """A spell plugged in at a charger during a simulated trace (the van stands)."""

    power_kw: float = Field(
        ..., ge=0.1, le=1000, description="The charger's power [kW]; the van's curve caps it."
    )
    price_per_kwh: float = Field(
        0.0, ge=0, le=100, description="Price of the energy drawn from the grid [per kWh]."
    )


#: Lightest and densest traffic ε_t [–]: the traffic law t_0 = t_p·(1 − ε_t)/ε_t needs
#: ε_t strictly inside 0..1; beyond these it is constant speed or stop-and-go already.
MIN_TRAFFIC_DENSITY = 0.01
MAX_TRAFFIC_DENSITY = 0.99


#: A traffic density ε_t [–] as a request gives it.
TrafficDensity = Annotated[float, Field(ge=MIN_TRAFFIC_DENSITY, le=MAX_TRAFFIC_DENSITY)]


class StreetType(Params):
    """Shape of the generated speed trace on one kind of street (paper §2.2)."""

    mean_speed_mps: float = Field(
        ..., ge=0.5, le=60, description="Mean speed v̄ [m/s]; at least 0.5 m/s."
    )
    speed_variation: float = Field(
        ..., ge=0, le=1, description="Relative amplitude dv of the trapezoid [–]."
    )
    period_divisor: float = Field(
        ..., ge=0.1, le=1000, description="k in t_p = t_NEDC / k [–]: more k, shorter waves."
    )
    traffic_density: float = Field(
        ...,
        ge=MIN_TRAFFIC_DENSITY,
        le=MAX_TRAFFIC_DENSITY,
        description="Default traffic density ε_t on this street type [–], 0.01–0.99.",
    )


#: Street-type presets. Mean speeds are typical free-flow averages (urban with lights,
#: rural highway, motorway); the shape parameters are tuned so that a calm and an aggressive
#: driver differ by the paper's 10–12 % on an urban leg (tests/core/physics/test_cycles.py).
STREET_TYPES: dict[str, StreetType] = {
    "urban": StreetType(
        mean_speed_mps=30 / 3.6, speed_variation=0.8, period_divisor=16, traffic_density=0.5
    ),
    "highway": StreetType(
        mean_speed_mps=70 / 3.6, speed_variation=0.3, period_divisor=8, traffic_density=0.3
    ),
    "expressway": StreetType(
        mean_speed_mps=100 / 3.6, speed_variation=0.15, period_divisor=4, traffic_density=0.2
    ),
}
StreetTypeName = Literal["urban", "highway", "expressway"]
#: Share of the maximum acceleration a driver at least ramps up and down with at the ends of a
#: leg (a driver with ε_d = 0, who keeps a constant speed as in the paper's Fig. 10, still has
#: to start and stop) [–].
LEAST_RAMP_SHARE = 0.2

#: Driver aggressiveness ε_d of a calm and of an aggressive driver (paper §2.2, Fig. 9): a calm
#: driver pulls away at 0.3 · 2 m/s² = 0.6 m/s², the acceleration of economical driving; an
#: aggressive one at the van's full 2 m/s².
CALM_DRIVER = 0.3
NORMAL_DRIVER = 0.5
AGGRESSIVE_DRIVER = 1.0
