"""``/v1/vehicle-profiles``: a profile's van from its request, and the stored profile as the
API answers it."""

from __future__ import annotations

from typing import Any

from app.operations.vans import van_of
from app.profiles import Profile, StoredCalibration, profile_store
from app.schemas.calibration import CalibrationResponse
from app.schemas.profiles import VehicleProfileOut, VehicleProfileRequest
from app.settings import Settings
from core.exceptions import InvalidParameterError
from core.params import CargoBoxParams, VanParams, VehicleParams


def fitted_van(calibration: StoredCalibration) -> VanParams:
    """The van a calibration started from, with the values it fitted."""
    van = calibration.van
    return VanParams(
        **van.model_dump(exclude={"vehicle", "cargo_box"}),
        vehicle=VehicleParams(**van.vehicle.model_dump() | calibration.answer["vehicle"]),
        cargo_box=CargoBoxParams(**van.cargo_box.model_dump() | calibration.answer["cargo_box"]),
    )


def profile_van(
    request: VehicleProfileRequest, settings: Settings
) -> tuple[VanParams, dict[str, Any] | None]:
    """The profile's parameters, and the calibration answer it comes from (if any)."""
    if request.calibration_id is None:
        return van_of(request, settings), None
    for chosen in ("preset", "profile"):
        if chosen in request.vehicle.model_fields_set:
            raise InvalidParameterError(
                "a profile comes from a calibration_id or from a preset or profile, not both",
                f"vehicle.{chosen}",
            )
    stored = profile_store(settings.database_url).calibration(request.calibration_id)
    if stored is None:
        raise InvalidParameterError(
            f"no calibration with id {request.calibration_id!r}", "calibration_id"
        )
    return request.van(fitted_van(stored)), stored.answer | {
        "created_at": stored.created_at.isoformat()
    }


def profile_out(profile: Profile) -> VehicleProfileOut:
    calibration = None
    if profile.calibration is not None:
        fit = {k: v for k, v in profile.calibration.items() if k != "created_at"}
        # Stored as JSON (intervals as arrays): read back as JSON is read, not strictly.
        calibration = CalibrationResponse.model_validate(fit, strict=False)
    return VehicleProfileOut(
        name=profile.name,
        description=profile.description,
        **dict(profile.van),
        calibration=calibration,
        created_at=profile.created_at,
        updated_at=profile.updated_at,
    )
