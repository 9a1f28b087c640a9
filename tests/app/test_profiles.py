"""Vehicle profiles: named vans kept in the service's database and used wherever a preset is."""

from __future__ import annotations

import copy
import uuid

import httpx
import pytest

from app.database import Database
from app.examples import (
    CALIBRATION_EXAMPLE,
    FLEET_PLAN_EXAMPLE,
    PLAN_EXAMPLE,
    SIMULATE_EXAMPLE,
    SPEED_SWEEP_EXAMPLE,
)
from app.profiles import ProfileStore
from core.params import PRESETS
from testbed.services import Server
from tests.app.test_celery import own_services
from tests.app.test_jobs import submit, wait_for

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

#: The reefer preset as one fleet runs it: heavier (and rated heavier), a bigger pack, a better
#: box.
CHANGES = {
    "vehicle": {"mass_kg": 3100.0, "gross_mass_kg": 3600.0, "drag_coefficient": 0.36},
    "battery": {"usable_capacity_kwh": 75.0},
    "cargo_box": {"wall_heat_transfer_w_m2k": 0.3},
    "payload_kg": 420.0,
}


def unique(prefix: str) -> str:
    return f"{prefix}-{uuid.uuid4().hex[:8]}"


def make_profile(client, **extra) -> str:
    name = unique("van")
    body = {
        "name": name,
        "description": "our reefers",
        "vehicle": {"preset": "ev-van-3.5t-reefer"} | CHANGES["vehicle"],
        "battery": CHANGES["battery"],
        "cargo_box": CHANGES["cargo_box"],
        "payload_kg": CHANGES["payload_kg"],
    } | extra
    made = client.post("/v1/vehicle-profiles", json=body)
    assert made.status_code == 201, made.text
    assert made.headers["Location"] == f"/v1/vehicle-profiles/{name}"
    return name


def with_van(body: dict, van: dict) -> dict:
    """A request body with its van sections replaced by ``van``'s."""
    changed = copy.deepcopy(body)
    for section in ("vehicle", "battery", "cargo_box", "payload_kg"):
        changed.pop(section, None)
    return changed | van


def preset_van() -> dict:
    return {
        "vehicle": {"preset": "ev-van-3.5t-reefer"} | CHANGES["vehicle"],
        "battery": CHANGES["battery"],
        "cargo_box": CHANGES["cargo_box"],
        "payload_kg": CHANGES["payload_kg"],
    }


def test_a_profile_keeps_every_value_of_its_preset_and_changes(client):
    name = make_profile(client)
    profile = client.get(f"/v1/vehicle-profiles/{name}").json()
    preset = PRESETS["ev-van-3.5t-reefer"]
    assert profile["vehicle"]["mass_kg"] == 3100.0
    assert profile["vehicle"]["drag_coefficient"] == 0.36
    assert profile["vehicle"]["frontal_area_m2"] == preset.vehicle.frontal_area_m2
    assert profile["battery"]["usable_capacity_kwh"] == 75.0
    assert profile["cargo_box"]["wall_heat_transfer_w_m2k"] == 0.3
    assert profile["cargo_box"]["volume_m3"] == preset.cargo_box.volume_m3
    assert profile["payload_kg"] == 420.0
    assert profile["description"] == "our reefers" and profile["calibration"] is None
    assert name in [p["name"] for p in client.get("/v1/vehicle-profiles").json()["profiles"]]


@pytest.mark.parametrize(
    ("path", "example"),
    [("/v1/plans", PLAN_EXAMPLE), ("/v1/simulate", SIMULATE_EXAMPLE)],
)
def test_a_plan_on_a_profile_is_the_plan_on_its_preset_and_changes(client, path, example):
    name = make_profile(client)
    base = with_van(example, {})
    by_profile = client.post(path, json=base | {"vehicle": {"profile": name}})
    by_preset = client.post(path, json=with_van(example, preset_van()))
    assert by_profile.status_code == by_preset.status_code == 200, by_profile.text
    first, second = by_profile.json(), by_preset.json()
    for answer in (first, second):
        answer.get("solver", {}).pop("runtime_s", None)
    assert first == second
    # and it is not the preset's own answer: the changes count
    plain = client.post(path, json=base | {"vehicle": {"preset": "ev-van-3.5t-reefer"}}).json()
    plain.get("solver", {}).pop("runtime_s", None)
    assert plain != first


