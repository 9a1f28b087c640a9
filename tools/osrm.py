"""The OSRM road router from the ``osrm-bindings`` wheel on PyPI (pinned), for one's own region.

The wheel carries the OSRM programs (``osrm-extract``, ``osrm-partition``, ``osrm-customize``,
``osrm-routed``) and the car profile; they need only libc and libstdc++, so they run beside any
Python. Commands::

    python -m tools.osrm install                    # fetch the programs into .router/
    python -m tools.osrm prepare region.osm.pbf     # extract, partition, customize (car)
    python -m tools.osrm serve region.osrm [--port 5000]

``make router PBF=region.osm.pbf`` and ``make router-serve`` call these.
"""

from __future__ import annotations

import argparse
import os
import shutil
import socket
import stat
import subprocess
import sys
import tempfile
import time
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

OSRM_VERSION = "26.10.0"
ROOT = Path(__file__).resolve().parents[1]
# Not ".osrm": OSRM cuts a path at the first ".osrm" it contains.
HOME = ROOT / ".router"
BIN = HOME / "osrm" / "bin"
PROFILES = HOME / "osrm" / "share" / "profiles"


def install() -> Path:
    """Download the pinned osrm-bindings wheel and unpack its programs; the bin folder."""
    routed = BIN / "osrm-routed"
    if routed.exists():
        return BIN
    HOME.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory() as download:
        subprocess.run(
            [
                sys.executable,
                "-m",
                "pip",
                "download",
                "--quiet",
                "--no-deps",
                "--only-binary=:all:",
                "--python-version",
                "3.12",
                "--platform",
                "manylinux_2_28_x86_64",
                "-d",
                download,
                f"osrm-bindings=={OSRM_VERSION}",
            ],
            check=True,
        )
        (wheel,) = Path(download).glob("osrm_bindings-*.whl")
        with zipfile.ZipFile(wheel) as archive:
            for name in archive.namelist():
                if name.startswith(("osrm/bin/", "osrm/share/profiles/")) and not name.endswith(
                    "/"
                ):
                    archive.extract(name, HOME)
    for program in BIN.iterdir():
        program.chmod(program.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return BIN


#: The extract formats osrm-extract reads; it names its output after the name without them.
EXTRACT_SUFFIXES = (".osm.pbf", ".osm.bz2", ".osm", ".pbf")


def prepare(pbf: Path, out_dir: Path | None = None) -> Path:
    """Extract, partition and customize an OpenStreetMap extract (``.osm.pbf``, ``.osm.bz2``
    or ``.osm``) with the car profile (MLD); the .osrm base."""
    install()
    out_dir = out_dir or pbf.parent
    out_dir.mkdir(parents=True, exist_ok=True)
    source = out_dir / pbf.name
    if source.resolve() != pbf.resolve():
        shutil.copyfile(pbf, source)
    suffix = next((s for s in EXTRACT_SUFFIXES if pbf.name.endswith(s)), "")
    base = out_dir / (pbf.name.removesuffix(suffix) + ".osrm")
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    subprocess.run([BIN / "osrm-extract", "-p", PROFILES / "car.lua", source], check=True, **quiet)
    subprocess.run([BIN / "osrm-partition", base], check=True, **quiet)
    subprocess.run([BIN / "osrm-customize", base], check=True, **quiet)
    return base


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def start(base: Path, port: int, max_table_size: int = 100) -> subprocess.Popen[bytes]:
    """osrm-routed on 127.0.0.1:``port``, ready to answer."""
    process = subprocess.Popen(
        [
            BIN / "osrm-routed",
            "--algorithm",
            "mld",
            "--ip",
            "127.0.0.1",
            "--port",
            str(port),
            "--max-table-size",
            str(max_table_size),
            base,
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise RuntimeError(f"osrm-routed exited with {process.returncode}")
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.2):
                return process
        except OSError:
            time.sleep(0.02)
    process.kill()
    raise RuntimeError("osrm-routed did not start within 30 s")


@contextmanager
def running(base: Path, max_table_size: int = 100) -> Iterator[str]:
    """A router on a free loopback port for the duration; yields its URL."""
    port = free_port()
    process = start(base, port, max_table_size)
    try:
        yield f"http://127.0.0.1:{port}"
    finally:
        process.terminate()
        process.wait(timeout=10)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m tools.osrm", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    commands.add_parser("install", help="fetch the OSRM programs into .router/")
    prep = commands.add_parser(
        "prepare", help="extract, partition, customize a .osm.pbf, .osm.bz2 or .osm"
    )
    prep.add_argument("pbf", type=Path)
    prep.add_argument("--out", type=Path, default=None, help="folder (default: beside the pbf)")
    serve = commands.add_parser("serve", help="run osrm-routed on 127.0.0.1")
    serve.add_argument("base", type=Path, help="the .osrm file prepare wrote, or its folder")
    serve.add_argument("--port", type=int, default=int(os.environ.get("OSRM_PORT", 5000)))
    serve.add_argument("--max-table-size", type=int, default=100)
    args = parser.parse_args(argv)
    if args.command == "install":
        print(install())
    elif args.command == "prepare":
        print(prepare(args.pbf, args.out))
    else:
        install()
        base = args.base
        if base.is_dir():
            found = sorted(base.glob("*.osrm.properties"))
            if not found:
                parser.error(f"no prepared region in {base}: run make router PBF=… first")
            base = found[0].with_suffix("")
        os.execv(
            BIN / "osrm-routed",
            [
                "osrm-routed",
                "--algorithm",
                "mld",
                "--ip",
                "127.0.0.1",
                "--port",
                str(args.port),
                "--max-table-size",
                str(args.max_table_size),
                str(base),
            ],
        )


if __name__ == "__main__":
    main()
