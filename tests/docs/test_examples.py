"""Every example of the README and the guides runs as its reader would run it — the requests
with bash and curl against the real service, the Python as it is — and answers what the page
says it answers (tests/docs/examples.py says how a page's blocks are read)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from app.settings import Settings
from testbed.services import Server
from tests.docs.examples import (
    ROOT,
    SERVICE,
    SETUP,
    Block,
    blocks,
    last_json,
    matches,
    pages,
    same_output,
)

#: Starts servers or outside services, or runs full searches: make check, not make test.
pytestmark = pytest.mark.slow

#: Pages whose files are run through the plan viewer (tests/docs/test_site.py), not a request.
VIEWER_PAGES = {"docs/dispatchers/viewer.md"}
PAGES = [p for p in pages() if any(b.is_request or b.language == "python" for b in blocks(p))]


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    started = Server({"COLDROUTE_WORKERS": "2"}).start()
    yield started
    started.close()


def _run(block: Block, folder: Path, url: str) -> str:
    text = SERVICE.sub(url, block.text)
    if block.language == "sh":
        command = ["bash", "-euo", "pipefail", "-c", text]
    else:
        command = [sys.executable, "-c", text]
    done = subprocess.run(
        command,
        cwd=folder,
        env=os.environ | {"PYTHONPATH": str(ROOT)},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, f"{block.name}: {done.stderr[-2000:]}"
    return done.stdout


@pytest.mark.parametrize("page", PAGES, ids=[str(p.relative_to(ROOT)) for p in PAGES])
def test_every_example_of_the_page_answers_what_it_shows(server, page, tmp_path):
    found = blocks(page)
    checked = 0
    for index, block in enumerate(found):
        following = found[index + 1] if index + 1 < len(found) else None
        if block.title:
            (tmp_path / block.title).write_text(block.text, encoding="utf-8")
        elif block.is_request or block.language == "python":
            output = _run(block, tmp_path, server.url)
            if following and following.title is None and following.language == "json":
                shown = json.loads(following.text)
                assert matches(shown, last_json(output)) == [], following.name
                checked += 1
            elif following and following.title is None and following.language == "text":
                assert same_output(following.text, output) == [], following.name
                checked += 1
    assert checked, f"{page}: no example shows what it answers"


def _kind(block: Block, previous: Block | None) -> str:
    if block.title:
        return "file"
    if block.is_request:
        return "request"
    if block.language == "python":
        return "program"
    after_run = previous is not None and (previous.is_request or previous.language == "python")
    if block.language in ("json", "text") and after_run:
        return "shown answer"
    if block.language == "text":
        return "drawing"
    if block.language == "sh":
        return "set-up"
    return "unknown"


def test_every_block_of_every_page_is_an_example_the_tests_read():
    """No block the tests would pass over: each is a file, a request, a program, what one
    answers, a drawing, or a machine's set-up."""
    for page in pages():
        found = blocks(page)
        for index, block in enumerate(found):
            previous = found[index - 1] if index else None
            assert _kind(block, previous) != "unknown", f"{block.name}: ```{block.language}"


def test_every_file_a_page_gives_is_used_by_an_example_after_it():
    for page in pages():
        found = blocks(page)
        for index, block in enumerate(found):
            if not block.title or block.page in VIEWER_PAGES:
                continue
            later = " ".join(b.text for b in found[index + 1 :] if not b.title)
            assert block.title in later, f"{block.name}: {block.title} is used by no example"


def test_every_set_up_command_names_a_make_target_and_settings_that_exist():
    makefile = (ROOT / "Makefile").read_text()
    targets = set(re.findall(r"^([a-z][\w.-]*):", makefile, flags=re.MULTILINE))
    settings = {f"COLDROUTE_{name.upper()}" for name in Settings.model_fields}
    commands = 0
    for page in pages():
        found = blocks(page)
        for index, block in enumerate(found):
            if _kind(block, found[index - 1] if index else None) != "set-up":
                continue
            for command in block.commands():
                words = [w for w in command.split() if not re.match(r"^[A-Z_]+=", w)]
                assert words and words[0] in SETUP, f"{block.name}: {command!r}"
                if words[0] == "make":
                    named = [w for w in words[1:] if "=" not in w] or ["all"]
                    assert set(named) <= targets, f"{block.name}: make {named}"
                for variable in re.findall(r"COLDROUTE_[A-Z0-9_]+", command):
                    assert variable in settings, f"{block.name}: {variable}"
                commands += 1
    assert commands >= 10