def test_changes_beside_a_profile_apply_on_top_for_that_request_only(client):
    name = make_profile(client)
    body = with_van(SIMULATE_EXAMPLE, {})
    on_top = client.post(
        "/v1/simulate",
        json=body | {"vehicle": {"profile": name, "mass_kg": 2500.0}, "payload_kg": 0.0},
    ).json()
    van = preset_van()
    van["vehicle"] = van["vehicle"] | {"mass_kg": 2500.0}
    expected = client.post("/v1/simulate", json=with_van(body, van | {"payload_kg": 0.0})).json()
    assert on_top == expected
    assert client.get(f"/v1/vehicle-profiles/{name}").json()["vehicle"]["mass_kg"] == 3100.0


def test_fleets_studies_and_jobs_take_profiles(client, tmp_path):
    name = make_profile(client)
    fleet = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    fleet["vehicles"][0] = with_van(fleet["vehicles"][0], {"vehicle": {"profile": name}})
    planned = client.post("/v1/fleet-plans", json=fleet)
    assert planned.status_code == 200, planned.text
    sweep = with_van(SPEED_SWEEP_EXAMPLE, {"vehicle": {"profile": name}})
    by_profile = client.post("/v1/studies/speed-sweep", json=sweep).json()
    by_preset = client.post(
        "/v1/studies/speed-sweep", json=with_van(SPEED_SWEEP_EXAMPLE, preset_van())
    ).json()
    assert by_profile == by_preset


def test_an_unknown_profile_is_a_422_naming_it_wherever_a_van_is(client):
    missing = {"vehicle": {"profile": "no-such-van"}}
    plan = client.post("/v1/plans", json=with_van(PLAN_EXAMPLE, missing))
    assert plan.status_code == 422
    assert plan.json()["errors"][0]["field"] == "vehicle.profile"
    assert "no-such-van" in plan.json()["detail"]
    fleet = copy.deepcopy(FLEET_PLAN_EXAMPLE)
    fleet["vehicles"][1] = with_van(fleet["vehicles"][1], missing)
    answer = client.post("/v1/fleet-plans", json=fleet)
    assert answer.status_code == 422
    assert answer.json()["errors"][0]["field"] == "vehicles[1].vehicle.profile"
    sweep = client.post("/v1/studies/speed-sweep", json=with_van(SPEED_SWEEP_EXAMPLE, missing))
    assert sweep.json()["errors"][0]["field"] == "vehicle.profile"
    job = client.post("/v1/jobs", json={"type": "plan", "request": with_van(PLAN_EXAMPLE, missing)})
    assert job.status_code == 422
    assert job.json()["errors"][0]["field"] == "request.vehicle.profile"
    both = {"vehicle": {"profile": make_profile(client), "preset": "paper-generic"}}
    refused = client.post("/v1/plans", json=with_van(PLAN_EXAMPLE, both))
    assert refused.json()["errors"][0]["field"] == "vehicle.preset"


