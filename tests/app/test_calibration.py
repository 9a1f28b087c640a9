"""POST /v1/calibrations over HTTP: the example's two trips were logged by a van with drag
0.38 and 520 W of auxiliaries (app/examples.py), and the fit says so; bad trips are 422s
naming trip, column and row; too many samples a 413 pointing to jobs; the job answers the
same."""

from __future__ import annotations

import copy
import json
import time

import httpx
import pytest

from app.examples import CALIBRATION_EXAMPLE
from testbed.services import Server
from tests.app.apps import app_client


@pytest.fixture
def client():
    return app_client(max_body_bytes=2_000_000, max_sync_calibration_samples=5000)


@pytest.mark.slow
def test_the_example_recovers_the_van_that_logged_it(client):
    response = client.post("/v1/calibrations", json=CALIBRATION_EXAMPLE)
    assert response.status_code == 200, response.text
    body = response.json()
    drag = body["parameters"]["drag_coefficient"]
    auxiliaries = body["parameters"]["auxiliaries_power_w"]
    assert drag["initial"] == 0.34 and auxiliaries["initial"] == 400
    assert drag["value"] == pytest.approx(0.38, rel=0.01)
    assert auxiliaries["value"] == pytest.approx(520, rel=0.03)
    assert drag["ci95"][0] <= 0.38 <= drag["ci95"][1] and drag["identifiable"]
    assert body["vehicle"] == {
        "drag_coefficient": drag["value"],
        "auxiliaries_power_w": auxiliaries["value"],
    }
    assert body["cargo_box"] == {}
    assert [t["id"] for t in body["trips"]] == ["city", "ring-road"]
    assert all(t["r2"] > 0.999 and abs(t["energy_error_pct"]) < 0.5 for t in body["trips"])
    assert body["validation"]["method"] == "2-fold cross-validation"
    assert len(body["validation"]["trips"]) == 2 and len(body["id"]) == 36


def test_validation_trips_are_predicted_not_fitted(client):
    body = copy.deepcopy(CALIBRATION_EXAMPLE)
    body["trips"][1]["role"] = "validation"
    answer = client.post("/v1/calibrations", json=body).json()
    assert [t["id"] for t in answer["trips"]] == ["city"]
    assert answer["validation"]["method"] == "validation trips"
    assert [t["id"] for t in answer["validation"]["trips"]] == ["ring-road"]


def bad(change) -> dict:
    body = copy.deepcopy(CALIBRATION_EXAMPLE)
    change(body["trips"][1])
    return body


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda t: t["speed_mps"].__setitem__(40, -2.0), "trips[1].speed_mps[40]"),
        (lambda t: t["time_s"].__setitem__(7, 3), "trips[1].time_s[7]"),
        (lambda t: t["battery_power_w"].pop(), "trips[1].battery_power_w"),
        (lambda t: t["battery_power_w"].__setitem__(9, "lots"), "trips[1].battery_power_w[9]"),
        (lambda t: t.update(time_s=t["time_s"][:50], speed_mps=t["speed_mps"][:50],
                            battery_power_w=t["battery_power_w"][:50],
                            ambient_c=t["ambient_c"][:50]), "trips[1].time_s"),
        (lambda t: t.pop("battery_power_w"), "trips[1]"),
        # the trust issue's audit: a 500, or a 422 naming a field without its trip
        (lambda t: t["battery_power_w"].__setitem__(5, 1e308), "trips[1].battery_power_w[5]"),
        (lambda t: t.update(payload_kg=[50_000.0] * len(t["time_s"])), "trips[1].payload_kg[0]"),
        (lambda t: t.update(grade=[0.0] * 3 + [0.9] * (len(t["time_s"]) - 3)),
         "trips[1].grade[3]"),
        (lambda t: t.update(ambient_c=[25.0] * 4 + [70.0] * (len(t["time_s"]) - 4)),
         "trips[1].ambient_c[4]"),
        (lambda t: t.update(door_openings=[{"start_s": 1e6, "duration_s": 30}]),
         "trips[1].door_openings[0].start_s"),
        (lambda t: t.update(time_s=[k * 4000.0 for k in range(len(t["time_s"]))]),
         "trips[1].time_s"),
        (lambda t: t.update(id="city"), "trips[1].id"),
    ],
)  # fmt: skip
def test_a_bad_trip_is_a_422_naming_trip_column_and_row(client, change, field):
    response = client.post("/v1/calibrations", json=bad(change))
    assert response.status_code == 422, response.text
    assert any(e["field"] == field for e in response.json()["errors"]), response.json()


