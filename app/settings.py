"""Service settings from the environment (prefix ``COLDROUTE_``)."""

from __future__ import annotations

import os
from functools import lru_cache
from typing import Annotated

from pydantic import Field, SecretStr
from pydantic_settings import BaseSettings, SettingsConfigDict

from core.params import MAX_STOPS, MAX_TRACE_SAMPLES
from core.planning.model import MAX_VEHICLES


class Settings(BaseSettings):
    """Every knob of the service; each is an environment variable ``COLDROUTE_<NAME>``."""

    model_config = SettingsConfigDict(env_prefix="COLDROUTE_", frozen=True)

    host: str = Field(
        "127.0.0.1",
        description="Interface the server listens on (make serve); 0.0.0.0 to serve the network.",
    )
    port: int = Field(8000, ge=1, le=65535, description="Port uvicorn listens on.")
    log_level: str = Field("info", description="Python log level of the request log.")
    cors_origins: list[str] = Field(
        default_factory=list, description='Allowed CORS origins, JSON list: ["https://a.b"].'
    )
    tile_url: Annotated[str, Field(pattern=r"^(https?://[^\s'\"<>]*\{z\}[^\s'\"<>]*)?$")] = Field(
        "https://tile.openstreetmap.org/{z}/{x}/{y}.png",
        description="Map tiles of the plan viewer (/viewer): an XYZ URL with {z}, {x}, {y} "
        "(and {s} for a subdomain); empty for none (the routes draw on a plain background).",
    )
    tile_attribution: str = Field(
        "© OpenStreetMap contributors",
        max_length=200,
        description="The credit the viewer shows under its tiles.",
    )
    api_key: SecretStr | None = Field(
        None, description="When set, every /v1 request needs this value in X-API-Key."
    )
    max_stops: int = Field(
        1000, ge=1, le=MAX_STOPS, description=f"Most stops in one round (at most {MAX_STOPS})."
    )
    max_vehicles: int = Field(
        250,
        ge=1,
        le=MAX_VEHICLES,
        description=f"Most vans in one fleet plan (at most {MAX_VEHICLES}).",
    )
    max_trace_samples: int = Field(
        200_000,
        ge=2,
        le=MAX_TRACE_SAMPLES,
        description="Most samples in one simulated trace (55 h at 1 Hz; at most "
        f"{MAX_TRACE_SAMPLES:,}).",
    )
    max_body_bytes: int = Field(
        64_000_000,
        ge=1024,
        description="Largest request body [bytes]: 1,000 stops with their matrices take about "
        "20 MB.",
    )
    max_study_cell_stops: int = Field(
        2000, ge=1, description="Most cells × stops in one scenario study."
    )
    max_sync_simulated_s: float = Field(
        30_000_000.0,
        gt=0,
        description="Most time a synchronous study may simulate [s] (about a year of driving, "
        "a few seconds of work); beyond, a 413 points to jobs (max_job_simulated_s).",
    )
    max_job_simulated_s: float = Field(
        300_000_000.0,
        gt=0,
        description="Most time a study submitted as a job may simulate [s] (about ten years "
        "of driving).",
    )
    max_route_days: int = Field(
        200_000,
        ge=1,
        description="Most route-days × candidates one electrification study simulates (50 "
        "routes × 365 days × 3 candidates is 54,750); beyond, a 413 names the limit.",
    )
    job_part_route_days: int = Field(
        2_000,
        ge=1,
        description="A study submitted as a job is run in parts of about this many route-days "
        "× candidates each (some seconds of work), shared out over the workers: a worker lost "
        "costs one part, and the job's progress is told part by part.",
    )
    max_sync_route_days: int = Field(
        1_000,
        ge=1,
        description="Most route-days × candidates a synchronous electrification study "
        "simulates (a few seconds of work); beyond, a 413 points to jobs.",
    )
    max_sync_calibration_samples: int = Field(
        100_000,
        ge=2,
        description="Most samples, over all trips, a synchronous calibration fits (28 h at "
        "1 Hz, some ten seconds of work); beyond, a 413 points to jobs, which have no such bound.",
    )
    far_stop_km: float = Field(
        300.0,
        gt=0,
        le=20_040,
        description="A stop farther than this from the depot (great circle) is planned with a "
        "warning naming it: coordinates mistyped or swapped look like this [km].",
    )
    max_time_limit_s: float = Field(
        120.0,
        gt=0,
        description="Cap on a request's time_limit_s [s]: a search it stops says so "
        "(stopped_by: time_limit).",
    )
    max_job_time_limit_s: float = Field(
        600.0, gt=0, description="Cap on a job's solver time_limit_s [s] (jobs may solve longer)."
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
    workers: int = Field(
        default_factory=lambda: os.cpu_count() or 1,
        ge=1,
        le=256,
        description="Worker processes that solve and simulate (default: the CPU count).",
    )
    queue_size: int = Field(
        64, ge=0, le=100_000, description="Requests that may wait for a worker (503 beyond)."
    )
    queue_deadline_s: float = Field(
        30.0, gt=0, le=3600, description="Longest a request waits for a worker (503 beyond) [s]."
    )
    shutdown_grace_s: float = Field(
        8.0,
        ge=0,
        le=300,
        description="On SIGTERM, how long requests under way may finish before they are "
        "answered 503 and the workers stopped [s].",
    )
    database_url: str = Field(
        "sqlite:///coldroute.db",
        description="Where jobs and results are kept (SQLAlchemy URL): a SQLite file beside "
        "the server, or postgresql+psycopg://user@host/db.",
    )
    broker_url: str | None = Field(
        None,
        description="Celery broker (redis://127.0.0.1:6379/0): jobs go to Celery workers "
        "(make worker) instead of the server's own pool. Needs a PostgreSQL database_url.",
    )
    broker_queue: str = Field(
        "coldroute",
        min_length=1,
        max_length=200,
        description="Celery queue of the jobs: deployments that share a broker use their own.",
    )
    job_slots: int | None = Field(
        None,
        ge=1,
        le=256,
        description="Jobs the server's own pool runs at once; default: all workers but one, "
        "so synchronous requests keep a worker.",
    )
    job_retention_s: float = Field(
        7 * 86_400.0, gt=0, description="How long finished jobs and results are kept [s]."
    )
    job_heartbeat_s: float = Field(
        3.0, gt=0, le=600, description="How often a running job says it is alive [s]."
    )
    job_stale_after_s: float = Field(
        15.0,
        gt=0,
        le=3600,
        description="A running job silent this long lost its worker and is run again [s].",
    )
    job_resend_after_s: float = Field(
        120.0,
        gt=0,
        le=86_400,
        description="With Celery: a job sent to the broker this long ago that has not started, "
        "while the broker's queue is empty, lost its message (a worker died holding it) and is "
        "sent again [s]. A broker that restarted gets its jobs again at once.",
    )
    job_max_attempts: int = Field(
        3, ge=1, le=20, description="Runs of a job before it is failed (worker lost, router down)."
    )
    job_retry_backoff_s: list[Annotated[float, Field(ge=0, le=3600)]] = Field(
        default_factory=lambda: [5.0, 20.0, 60.0],
        min_length=1,
        max_length=20,
        description="Wait before the 2nd, 3rd, … run of a job whose outside service failed [s], "
        "JSON list; the last value repeats.",
    )

    @property
    def job_concurrency(self) -> int:
        """Jobs the server's own pool runs at once."""
        return self.job_slots or max(self.workers - 1, 1)


@lru_cache
def get_settings() -> Settings:
    """The settings, read once from the environment."""
    return Settings()
