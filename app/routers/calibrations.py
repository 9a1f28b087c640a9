"""POST /v1/calibrations: the model fitted to a van's measured trips."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, File, Form, Request, UploadFile
from starlette.concurrency import run_in_threadpool

from app.deps import ExecutorDep, SettingsDep
from app.examples import CALIBRATION_EXAMPLE
from app.operations import calibration as operation
from app.routers.forms import json_object, text_of, validated
from app.schemas.calibration import CalibrationRequest, CalibrationResponse
from core.exceptions import InvalidParameterError

router = APIRouter(tags=["calibration"])


@router.post(
    "/calibrations", operation_id="createCalibration", summary="Fit the model to measured trips"
)
async def create_calibration(
    request: Annotated[
        CalibrationRequest,
        Body(
            openapi_examples={
                "two-trips": {
                    "summary": "Two 10-minute trips of the reefer van, battery power at 1 Hz",
                    "value": CALIBRATION_EXAMPLE,
                }
            }
        ),
    ],
    http: Request,
    settings: SettingsDep,
    pool: ExecutorDep,
) -> CalibrationResponse:
    """Bounded nonlinear least squares of the simulated against the measured power, through
    the simulation the plans use: each parameter's value, standard error, 95 % interval and
    whether the data tell it apart; each trip's R², RMS error and energy error; the same on
    the validation trips (k-fold cross-validation when none is marked); and warnings where
    the data cannot tell parameters apart. Beyond `COLDROUTE_MAX_SYNC_CALIBRATION_SAMPLES`
    samples, a 413: submit it as a job (`POST /v1/jobs`, type `calibration`)."""
    return await pool.run(
        operation.run_calibration, request, settings, disconnected=http.is_disconnected
    )


@router.post(
    "/calibrations/csv",
    operation_id="createCalibrationFromCsv",
    summary="Fit the model to measured trips sent as CSV files",
)
async def create_calibration_from_csv(
    calibration: Annotated[
        str,
        Form(
            description="The body of POST /v1/calibrations as JSON text, its trips without "
            "their sample columns: `id`, `start`, `location`, `role`, `door_openings`."
        ),
    ],
    trips: Annotated[
        list[UploadFile],
        File(
            description="One CSV file per trip, named `<trip id>.csv`: a header row of column "
            "names — `time_s`, `speed_mps`, and any of `grade`, `payload_kg`, `ambient_c`, "
            "`battery_power_w`, `traction_power_w`, `auxiliaries_power_w`, `cabin_power_w`, "
            "`refrigeration_power_w` — then one row per sample; comma or semicolon between "
            "cells (with semicolons a decimal comma is read as a point). UTF-8."
        ),
    ],
    http: Request,
    settings: SettingsDep,
    pool: ExecutorDep,
) -> CalibrationResponse:
    """What POST /v1/calibrations does, with each trip's samples from a CSV file — what a
    telematics export becomes after one rename of its columns. A bad cell is a 422 naming the
    trip, the column and the row (`trips[1].speed_mps[40]`: the trip's 41st sample, line 42
    of its file)."""
    body = json_object(calibration, "calibration")
    files: dict[str, str] = {}
    for upload in trips:
        name = upload.filename or ""
        if name in files:
            raise InvalidParameterError(f"the file {name[:60]!r} is sent twice", "trips")
        files[name] = await text_of(upload, "trips")
    merged = await run_in_threadpool(operation.with_csv_trips, body, files)
    request = validated(CalibrationRequest, merged)
    return await pool.run(
        operation.run_calibration, request, settings, disconnected=http.is_disconnected
    )
