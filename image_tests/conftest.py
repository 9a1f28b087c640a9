"""The Docker image as an operator gets it, on a machine without Docker Hub: ``make test-image``.

This session's own ``dockerd`` (Debian's ``docker.io``, as root: the vfs storage driver, no
iptables, no bridge, its own data root and socket), a base image made by ``debootstrap`` from
Debian's packages and ``docker import``, and the image built from the ``Dockerfile`` with
``--network none`` from the wheelhouse ``make wheelhouse`` made. Everything it made goes at the
end: containers, volumes, images, the daemon and its folders. Not part of ``make test``: a
laptop without Docker still runs the test suite.
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import httpx
import pytest

ROOT = Path(__file__).resolve().parents[1]
#: What the image is called here, and the base it is built on.
IMAGE = "coldroute:image-test"
BASE = "coldroute-base:bookworm"
#: Debian's packages the base needs beyond minbase: Python 3.11 with its venv module.
BASE_PACKAGES = "python3,python3-venv,ca-certificates"
ARTIFACTS = ROOT / "test-artifacts" / "image"


@dataclass
class Docker:
    """The ``docker`` client on this session's daemon."""

    socket_path: Path
    made: list[tuple[str, str]] = field(default_factory=list)  # (kind, name) to remove

    def __call__(self, *args: str, timeout_s: float = 600, check: bool = True) -> str:
        run = subprocess.run(
            ["docker", "-H", f"unix://{self.socket_path}", *args],
            capture_output=True,
            text=True,
            timeout=timeout_s,
        )
        if check and run.returncode != 0:
            raise AssertionError(f"docker {' '.join(args)}: {run.stderr[-3000:]}")
        return run.stdout

    def inspect(self, name: str) -> dict:
        return json.loads(self("inspect", name))[0]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _unmount_under(folder: Path) -> None:
    """What the daemon left mounted in ``folder`` (its network namespace files), deepest
    first, so the folder can go."""
    with open("/proc/mounts") as mounts:
        points = [line.split()[1] for line in mounts]
    for point in sorted((p for p in points if p.startswith(f"{folder}/")), reverse=True):
        subprocess.run(["umount", "-l", point], capture_output=True, check=False)


@pytest.fixture(scope="session")
def docker() -> Iterator[Docker]:
    if os.geteuid() != 0:
        pytest.fail("make test-image starts its own dockerd and runs debootstrap: run it as root")
    if shutil.which("docker") is None or shutil.which("dockerd") is None:
        pytest.fail("no docker/dockerd: make test-image installs Debian's docker.io")
    work = Path(tempfile.mkdtemp(prefix="coldroute-docker-", dir="/var/tmp"))
    client = Docker(work / "docker.sock")
    log = (work / "dockerd.log").open("w")
    daemon = subprocess.Popen(
        [
            "dockerd",
            "--storage-driver=vfs",
            "--iptables=false",
            "--bridge=none",
            f"--data-root={work / 'root'}",
            f"--exec-root={work / 'exec'}",
            f"--pidfile={work / 'dockerd.pid'}",
            f"--host=unix://{client.socket_path}",
        ],
        stdout=log,
        stderr=subprocess.STDOUT,
    )
    try:
        deadline = time.monotonic() + 60
        while client("version", check=False, timeout_s=10) == "" or not client.socket_path.exists():
            if daemon.poll() is not None or time.monotonic() > deadline:
                pytest.fail(f"dockerd did not start: {(work / 'dockerd.log').read_text()[-3000:]}")
            time.sleep(0.5)
        yield client
    finally:
        for kind, name in reversed(client.made):
            client(kind, "rm", "-f", name, check=False, timeout_s=120)
        daemon.terminate()
        try:
            daemon.wait(timeout=30)
        except subprocess.TimeoutExpired:
            daemon.kill()
            daemon.wait()
        log.close()
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        shutil.copy(work / "dockerd.log", ARTIFACTS / "dockerd.log")
        _unmount_under(work)
        shutil.rmtree(work, ignore_errors=True)