def test_a_profile_from_a_calibration_is_the_van_it_fitted(client):
    fit = client.post("/v1/calibrations", json=CALIBRATION_EXAMPLE)
    assert fit.status_code == 200, fit.text
    fitted = fit.json()
    name = unique("fitted")
    made = client.post(
        "/v1/vehicle-profiles",
        json={"name": name, "calibration_id": fitted["id"], "battery": {"min_soc": 0.2}},
    )
    assert made.status_code == 201, made.text
    profile = made.json()
    for parameter, value in fitted["vehicle"].items():
        assert profile["vehicle"][parameter] == value
    starting = PRESETS[CALIBRATION_EXAMPLE["vehicle"]["preset"]]
    assert profile["vehicle"]["mass_kg"] == starting.vehicle.mass_kg
    assert profile["battery"]["min_soc"] == 0.2
    # the profile records the fit it came from, figures included
    assert profile["calibration"]["id"] == fitted["id"]
    assert profile["calibration"]["parameters"] == fitted["parameters"]
    assert profile["calibration"]["trips"] == fitted["trips"]
    unknown = client.post(
        "/v1/vehicle-profiles", json={"name": unique("x"), "calibration_id": str(uuid.uuid4())}
    )
    assert unknown.status_code == 422 and unknown.json()["errors"][0]["field"] == "calibration_id"
    mixed = client.post(
        "/v1/vehicle-profiles",
        json={
            "name": unique("x"),
            "calibration_id": fitted["id"],
            "vehicle": {"preset": "paper-generic"},
        },
    )
    assert mixed.status_code == 422 and mixed.json()["errors"][0]["field"] == "vehicle.preset"


def test_put_creates_then_replaces_and_delete_forgets(client):
    name = unique("van")
    path = f"/v1/vehicle-profiles/{name}"
    body = with_van(SIMULATE_EXAMPLE, {"vehicle": {"profile": name}})
    created = client.put(path, json={"vehicle": {"preset": "paper-generic"}})
    assert created.status_code == 201 and created.headers["Location"] == path
    light = client.post("/v1/simulate", json=body).json()
    replaced = client.put(path, json={"vehicle": {"preset": "paper-generic", "mass_kg": 2600}})
    assert replaced.status_code == 200 and replaced.json()["vehicle"]["mass_kg"] == 2600
    assert replaced.json()["created_at"] == created.json()["created_at"]
    assert replaced.json()["updated_at"] > created.json()["updated_at"]
    heavy = client.post("/v1/simulate", json=body).json()
    assert heavy["energy_kwh"]["traction"] > light["energy_kwh"]["traction"]
    assert client.delete(path).status_code == 204
    assert client.get(path).status_code == 404
    assert client.delete(path).status_code == 404
    gone = client.post("/v1/simulate", json=body)
    assert gone.status_code == 422 and gone.json()["errors"][0]["field"] == "vehicle.profile"


@pytest.mark.parametrize(
    ("method", "path", "body", "status", "field"),
    [
        ("post", "", {"vehicle": {"preset": "paper-generic"}}, 422, "name"),
        ("post", "", {"name": "a b"}, 422, "name"),
        ("post", "", {"name": "x" * 65}, 422, "name"),
        ("post", "", {"name": "ok", "battery": {"usable_capacity_kwh": -1}}, 422,
         "battery.usable_capacity_kwh"),
        ("post", "", {"name": "ok", "vehicle": {"preset": "no-such-preset"}}, 422,
         "vehicle.preset"),
        ("post", "", {"name": "ok", "colour": "white"}, 422, "colour"),
        ("put", "/right-name", {"name": "other-name"}, 422, "name"),
        ("put", "/bad%20name", {}, 422, "path.name"),
        # a URL path reads these as steps: the profile could never be reached again
        ("post", "", {"name": "."}, 422, "name"),
        ("post", "", {"name": ".."}, 422, "name"),
    ],
)  # fmt: skip
def test_bad_profiles_are_refused_naming_the_field(client, method, path, body, status, field):
    answer = getattr(client, method)(f"/v1/vehicle-profiles{path}", json=body)
    assert answer.status_code == status, answer.text
    assert field in [e["field"] for e in answer.json()["errors"]]


def test_a_name_in_use_is_a_409_and_the_profile_stays(client):
    name = make_profile(client)
    again = client.post("/v1/vehicle-profiles", json={"name": name})
    assert again.status_code == 409 and "PUT" in again.json()["detail"]
    assert client.get(f"/v1/vehicle-profiles/{name}").json()["vehicle"]["mass_kg"] == 3100.0