def test_a_trip_whose_measured_power_is_all_zero_is_fitted_without_a_relative_error(client):
    # The audit's 500: a division by the measured energy, 0.
    body = copy.deepcopy(CALIBRATION_EXAMPLE)
    body["trips"][1]["battery_power_w"] = [0.0] * len(body["trips"][1]["time_s"])
    response = client.post("/v1/calibrations", json=body)
    assert response.status_code == 200, response.text
    fits = {t["id"]: t for t in response.json()["trips"]}
    assert fits["ring-road"]["energy_error_pct"] is None
    assert fits["city"]["energy_error_pct"] is not None


def test_a_nan_in_a_column_is_named(client):
    body = bad(lambda t: t["speed_mps"].__setitem__(12, float("nan")))
    response = client.post(
        "/v1/calibrations",
        content=json.dumps(body),  # Python's JSON writes NaN, as some exporters do
        headers={"content-type": "application/json"},
    )
    assert response.status_code == 422
    assert any(e["field"] == "trips[1].speed_mps[12]" for e in response.json()["errors"])


def test_an_unknown_parameter_is_named(client):
    body = CALIBRATION_EXAMPLE | {"parameters": ["drag_coefficient", "mass_kg"]}
    response = client.post("/v1/calibrations", json=body)
    assert response.status_code == 422
    assert any(e["field"].startswith("parameters[1]") for e in response.json()["errors"])


@pytest.mark.slow
def test_too_many_samples_for_an_answer_is_a_413_pointing_to_jobs_which_fit_them():
    server = Server(
        {"COLDROUTE_WORKERS": "2", "COLDROUTE_MAX_SYNC_CALIBRATION_SAMPLES": "1000"}
    ).start()
    try:
        response = httpx.post(f"{server.url}/v1/calibrations", json=CALIBRATION_EXAMPLE, timeout=30)
        assert response.status_code == 413
        assert "POST /v1/jobs, type calibration" in response.json()["detail"]
        submitted = httpx.post(
            f"{server.url}/v1/jobs",
            json={"type": "calibration", "request": CALIBRATION_EXAMPLE},
            timeout=30,
        )
        assert submitted.status_code == 202, submitted.text
        deadline = time.monotonic() + 60
        while True:
            job = httpx.get(f"{server.url}/v1/jobs/{submitted.json()['id']}", timeout=10).json()
            if job["status"] in ("succeeded", "failed") or time.monotonic() > deadline:
                break
            time.sleep(0.2)
    finally:
        server.close()
    assert job["status"] == "succeeded", job
    fitted = job["result"]["parameters"]["drag_coefficient"]["value"]
    assert fitted == pytest.approx(0.38, rel=0.01)


def as_csv(body: dict, delimiter: str = ",") -> tuple[dict, list]:
    """The form of POST /v1/calibrations/csv: the trips' metadata as JSON text, each trip's
    columns as a file ``<id>.csv`` (with semicolons, decimal commas, as a spreadsheet in much
    of Europe exports it)."""
    columns = ("time_s", "speed_mps", "battery_power_w", "ambient_c")
    meta = copy.deepcopy(body)
    files = []
    for trip in meta["trips"]:
        rows = [delimiter.join(columns)]
        for values in zip(*(trip.pop(c) for c in columns), strict=True):
            cells = [repr(float(v)) for v in values]
            rows.append(
                delimiter.join(c.replace(".", ",") if delimiter == ";" else c for c in cells)
            )
        files.append(("trips", (f"{trip['id']}.csv", "\r\n".join(rows) + "\r\n", "text/csv")))
    return {"calibration": json.dumps(meta)}, files


@pytest.mark.parametrize("delimiter", [",", ";"])
def test_trips_as_csv_files_fit_as_the_same_trips_in_json(client, delimiter):
    by_json = client.post("/v1/calibrations", json=CALIBRATION_EXAMPLE).json()
    data, files = as_csv(CALIBRATION_EXAMPLE, delimiter)
    by_csv = client.post("/v1/calibrations/csv", data=data, files=files)
    assert by_csv.status_code == 200, by_csv.text
    for name, fitted in by_json["parameters"].items():
        assert by_csv.json()["parameters"][name]["value"] == pytest.approx(fitted["value"])
    assert [t["r2"] for t in by_csv.json()["trips"]] == pytest.approx(
        [t["r2"] for t in by_json["trips"]]
    )


