"""Liveness."""

from __future__ import annotations

from importlib.metadata import version

from fastapi import APIRouter

from app.schemas import Health

router = APIRouter(tags=["health"])


@router.get("/healthz", operation_id="getHealth", summary="Liveness probe")
def health() -> Health:
    """Answers while the service runs."""
    return Health(version=version("coldroute"))
