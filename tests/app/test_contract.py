"""Contract: Schemathesis drives every operation of the served OpenAPI document against the real
server, with every phase (examples, coverage, fuzzing, stateful) and every check — no 5xx, every
answer as documented, schema-violating requests refused (schemathesis.toml says why some
schema-valid ones may get a 422; use_after_free is left out, see below)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from testbed.services import Server

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

KEY = "contract-key"
#: ``st``, with room on the stack: Hypothesis describes its lambdas by parsing their source
#: file, and where Schemathesis's schema walk is deep already that parse hits the recursion
#: limit and leaves CPython 3.11.7's AST depth counter wrong — the next parse fails with
#: "SystemError: AST constructor recursion depth mismatch" (CPython gh-106905), a failure of
#: the tool, not of the service.
SCHEMATHESIS = [
    sys.executable,
    "-c",
    "import sys; sys.setrecursionlimit(20_000); sys.argv[0] = 'st'; "
    "from schemathesis.cli import schemathesis; sys.exit(schemathesis())",
]
ROOT = Path(__file__).resolve().parents[2]


def test_every_phase_and_check_passes():
    server = Server(
        {
            "COLDROUTE_WORKERS": "2",
            "COLDROUTE_API_KEY": KEY,
            "COLDROUTE_MAX_STOPS": "12",
            "COLDROUTE_MAX_TRACE_SAMPLES": "20000",
            "COLDROUTE_MAX_TIME_LIMIT_S": "0.05",
            "COLDROUTE_MAX_JOB_TIME_LIMIT_S": "0.05",
            "COLDROUTE_MAX_BODY_BYTES": "200000",
            "COLDROUTE_MAX_STUDY_CELL_STOPS": "100",
            "COLDROUTE_MAX_SYNC_ROUTE_DAYS": "20",
            "COLDROUTE_MAX_ROUTE_DAYS": "100",
        }
    ).start()
    try:
        run = _schemathesis(server)
        if run.returncode and CPYTHON_AST_BUG in run.stdout + run.stderr:
            # the tool's own failure (below): once more, with one worker (no thread races)
            run = _schemathesis(server, workers=1)
        log = server.log_path.read_text()
    finally:
        server.close()
    assert run.returncode == 0, run.stdout[-20_000:] + run.stderr[-2_000:] + log[-5_000:]


#: How CPython 3.11's AST depth counter (gh-106905) fails inside Schemathesis: seen once in
#: several full runs with two Schemathesis workers (twice in a row on a busy machine), never in
#: the service's answers; it races between threads, so one worker does not meet it.
CPYTHON_AST_BUG = "AST constructor recursion depth mismatch"


def _schemathesis(server: Server, workers: int = 2) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [
            *SCHEMATHESIS,
            "run",
            f"{server.url}/openapi.json",
            "--phases",
            "examples,coverage,fuzzing,stateful",
            "--checks",
            "all",
            # DELETE /v1/jobs/{id} cancels and keeps the job readable ("cancelled"), as the
            # jobs API promises; "a deleted resource is gone" does not apply to it.
            "--exclude-checks",
            "use_after_free",
            "--max-examples",
            os.environ.get("COLDROUTE_CONTRACT_EXAMPLES", "10"),
            "--header",
            f"X-API-Key: {KEY}",
            "--generation-deterministic",
            "--request-timeout",
            "60",
            # The Swagger examples carry their replays, which do the work recorded whatever
            # the server's cap (a 2 s search's): 12 s on a busy machine, queued behind others.
            "--max-response-time",
            "60",
            "--workers",
            str(workers),
            "--no-color",
        ],
        cwd=ROOT,  # schemathesis.toml
        capture_output=True,
        text=True,
        timeout=540,
    )
