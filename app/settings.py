"""Service settings from the environment (prefix ``COLDROUTE_``)."""

from __future__ import annotations

from functools import lru_cache

from pydantic import Field, SecretStr
from pydantic_settings import BaseSettings, SettingsConfigDict


class Settings(BaseSettings):
    """Every knob of the service; each is an environment variable ``COLDROUTE_<NAME>``."""

    model_config = SettingsConfigDict(env_prefix="COLDROUTE_", frozen=True)

    host: str = Field("0.0.0.0", description="Interface uvicorn listens on.")
    port: int = Field(8000, ge=1, le=65535, description="Port uvicorn listens on.")
    log_level: str = Field("info", description="Python log level of the request log.")
    cors_origins: list[str] = Field(
        default_factory=list, description='Allowed CORS origins, JSON list: ["https://a.b"].'
    )
    api_key: SecretStr | None = Field(
        None, description="When set, every /v1 request needs this value in X-API-Key."
    )
    max_stops: int = Field(500, ge=1, description="Most stops in one round.")
    max_trace_samples: int = Field(
        200_000, ge=2, description="Most samples in one simulated trace (55 h at 1 Hz)."
    )
    max_body_bytes: int = Field(10_000_000, ge=1024, description="Largest request body [bytes].")
    max_study_cell_stops: int = Field(
        2000, ge=1, description="Most cells × stops in one scenario study."
    )
    max_time_limit_s: float = Field(
        10.0, gt=0, description="Cap on a request's solver time_limit_s [s]."
    )
    osrm_url: str | None = Field(
        None,
        description="Base URL of an OSRM router (http://127.0.0.1:5000); unset: distances are "
        "estimated from the great circle.",
    )
    osrm_timeout_s: float = Field(10.0, gt=0, le=300, description="Timeout of one OSRM call [s].")
    osrm_table_size: int = Field(
        100,
        ge=2,
        le=10_000,
        description="Most places per side of one OSRM /table call (the server's "
        "--max-table-size); larger rounds are fetched in blocks.",
    )
    max_snap_distance_m: float = Field(
        500.0,
        gt=0,
        description="Farthest a stop may lie from the road OSRM snaps it to [m] (422 beyond).",
    )
    weather_url: str | None = Field(
        None,
        description="Base URL of an Open-Meteo-compatible forecast API "
        "(https://api.open-meteo.com); unset: the climatology.",
    )
    weather_archive_url: str | None = Field(
        None,
        description="Base URL of its archive API for past dates "
        "(https://archive-api.open-meteo.com); unset: the same as weather_url.",
    )
    weather_timeout_s: float = Field(
        5.0, gt=0, le=120, description="Timeout of one weather call [s]."
    )


@lru_cache
def get_settings() -> Settings:
    """The settings, read once from the environment."""
    return Settings()
