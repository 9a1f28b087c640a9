"""The van of a request: a preset, or a vehicle profile from the service's database, with the
request's changes."""

from __future__ import annotations

from app.profiles import profile_store
from app.schemas.base import VanRequest
from app.settings import Settings
from core.params import VanParams


def van_of(request: VanRequest, settings: Settings) -> VanParams:
    """The request's van; an unknown ``vehicle.profile`` is a 422 naming it."""
    name = request.profile()
    if name is None:
        return request.van()
    return request.van(profile_store(settings.database_url).van(name))
