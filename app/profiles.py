"""Vehicle profiles and the calibrations they may come from, in the service's database.

A profile is a named, complete set of van parameters (what a preset is, but the operator's);
a calibration is kept with the van it started from, so that a profile can be made from it
later by its ``id``. Both live beside the jobs (one database, one chain of Alembic
migrations): SQLite by default, PostgreSQL by URL, shared by every replica and worker.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass
from typing import Any

from sqlalchemy import JSON, String, delete, select, update
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Mapped, mapped_column

from app.database import Base, Database, UtcDateTime, database_for, now
from core.exceptions import InvalidParameterError
from core.params import VanParams


class ProfileRow(Base):
    """One vehicle profile: its parameters as a preset has them, and the fit it came from."""

    __tablename__ = "vehicle_profiles"

    name: Mapped[str] = mapped_column(String(64), primary_key=True)
    description: Mapped[str] = mapped_column(String(1000))
    van: Mapped[dict[str, Any]] = mapped_column(JSON)
    calibration: Mapped[dict[str, Any] | None] = mapped_column(JSON, nullable=True)
    created_at: Mapped[dt.datetime] = mapped_column(UtcDateTime)
    updated_at: Mapped[dt.datetime] = mapped_column(UtcDateTime)


class CalibrationRow(Base):
    """One calibration's answer and the van it started from."""

    __tablename__ = "calibrations"

    id: Mapped[str] = mapped_column(String(36), primary_key=True)
    van: Mapped[dict[str, Any]] = mapped_column(JSON)
    answer: Mapped[dict[str, Any]] = mapped_column(JSON)
    created_at: Mapped[dt.datetime] = mapped_column(UtcDateTime)


@dataclass(frozen=True)
class Profile:
    """A profile as read from the store."""

    name: str
    description: str
    van: VanParams
    calibration: dict[str, Any] | None
    created_at: dt.datetime
    updated_at: dt.datetime

    @classmethod
    def of(cls, row: ProfileRow) -> Profile:
        return cls(
            name=row.name,
            description=row.description,
            van=van_from_json(row.van),
            calibration=row.calibration,
            created_at=row.created_at,
            updated_at=row.updated_at,
        )


@dataclass(frozen=True)
class StoredCalibration:
    """A calibration as read from the store: the van it started from and its answer."""

    id: str
    van: VanParams
    answer: dict[str, Any]
    created_at: dt.datetime


def van_to_json(van: VanParams) -> dict[str, Any]:
    return van.model_dump(mode="json")


def van_from_json(data: dict[str, Any]) -> VanParams:
    # Stored as JSON: read back as JSON is read (enums from text, tuples from arrays).
    return VanParams.model_validate(data, strict=False)


class ProfileStore:
    """Profiles and calibrations behind one database URL."""

    def __init__(self, database: Database) -> None:
        self.database = database

    def create(self, name: str, description: str, van: VanParams, calibration: Any) -> Profile:
        """A new profile; a name in use is a :class:`ProfileExistsError`."""
        moment = now()
        row = ProfileRow(
            name=name,
            description=description,
            van=van_to_json(van),
            calibration=calibration,
            created_at=moment,
            updated_at=moment,
        )
        try:
            with self.database.transaction() as session:
                session.add(row)
        except IntegrityError:
            raise ProfileExistsError(name) from None
        return Profile.of(row)

    def put(
        self, name: str, description: str, van: VanParams, calibration: Any
    ) -> tuple[Profile, bool]:
        """Create or replace the profile ``name``: the profile as written, and whether it is
        new. Each step is one statement, so a DELETE or a PUT of the same name at the same
        moment makes this one try again, never fail half-way."""
        values = {
            "description": description,
            "van": van_to_json(van),
            "calibration": calibration,
            "updated_at": now(),
        }
        for _ in range(PUT_ATTEMPTS):
            with self.database.transaction() as session:
                replaced = session.execute(
                    update(ProfileRow).where(ProfileRow.name == name).values(**values)
                )
                if replaced.rowcount == 1:  # type: ignore[attr-defined]
                    # the row is this transaction's until it commits: no DELETE takes it now
                    return Profile.of(session.get(ProfileRow, name)), False  # type: ignore[arg-type]
            try:
                return self.create(name, description, van, calibration), True
            except ProfileExistsError:  # made by another request meanwhile: replace it
                continue
        raise ProfileBusyError(name)

    def get(self, name: str) -> Profile | None:
        with self.database.transaction() as session:
            row = session.get(ProfileRow, name)
            return None if row is None else Profile.of(row)

    def all(self) -> list[Profile]:
        with self.database.transaction() as session:
            rows = session.scalars(select(ProfileRow).order_by(ProfileRow.name))
            return [Profile.of(row) for row in rows]

    def delete(self, name: str) -> bool:
        """Delete a profile; whether there was one."""
        with self.database.transaction() as session:
            gone = session.execute(delete(ProfileRow).where(ProfileRow.name == name))
            return bool(gone.rowcount == 1)  # type: ignore[attr-defined]

    def van(self, name: str, field: str = "vehicle.profile") -> VanParams:
        """The parameters of profile ``name``; an unknown one is a 422 naming ``field``."""
        profile = self.get(name)
        if profile is None:
            raise InvalidParameterError(
                f"no vehicle profile named {name!r} (GET /v1/vehicle-profiles)", field
            )
        return profile.van

    def save_calibration(self, calibration_id: str, van: VanParams, answer: Any) -> None:
        with self.database.transaction() as session:
            session.add(
                CalibrationRow(
                    id=calibration_id, van=van_to_json(van), answer=answer, created_at=now()
                )
            )

    def calibration(self, calibration_id: str) -> StoredCalibration | None:
        with self.database.transaction() as session:
            row = session.get(CalibrationRow, calibration_id)
            if row is None:
                return None
            return StoredCalibration(row.id, van_from_json(row.van), row.answer, row.created_at)


#: How often a PUT tries again when other requests keep creating and deleting the same name.
PUT_ATTEMPTS = 5


class ProfileBusyError(Exception):
    """Other requests create and delete the profile faster than a PUT can write it."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.name = name


class ProfileExistsError(Exception):
    """A profile of that name exists already."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.name = name


def profile_store(url: str) -> ProfileStore:
    """The profiles of the database at ``url``."""
    return ProfileStore(database_for(url))
