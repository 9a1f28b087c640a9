import subprocess
import sys

import pytest

from app.examples import SCENARIOS_EXAMPLE, SPEED_SWEEP_EXAMPLE
from report.paper import main as report_main


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


def test_report_cli_runs(tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "report.paper", "--out", str(tmp_path), "--quick"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0 and "wrote" in run.stdout
