"""Vehicle profiles (``/v1/vehicle-profiles``): a named set of van parameters kept by the
service — a preset with changes, or the van a calibration fitted."""

from __future__ import annotations

import datetime as dt
from typing import Annotated

from pydantic import Field

from app.schemas.base import ApiModel, NotNull, ProfileName, VanRequest, absent
from app.schemas.calibration import CalibrationResponse
from core.params import Preset


class VehicleProfileRequest(VanRequest):
    """A vehicle profile: a preset (``vehicle.preset``) or another profile
    (``vehicle.profile``) with the parameters to change — or ``calibration_id``, the van a
    calibration started from with the values it fitted, and any change beside it."""

    name: Annotated[ProfileName | None, NotNull] = absent(
        "The profile's name, used as `vehicle.profile` (letters, digits, `.`, `_`, `-`); "
        "needed by POST, and on PUT the path's name if given."
    )
    description: str = Field("", max_length=1000, description="What this van is.")
    calibration_id: Annotated[
        Annotated[str, Field(min_length=1, max_length=36)] | None, NotNull
    ] = absent(
        "The `id` of a calibration's answer (POST /v1/calibrations or a calibration job): "
        "the van it started from with the fitted values; not with `vehicle.preset` or "
        "`vehicle.profile`."
    )


class VehicleProfileOut(Preset):
    """A vehicle profile: every parameter's value, and the calibration it came from."""

    calibration: CalibrationResponse | None = Field(
        ..., description="The calibration the profile was made from, with its fit figures."
    )
    created_at: dt.datetime = Field(..., description="When the profile was created (UTC).")
    updated_at: dt.datetime = Field(..., description="When it was last replaced (UTC).")


class VehicleProfilesResponse(ApiModel):
    """Every vehicle profile, by name."""

    profiles: list[VehicleProfileOut] = Field(..., description="Every profile, by name.")
