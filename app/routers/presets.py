"""Parameter presets."""

from __future__ import annotations

from fastapi import APIRouter

from app.schemas.service import PresetsResponse
from core.params import PRESETS

router = APIRouter(tags=["presets"])


@router.get("/presets", operation_id="listPresets", summary="Parameter presets")
def list_presets() -> PresetsResponse:
    """Every preset with every parameter value; a request names one in `vehicle.preset`."""
    return PresetsResponse(presets=list(PRESETS.values()))
