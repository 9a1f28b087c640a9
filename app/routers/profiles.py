"""/v1/vehicle-profiles: named vans kept by the service, used as ``"vehicle": {"profile": …}``
wherever a preset is."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Path, Response
from starlette.exceptions import HTTPException

from app.deps import SettingsDep
from app.operations.profiles import profile_out, profile_van
from app.profiles import (
    Profile,
    ProfileBusyError,
    ProfileExistsError,
    ProfileStore,
    profile_store,
)
from app.schemas.base import ProfileName
from app.schemas.profiles import (
    VehicleProfileOut,
    VehicleProfileRequest,
    VehicleProfilesResponse,
)
from core.exceptions import InvalidParameterError

router = APIRouter(prefix="/vehicle-profiles", tags=["vehicle profiles"])

NamePath = Annotated[ProfileName, Path(description="The profile's name.")]
PROFILE_EXAMPLES = {
    "from-a-preset": {
        "summary": "The reefer preset with this fleet's battery and box",
        "value": {
            "name": "van-17",
            "description": "Our 3.5 t reefers with the 75 kWh pack and the thicker box",
            "vehicle": {"preset": "ev-van-3.5t-reefer", "mass_kg": 2950},
            "battery": {"usable_capacity_kwh": 75},
            "cargo_box": {"wall_heat_transfer_w_m2k": 0.3},
        },
    },
    "from-a-calibration": {
        "summary": "The van a calibration fitted (its answer's id)",
        "value": {
            "name": "van-17-fitted",
            "calibration_id": "3b9d2f64-8c1e-4a7b-b0d5-6e2a9c4f7d13",
        },
    },
}


def _store(settings: SettingsDep) -> ProfileStore:
    return profile_store(settings.database_url)


def _found(profile: Profile | None, name: str) -> Profile:
    if profile is None:
        raise HTTPException(404, f"no vehicle profile named {name!r}")
    return profile


@router.post(
    "",
    operation_id="createVehicleProfile",
    summary="Keep a named van",
    status_code=201,
)
def create_profile(
    request: Annotated[VehicleProfileRequest, Body(openapi_examples=PROFILE_EXAMPLES)],
    settings: SettingsDep,
    response: Response,
) -> VehicleProfileOut:
    """A preset (or another profile) with changes, or the van a calibration fitted
    (`calibration_id`), kept under `name` in the service's database. Every parameter is
    resolved now: the profile does not follow later changes of its preset. A name in use is a
    409 (PUT replaces)."""
    if request.name is None:
        raise InvalidParameterError("a new profile needs a name", "name")
    van, calibration = profile_van(request, settings)
    try:
        made = _store(settings).create(request.name, request.description, van, calibration)
    except ProfileExistsError:
        raise HTTPException(
            409, f"a vehicle profile named {request.name!r} exists; PUT replaces it"
        ) from None
    response.headers["Location"] = f"/v1/vehicle-profiles/{made.name}"
    return profile_out(made)


@router.get("", operation_id="listVehicleProfiles", summary="Every named van")
def list_profiles(settings: SettingsDep) -> VehicleProfilesResponse:
    """Every profile with every parameter value, by name."""
    return VehicleProfilesResponse(profiles=[profile_out(p) for p in _store(settings).all()])


@router.get("/{name}", operation_id="getVehicleProfile", summary="One named van")
def get_profile(name: NamePath, settings: SettingsDep) -> VehicleProfileOut:
    """The profile with every parameter value and the calibration it came from."""
    return profile_out(_found(_store(settings).get(name), name))


@router.put(
    "/{name}",
    operation_id="replaceVehicleProfile",
    summary="Create or replace a named van",
    responses={201: {"model": VehicleProfileOut, "description": "Created."}},
)
def put_profile(
    name: NamePath,
    request: Annotated[VehicleProfileRequest, Body(openapi_examples=PROFILE_EXAMPLES)],
    settings: SettingsDep,
    response: Response,
) -> VehicleProfileOut:
    """The profile `name`, made as POST makes one: replaced when it exists (200), created
    otherwise (201). Plans that name it use the new values from then on."""
    if request.name is not None and request.name != name:
        raise InvalidParameterError(f"the body names {request.name!r}, the path {name!r}", "name")
    van, calibration = profile_van(request, settings)
    try:
        written, created = _store(settings).put(name, request.description, van, calibration)
    except ProfileBusyError:
        raise HTTPException(
            409, f"other requests keep creating and deleting {name!r}; try again"
        ) from None
    if created:
        response.status_code = 201
        response.headers["Location"] = f"/v1/vehicle-profiles/{name}"
    return profile_out(written)


@router.delete(
    "/{name}",
    operation_id="deleteVehicleProfile",
    summary="Forget a named van",
    status_code=204,
    response_class=Response,
)
def delete_profile(name: NamePath, settings: SettingsDep) -> Response:
    """Plans and jobs that name it afterwards are a 422 naming `vehicle.profile`."""
    if not _store(settings).delete(name):
        raise HTTPException(404, f"no vehicle profile named {name!r}")
    return Response(status_code=204)
