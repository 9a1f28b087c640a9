"""The container as an operator runs it: healthy by its own HEALTHCHECK, answering plans and
fleet plans, not root, its jobs kept on its volume across a restart, stopped within Docker's
10 s with a long solve in flight, and one JSON line per request on stdout."""

from __future__ import annotations

import json
import threading
import time

import httpx
import numpy as np

from image_tests.conftest import Container, Docker, example

#: The Dockerfile's HEALTHCHECK start period [s]: healthy before it ends.
START_PERIOD_S = 60
#: What ``docker stop`` waits before it kills [s].
DOCKER_STOP_S = 10


def test_the_image_carries_no_wheelhouse_pip_or_compiler(docker: Docker, image: str):
    config = docker.inspect(image)["Config"]
    assert config["User"] == "coldroute"
    assert "/srv/coldroute/data" in config["Volumes"]
    assert config["Healthcheck"]["Test"][0] == "CMD"
    missing = docker(
        "run", "--rm", "--network", "none", "--entrypoint", "sh", image, "-c",
        "for p in /wheelhouse /opt/coldroute/bin/pip /usr/bin/gcc /usr/bin/cc; do "
        "test -e $p || echo absent $p; done",
    )  # fmt: skip
    assert missing.split() == [
        word for p in ("/wheelhouse", "/opt/coldroute/bin/pip", "/usr/bin/gcc", "/usr/bin/cc")
        for word in ("absent", p)
    ]  # fmt: skip


def test_healthy_answers_plans_as_non_root_and_logs_json_lines(run_container):
    container: Container = run_container("coldroute-answers")
    took_s = container.wait_healthy(within_s=START_PERIOD_S)
    with container.client() as http:
        plan = http.post("/v1/plans", json=example("/v1/plans", "vienna-8-stops"))
        fleet = http.post("/v1/fleet-plans", json=example("/v1/fleet-plans", "vienna-two-vans"))
        health = http.get("/healthz")
        # the viewer and the libraries vendored beside it, from the image's own files
        viewer = http.get("/viewer")
        libraries = [
            http.get(f"/viewer/static/vendor/{path}")
            for path in ("leaflet/leaflet.js", "leaflet/LICENSE", "uplot/uPlot.iife.min.js")
        ]
        # the guide, built into the image
        guide = http.get("/guide/engineers/model/")
        katex = http.get("/guide/assets/katex/katex.min.js")
    assert viewer.status_code == 200 and "leaflet.js" in viewer.text
    assert guide.status_code == 200 and "The model" in guide.text
    assert katex.status_code == 200
    assert [r.status_code for r in libraries] == [200, 200, 200]
    assert plan.status_code == 200, plan.text
    assert len(plan.json()["stops"]) == 8 and plan.json()["battery"]["feasible"]
    assert fleet.status_code == 200, fleet.text
    served = sum(len(route["stops"]) for route in fleet.json()["routes"])
    unassigned = len(fleet.json()["unassigned"])
    assert served + unassigned == len(example("/v1/fleet-plans", "vienna-two-vans")["stops"])
    assert served > 0
    assert health.json()["status"] == "ok"

    # The server, PID 1 of the container, runs as the image's user, not as root.
    status = container.docker("exec", container.name, "cat", "/proc/1/status")
    uid = next(line.split()[1:] for line in status.splitlines() if line.startswith("Uid:"))
    assert uid[0] == uid[1] != "0"

    # stdout only: one JSON object per line, one line per request with its status.
    container.keep_logs("answers")
    stdout = container.docker("logs", container.name)
    lines = [json.loads(line) for line in stdout.splitlines()]
    requests = [line for line in lines if line.get("message") == "request"]
    by_path = {(line["path"], line["status"]) for line in requests}
    assert {("/v1/plans", 200), ("/v1/fleet-plans", 200), ("/healthz", 200)} <= by_path
    assert all("request_id" in line and "duration_ms" in line for line in requests)
    assert took_s < START_PERIOD_S


def test_a_job_outlives_its_container_on_the_volume(run_container, docker: Docker):
    first: Container = run_container("coldroute-jobs")
    first.wait_healthy(within_s=START_PERIOD_S)
    with first.client() as http:
        submitted = http.post("/v1/jobs", json=example("/v1/jobs", "plan"))
        assert submitted.status_code in (200, 201, 202), submitted.text
        job_id = submitted.json()["id"]
        deadline = time.monotonic() + 120
        while (job := http.get(f"/v1/jobs/{job_id}").json())["status"] not in (
            "succeeded",
            "failed",
        ):
            assert time.monotonic() < deadline, job
            time.sleep(0.5)
    assert job["status"] == "succeeded", job
    docker("stop", first.name, timeout_s=60)
    docker("rm", first.name)

    second: Container = run_container("coldroute-jobs")  # a new container, the same volume
    second.wait_healthy(within_s=START_PERIOD_S)
    with second.client() as http:
        again = http.get(f"/v1/jobs/{job_id}")
    assert again.status_code == 200
    assert again.json()["status"] == "succeeded"
    assert again.json()["result"] == job["result"]


def long_fleet() -> dict:
    """60 stops around Vienna and a 60 s budget: a solve well under way when the stop comes."""
    body = example("/v1/fleet-plans", "vienna-two-vans")
    del body["replay"]  # the example's record replays the example, not these 60 stops
    del body["work_s"]  # the example's work is 2 s's: this solve has the default work of 60 s
    rng = np.random.default_rng(7)
    body["stops"] = [
        {
            "id": f"s{k}",
            "lat": round(48.21 + rng.uniform(-0.06, 0.06), 5),
            "lon": round(16.37 + rng.uniform(-0.09, 0.09), 5),
            "service_time_s": 300,
            "delivery_kg": 5,
        }
        for k in range(60)
    ]
    body["time_limit_s"] = 60
    return body


def test_docker_stop_with_a_long_solve_in_flight_exits_within_10_s(run_container, docker: Docker):
    container: Container = run_container("coldroute-stop")
    container.wait_healthy(within_s=START_PERIOD_S)
    answers: list[httpx.Response | Exception] = []

    def solve() -> None:
        try:
            with container.client(timeout_s=90) as http:
                answers.append(http.post("/v1/fleet-plans", json=long_fleet()))
        except httpx.HTTPError as error:
            answers.append(error)

    solving = threading.Thread(target=solve)
    solving.start()
    time.sleep(3)  # the solve is under way
    assert not answers, answers
    began = time.monotonic()
    docker("stop", container.name, timeout_s=60)
    stopped_s = time.monotonic() - began
    solving.join(timeout=30)
    state = docker.inspect(container.name)["State"]
    container.keep_logs("stop")
    assert stopped_s < DOCKER_STOP_S
    assert state["ExitCode"] != 137  # not killed: it exited on its own
    assert len(answers) == 1 and isinstance(answers[0], httpx.Response), answers
    assert answers[0].status_code in (200, 503), answers[0].text
