import subprocess
import sys

import pytest

from app.examples import SCENARIOS_EXAMPLE, SPEED_SWEEP_EXAMPLE
from report.paper import main as report_main
from tests.app.apps import app_client


def test_speed_sweep_example(client):
    body = client.post("/v1/studies/speed-sweep", json=SPEED_SWEEP_EXAMPLE).json()
    assert [p["speed_kmh"] for p in body["points"]] == SPEED_SWEEP_EXAMPLE["speeds_kmh"]
    assert 30 <= body["optimum_speed_kmh"] <= 50
    best = min(body["points"], key=lambda p: p["energy_wh_per_km"]["total"])
    assert best["speed_kmh"] == body["optimum_speed_kmh"]


def test_scenarios_example(client):
    body = client.post("/v1/studies/scenarios", json=SCENARIOS_EXAMPLE).json()
    assert len(body["cells"]) == 2 * 3 * 2
    assert body["tour"][0] == "depot-simmering"
    winter = [c for c in body["cells"] if c["season"] == "winter"]
    assert all(c["energy_kwh"]["cabin"] > 1 for c in winter)


@pytest.mark.parametrize(
    ("path", "change", "field"),
    [
        ("/v1/studies/speed-sweep", {"speeds_kmh": []}, "speeds_kmh"),
        ("/v1/studies/speed-sweep", {"speeds_kmh": [40, 0]}, "speeds_kmh[1]"),
        ("/v1/studies/speed-sweep", {"distance_m": -1}, "distance_m"),
        ("/v1/studies/scenarios", {"traffic_density": [1.5]}, "traffic_density[0]"),
        ("/v1/studies/scenarios", {"driver_aggressiveness": []}, "driver_aggressiveness"),
        (
            "/v1/studies/scenarios",
            {"seasons": [{"name": "x", "date": "2026-02-30"}]},
            "seasons[0].date",
        ),
    ],
)
def test_bad_studies_name_the_field(client, path, change, field):
    example = SPEED_SWEEP_EXAMPLE if "speed" in path else SCENARIOS_EXAMPLE
    response = client.post(path, json=example | change)
    assert response.status_code == 422
    assert any(e["field"] == field for e in response.json()["errors"]), response.json()


def test_grid_larger_than_the_limit(client):
    # 40 stops allowed per plan in the test settings; 12 cells × 8 stops is fine, 10 × 10 × 10
    # cells × 8 stops is not.
    response = client.post(
        "/v1/studies/scenarios",
        json=SCENARIOS_EXAMPLE
        | {
            "seasons": [{"name": f"s{i}", "date": "2026-03-01"} for i in range(10)],
            "driver_aggressiveness": [0.1 * i for i in range(10)],
            "traffic_density": [0.05 + 0.09 * i for i in range(10)],
        },
    )
    assert response.status_code == 422
    assert response.json()["title"] == "Limit exceeded"


def test_report_writes_page_and_charts(tmp_path):
    page = report_main(["--out", str(tmp_path), "--quick"])
    text = page.read_text()
    assert "| claim (paper §4) |" in text and "40 km/h" in text
    for name in ("fig8-day-profile", "fig9-seasons-drivers", "fig10-traffic", "fig11-speed-sweep"):
        png = tmp_path / f"{name}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
        assert f"({name}.png)" in text


@pytest.mark.slow
def test_report_cli_runs(tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "report.paper", "--out", str(tmp_path), "--quick"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0 and "wrote" in run.stdout


@pytest.mark.slow
def test_a_grid_of_week_long_rounds_is_refused_before_it_runs(client):
    """The audit: 1,200 cells of a 5.8-day round passed the limit, which counted cell-stops
    only. The services alone (7 stops of 20 h) make each cell at least 5.8 days: the study
    is a 413 pointing to jobs before any simulation, and as a job a 422 naming the limit."""
    long_stops = [
        stop | {"service_time_s": 72_000, "door_open_s": 600}
        for stop in SCENARIOS_EXAMPLE["plan"]["stops"][:7]
    ]
    body = SCENARIOS_EXAMPLE | {
        "plan": SCENARIOS_EXAMPLE["plan"] | {"stops": long_stops},
        "seasons": [{"name": f"s{i}", "date": "2026-03-01"} for i in range(12)],
        "driver_aggressiveness": [0.1 * i for i in range(1, 11)],
        "traffic_density": [0.05 + 0.09 * i for i in range(2)],
    }
    refused = client.post("/v1/studies/scenarios", json=body)
    assert refused.status_code == 413, refused.text[:300]
    assert "POST /v1/jobs" in refused.json()["detail"]
    roomy = app_client(max_study_cell_stops=100_000, max_job_simulated_s=86_400.0 * 365)
    job = roomy.post("/v1/jobs", json={"type": "scenarios", "request": body})
    assert job.status_code == 422, job.text[:300]
    assert job.json()["title"] == "Limit exceeded"
    assert job.json()["errors"][0]["field"] == "request.seasons"