def _edit_file(files: list, index: int, edit) -> list:
    changed = list(files)
    name, (filename, text, kind) = changed[index]
    changed[index] = (name, (filename, edit(text), kind))
    return changed


def _cell(row: int, column: int, value: str):
    def edit(text: str) -> str:
        lines = text.split("\r\n")
        cells = lines[row + 1].split(",")
        cells[column] = value
        lines[row + 1] = ",".join(cells)
        return "\r\n".join(lines)

    return edit


@pytest.mark.parametrize(
    ("edit", "field", "words"),
    [
        (_cell(40, 1, "fast"), "trips[1].speed_mps[40]", "not a number"),
        (_cell(12, 2, ""), "trips[1].battery_power_w[12]", "not a number"),
        (_cell(7, 2, "inf"), "trips[1].battery_power_w[7]", "finite"),
        (_cell(40, 1, "-2.0"), "trips[1].speed_mps[40]", ""),
        (_cell(7, 0, "3.0"), "trips[1].time_s[7]", ""),
        (_cell(5, 2, "1,2"), "trips[1].time_s[5]", "cells"),
        (lambda t: t.replace("speed_mps", "velocity", 1), "trips[1]", "unknown column"),
        (lambda t: "\r\n".join(t.split("\r\n")[:30]), "trips[1].time_s", ""),
        # float() reads these as 10; a spreadsheet never writes them
        (_cell(40, 1, "1_0"), "trips[1].speed_mps[40]", "not a number"),
        (_cell(40, 1, "\u0661\u0660"), "trips[1].speed_mps[40]", "not a number"),
        (_cell(40, 1, "nan"), "trips[1].speed_mps[40]", "finite"),
    ],
)
def test_a_bad_csv_is_a_422_naming_trip_column_and_row(client, edit, field, words):
    data, files = as_csv(CALIBRATION_EXAMPLE)
    response = client.post("/v1/calibrations/csv", data=data, files=_edit_file(files, 1, edit))
    assert response.status_code == 422, response.text
    errors = response.json()["errors"]
    assert any(e["field"] == field and words in e["message"] for e in errors), errors


FORM = "application/x-www-form-urlencoded"


def test_files_and_trips_must_match(client):
    data, files = as_csv(CALIBRATION_EXAMPLE)
    missing = client.post("/v1/calibrations/csv", data=data, files=files[:1])
    assert missing.json()["errors"][0]["field"] == "trips[1]"
    assert "ring-road.csv" in missing.json()["detail"]
    stray = [(n, ("other.csv", t, k)) if f == "city.csv" else (n, (f, t, k))
             for n, (f, t, k) in files]  # fmt: skip
    assert (
        client.post("/v1/calibrations/csv", data=data, files=stray).json()["errors"][0]["field"]
        == "trips"
    )
    both = json.loads(data["calibration"])
    both["trips"][1]["time_s"] = CALIBRATION_EXAMPLE["trips"][1]["time_s"]
    twice = client.post("/v1/calibrations/csv", data={"calibration": json.dumps(both)}, files=files)
    assert twice.json()["errors"][0]["field"] == "trips[1].time_s"
    # not "both in the JSON and in its file" when the file has no such column (an audit's)
    assert "both" not in twice.json()["detail"] and "come from its file" in twice.json()["detail"]
    # trips as a text field, or the form urlencoded: named, in the request's words
    for sent in (
        {"data": data | {"trips": "city.csv"}},
        {"content": "calibration=%7B%7D&trips=x", "headers": {"content-type": FORM}},
    ):
        refused = client.post("/v1/calibrations/csv", **sent)  # type: ignore[arg-type]
        assert refused.status_code == 422
        assert refused.json()["errors"][0]["field"] == "trips[0]", refused.json()
        assert "must be a file" in refused.json()["detail"]
    broken = client.post("/v1/calibrations/csv", data={"calibration": "{"}, files=files)
    assert broken.status_code == 422 and broken.json()["errors"][0]["field"] == "calibration"
    meta = json.loads(data["calibration"])
    meta["trips"][0]["start"] = "yesterday"
    late = client.post("/v1/calibrations/csv", data={"calibration": json.dumps(meta)}, files=files)
    assert late.status_code == 422 and late.json()["errors"][0]["field"] == "trips[0].start"
