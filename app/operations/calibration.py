"""``POST /v1/calibrations`` and jobs of type ``calibration``: measured trips → the fit."""

from __future__ import annotations

import csv
import uuid
from typing import Any

import numpy as np

from app.operations.cells import delimiter_of, header_of, number
from app.operations.vans import van_of
from app.profiles import profile_store
from app.schemas.calibration import (
    CalibrationRequest,
    CalibrationResponse,
    FittedParameterOut,
    TripFitOut,
    TripRequest,
    ValidationOut,
)
from app.settings import Settings
from core.calibration.fit import (
    FITTABLE,
    Calibration,
    MeasuredTrip,
    calibrate,
    check_trips,
)
from core.exceptions import InvalidParameterError, TooMuchToWaitForError
from core.params import CargoBoxParams, VanParams


def measured_trips(request: CalibrationRequest) -> list[MeasuredTrip]:
    """The request's trips for the core, each checked (a 422 names trip, column and row)."""
    trips = []
    for trip in request.trips:

        def column(values: list[float] | None) -> np.ndarray | None:
            return None if values is None else np.asarray(values, dtype=float)

        measured = MeasuredTrip(
            id=trip.id,
            start=trip.start,
            location=trip.location,
            time_s=np.asarray(trip.time_s, dtype=float),
            speed_mps=np.asarray(trip.speed_mps, dtype=float),
            measured_w={c: np.asarray(v, dtype=float) for c, v in trip.measured_w().items()},
            role=trip.role,
            grade=column(trip.grade),
            payload_kg=column(trip.payload_kg),
            ambient_c=column(trip.ambient_c),
            door_openings=trip.door_openings,
        )
        trips.append(measured)
    check_trips(trips)
    return trips


def check_job(request: CalibrationRequest, settings: Settings) -> None:
    """Everything but the fit: what a job refuses at submission."""
    van_of(request, settings)
    measured_trips(request)


def check_calibration(request: CalibrationRequest, settings: Settings) -> None:
    """As :func:`check_job`, and synchronously a 413 beyond ``max_sync_calibration_samples``
    (a job has no such bound)."""
    check_job(request, settings)
    samples = sum(trip.samples() for trip in request.trips)
    if samples > settings.max_sync_calibration_samples:
        raise TooMuchToWaitForError(
            f"{len(request.trips)} trips of {samples:,} samples in all; a synchronous "
            f"calibration fits at most {settings.max_sync_calibration_samples:,}: submit it "
            "as a job (POST /v1/jobs, type calibration)",
            "trips",
        )


def run_calibration(request: CalibrationRequest, settings: Settings) -> CalibrationResponse:
    """The fit (``POST /v1/calibrations``), answered and kept in the service's database with
    the van it started from, so that a vehicle profile can be made from its ``id``."""
    check_calibration(request, settings)
    van = van_of(request, settings)
    response = answer(calibrate(van, measured_trips(request), request.fit_parameters()))
    profile_store(settings.database_url).save_calibration(
        response.id, profile_base(request, van, settings), response.model_dump(mode="json")
    )
    return response


def profile_base(request: CalibrationRequest, van: VanParams, settings: Settings) -> VanParams:
    """The van a profile made from this calibration starts from: the van the fit started
    from, but for the load of the measured trips (``payload_kg``), which is a fact of those
    trips, not of the van — the profile keeps its preset's (or profile's) payload, and
    differs from it only in what the request changed of the van and what the fit fitted."""
    base = van_of(request.model_copy(update={"payload_kg": None}), settings)
    return van.model_copy(update={"payload_kg": base.payload_kg})


def answer(fit: Calibration) -> CalibrationResponse:
    """The fit as the endpoint answers it."""
    vehicle = {p.name: p.value for p in fit.parameters if FITTABLE[p.name] is not CargoBoxParams}
    box = {p.name: p.value for p in fit.parameters if FITTABLE[p.name] is CargoBoxParams}
    return CalibrationResponse(
        id=str(uuid.uuid4()),
        parameters={p.name: FittedParameterOut(**dict(p)) for p in fit.parameters},
        trips=[TripFitOut(**dict(t)) for t in fit.trips],
        validation=ValidationOut(
            method=fit.validation_method, trips=[TripFitOut(**dict(t)) for t in fit.validation]
        ),
        vehicle=vehicle,
        cargo_box=box,
        warnings=fit.warnings,
    )


#: The columns a trip's CSV may have: the sample arrays of a trip, by the same names.
CSV_COLUMNS = tuple(
    name
    for name in TripRequest.model_fields
    if name not in ("id", "start", "location", "role", "door_openings")
)


def csv_columns(text: str, field: str) -> dict[str, list[float]]:
    """The sample columns of one trip's CSV: a header row naming columns of
    :data:`CSV_COLUMNS`, comma or semicolon between cells (with semicolons, a decimal comma is
    read as a point, as spreadsheets in much of Europe write it). A bad cell is a 422 naming
    ``field``, the column and the row (``trips[1].speed_mps[40]``, the 41st sample)."""
    lines = text.lstrip("\ufeff").splitlines()
    if not lines or not lines[0].strip():
        raise InvalidParameterError("the CSV has no header row", field)
    delimiter = delimiter_of(lines[0])
    rows = list(csv.reader(lines, delimiter=delimiter))
    header = header_of(rows[0], field)
    for name in header:
        if name not in CSV_COLUMNS:
            raise InvalidParameterError(
                f"unknown column {name[:40]!r}; the columns are {', '.join(CSV_COLUMNS)}", field
            )
    columns: dict[str, list[float]] = {name: [] for name in header}
    samples = [row for row in rows[1:] if any(cell.strip() for cell in row)]
    for index, row in enumerate(samples):
        if len(row) != len(header):
            raise InvalidParameterError(
                f"row {index + 1} has {len(row)} cells, the header {len(header)}",
                f"{field}.{header[0]}[{index}]",
            )
        for name, cell in zip(header, row, strict=True):
            columns[name].append(number(cell, delimiter, f"{field}.{name}[{index}]"))
    return columns


def with_csv_trips(body: dict[str, Any], files: dict[str, str]) -> dict[str, Any]:
    """The calibration's JSON body with each trip's columns from its CSV file, the file named
    after the trip (``<id>.csv``)."""
    trips = body.get("trips")
    if not isinstance(trips, list):
        raise InvalidParameterError("the calibration needs its trips[] (id, start, …)", "trips")
    by_id = {trip.get("id"): k for k, trip in enumerate(trips) if isinstance(trip, dict)}
    merged = [dict(trip) if isinstance(trip, dict) else trip for trip in trips]
    for filename, text in files.items():
        trip_id = filename.removesuffix(".csv")
        if trip_id not in by_id:
            raise InvalidParameterError(
                f"the file {filename[:60]!r} names no trip: a trip's file is <its id>.csv", "trips"
            )
        k = by_id[trip_id]
        given = [name for name in CSV_COLUMNS if name in merged[k]]
        if given:  # the samples come from the file: none in the JSON, whatever the file holds
            raise InvalidParameterError(
                f"trip {trip_id!r} has {given[0]} in the JSON: its samples come from its file "
                f"{filename[:60]!r}; leave the sample columns out of the JSON",
                f"trips[{k}].{given[0]}",
            )
        merged[k] |= csv_columns(text, f"trips[{k}]")
    for k, trip in enumerate(merged):
        if isinstance(trip, dict) and not any(name in trip for name in CSV_COLUMNS):
            raise InvalidParameterError(
                f"no file {str(trip.get('id'))[:60]}.csv for this trip", f"trips[{k}]"
            )
    return body | {"trips": merged}