def test_profiles_are_shared_by_replicas_on_postgresql_and_outlive_them():
    with own_services() as env:
        database = {"COLDROUTE_DATABASE_URL": env["COLDROUTE_DATABASE_URL"]}
        one = Server(database | {"COLDROUTE_WORKERS": "1"}).start()
        other = Server(database | {"COLDROUTE_WORKERS": "1"}).start()
        try:
            made = httpx.post(
                f"{one.url}/v1/vehicle-profiles",
                json={"name": "van-17"} | preset_van(),
                timeout=30,
            )
            assert made.status_code == 201, made.text
            body = with_van(PLAN_EXAMPLE, {"vehicle": {"profile": "van-17"}})
            on_other = httpx.post(f"{other.url}/v1/plans", json=body, timeout=60)
            assert on_other.status_code == 200, on_other.text
            job = submit(other.url, {"type": "plan", "request": body}).json()
            done = wait_for(other.url, job["id"])
            assert done["status"] == "succeeded"
            done["result"]["solver"].pop("runtime_s")
            direct = on_other.json()
            direct["solver"].pop("runtime_s")
            assert done["result"] == direct
        finally:
            one.close()
            other.close()
        # Both servers are gone: the profile is in PostgreSQL, for the next one to start.
        kept = ProfileStore(Database(env["COLDROUTE_DATABASE_URL"])).get("van-17")
        assert kept is not None and kept.van.battery.usable_capacity_kwh == 75


def test_a_profile_from_a_calibration_differs_from_its_van_only_in_what_was_fitted(client):
    """The trust issue: the 300 kg the measured trips carried became the profile's payload
    (the preset carries more), and a fleet on that profile left stops out as "the fleet is
    full". A profile keeps exactly what the fit fitted, and nothing else of the trips."""
    body = copy.deepcopy(CALIBRATION_EXAMPLE) | {"payload_kg": 300.0}
    body["vehicle"] = body["vehicle"] | {"mass_kg": 3000.0}  # a fact of the van: kept
    fitted = client.post("/v1/calibrations", json=body).json()
    made = client.post(
        "/v1/vehicle-profiles", json={"name": unique("fitted"), "calibration_id": fitted["id"]}
    ).json()
    preset = PRESETS[CALIBRATION_EXAMPLE["vehicle"]["preset"]].van()
    start = preset.model_copy(
        update={"vehicle": preset.vehicle.model_copy(update={"mass_kg": 3000.0})}
    ).model_dump(mode="json")
    assert made["payload_kg"] == preset.payload_kg != 300.0
    for section in ("vehicle", "cargo_box", "battery"):
        changed = {k for k, v in made[section].items() if v != start[section][k]}
        expected = set(fitted.get(section, {})) if section != "battery" else set()
        assert changed == {k for k in expected if fitted[section][k] != start[section][k]}
    for name, value in fitted["vehicle"].items():
        assert made["vehicle"][name] == value


def test_put_and_delete_racing_on_one_name_never_fail():
    """The audit: 5 of 120 PUTs racing DELETEs of the same profile on PostgreSQL were 500s
    (the row went between the read and the update). Ten threads, PostgreSQL as the machines
    run it: every answer is one of the documented ones, and the profile ends as one PUT
    wrote it or deleted."""
    import concurrent.futures

    with own_services() as env:
        server = Server(
            {"COLDROUTE_DATABASE_URL": env["COLDROUTE_DATABASE_URL"], "COLDROUTE_WORKERS": "1"}
        ).start()
        try:
            path = f"{server.url}/v1/vehicle-profiles/raced"

            def one(k: int) -> int:
                if k % 2:
                    return httpx.delete(path, timeout=30).status_code
                body = {"vehicle": {"preset": "paper-generic", "mass_kg": 2000.0 + k}}
                return httpx.put(path, json=body, timeout=30).status_code

            with concurrent.futures.ThreadPoolExecutor(10) as pool:
                statuses = list(pool.map(one, range(120)))
            final = httpx.get(path, timeout=30)
        finally:
            server.close()
    assert set(statuses) <= {200, 201, 204, 404, 409}, statuses
    assert statuses.count(200) + statuses.count(201) >= 50
    assert final.status_code in (200, 404)
    if final.status_code == 200:
        assert final.json()["vehicle"]["mass_kg"] in {2000.0 + k for k in range(0, 120, 2)}