@pytest.fixture(scope="session")
def image(docker: Docker) -> str:
    """The base from Debian's packages, then the image on it, built without network."""
    wheelhouse = ROOT / "wheelhouse"
    if not any(wheelhouse.glob("coldroute-*.whl")):
        pytest.fail("no wheelhouse/coldroute-*.whl: make test-image runs make wheelhouse first")
    with tempfile.TemporaryDirectory(prefix="coldroute-base-", dir="/var/tmp") as folder:
        base = f"{folder}/rootfs"  # made by debootstrap: a root of 0755, not the temp's 0700
        subprocess.run(
            ["debootstrap", "--variant=minbase", f"--include={BASE_PACKAGES}", "bookworm", base],
            check=True,
            capture_output=True,
            timeout=900,
        )
        tar = subprocess.Popen(["tar", "-C", base, "-c", "."], stdout=subprocess.PIPE)
        imported = subprocess.run(
            ["docker", "-H", f"unix://{docker.socket_path}", "import", "-", BASE],
            stdin=tar.stdout,
            capture_output=True,
            text=True,
            check=False,
        )
        tar.wait()
        assert imported.returncode == 0, imported.stderr
    docker.made.append(("image", BASE))
    docker.made.append(("image", IMAGE))
    docker("build", "--network", "none", "--build-arg", f"BASE={BASE}", "-t", IMAGE, str(ROOT))
    docker("image", "prune", "-f")  # the build stage, with the wheelhouse, is not kept
    return IMAGE


@dataclass
class Container:
    """A container of the image on the host's network, answering on ``port``."""

    docker: Docker
    name: str
    port: int

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def health(self) -> str:
        return str(self.docker.inspect(self.name)["State"]["Health"]["Status"])

    def wait_healthy(self, within_s: float) -> float:
        """Seconds until its own HEALTHCHECK says healthy; fails after ``within_s``."""
        began = time.monotonic()
        while (status := self.health()) != "healthy":
            assert status != "unhealthy", self.docker("logs", self.name)[-3000:]
            if time.monotonic() - began >= within_s:
                health = self.docker.inspect(self.name)["State"]["Health"]
                raise AssertionError(
                    f"still {status} after {within_s} s; its checks: {health['Log'][-3:]}; "
                    f"its log: {self.docker('logs', self.name)[-3000:]}"
                )
            time.sleep(0.5)
        return time.monotonic() - began

    def client(self, timeout_s: float = 60) -> httpx.Client:
        return httpx.Client(base_url=self.url, timeout=timeout_s)

    def keep_logs(self, label: str) -> None:
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        (ARTIFACTS / f"{label}.log").write_text(self.docker("logs", self.name))


@pytest.fixture
def run_container(docker: Docker, image: str, request: pytest.FixtureRequest):
    """Start a container of the image as an operator would: detached, on a named volume for
    its job database, on the host's network (no bridge here) at a free port."""
    counter = iter(range(100))

    def start(volume: str, *env: str) -> Container:
        name = f"coldroute-{request.node.name[:40]}-{next(counter)}".replace("[", "-")
        name = "".join(c if c.isalnum() or c in "-_." else "-" for c in name)
        if ("volume", volume) not in docker.made:
            docker("volume", "create", volume)
            docker.made.insert(0, ("volume", volume))
        port = _free_port()
        args = [
            "run",
            "-d",
            "--name",
            name,
            "--network",
            "host",
            "-v",
            f"{volume}:/srv/coldroute/data",
        ]
        args += ["-e", f"COLDROUTE_PORT={port}", "-e", "COLDROUTE_WORKERS=2"]
        for setting in env:
            args += ["-e", setting]
        docker(*args, image)
        docker.made.append(("container", name))
        return Container(docker, name, port)

    return start


def example(path: str, name: str) -> dict:
    """A request body from the committed OpenAPI document's examples."""
    document = json.loads((ROOT / "openapi" / "openapi.json").read_text())
    content = document["paths"][path]["post"]["requestBody"]["content"]["application/json"]
    return dict(content["examples"][name]["value"])
