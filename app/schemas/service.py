"""The presets, liveness and readiness."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from app.schemas.base import ApiModel
from core.params import Preset


class PresetsResponse(ApiModel):
    """Every preset with every value."""

    presets: list[Preset] = Field(..., description="Every preset with every parameter value.")


class Health(ApiModel):
    """Liveness."""

    status: Literal["ok"] = Field("ok", description="Always ok: the process answers.")
    version: str = Field(..., description="Version of the service.")


class Check(ApiModel):
    """One dependency of the service."""

    name: str = Field(
        ..., description="workers, database, broker, celery_workers, osrm or weather."
    )
    ok: bool = Field(..., description="Whether it answered.")
    detail: str = Field(..., description="What was checked, or what went wrong.")
    critical: bool = Field(
        ...,
        description="Whether the service is unready without it (the weather service is not: "
        "plans fall back to the climatology).",
    )


class Readiness(ApiModel):
    """Whether the service can take work, dependency by dependency."""

    status: Literal["ready", "degraded", "unavailable"] = Field(
        ...,
        description="ready; degraded (a non-critical service is down); unavailable (503).",
    )
    checks: list[Check] = Field(..., description="Each dependency's answer.")
