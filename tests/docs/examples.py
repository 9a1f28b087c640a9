"""The examples of the README and the guides, read as their readers would run them.

A page's fenced blocks, in order:

- a block with a ``title`` (```` ```json title="plan.json" ````, ``csv``…) is a file the
  commands after it use (``-d @plan.json``, ``-F history=@export.csv``);
- a ``sh`` block whose commands call the service (``curl`` at ``localhost:8000``) is a request:
  the tests run it with bash beside those files, against the running app;
- a ``json`` block without a title right after a request is its answer, shown in part: every
  field it shows is in the real answer, each number to the digits it shows, ``"…"`` standing
  for any value and a list ending in ``"…"`` for any further items;
- a ``python`` block is run as it is, and a ``text`` block right after it is its output, each
  number to the digits shown and every word as shown;
- any other ``sh`` block sets up a machine (``make``, ``docker``, settings): every ``make``
  target it names is in the Makefile and every ``COLDROUTE_`` variable is a setting.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
FENCE = re.compile(r"^```(\w+)?(?:\s+title=\"([^\"]+)\")?\s*$")
#: How the pages call the service.
SERVICE = re.compile(r"(https?://)?localhost:8000")
#: The first words of a machine's set-up commands.
SETUP = {"make", "docker", "debootstrap", "tar", "export", "celery", "curl"}


@dataclass(frozen=True)
class Block:
    page: str
    line: int
    language: str
    title: str | None
    text: str

    @property
    def name(self) -> str:
        return f"{self.page}:{self.line}"

    def commands(self) -> list[str]:
        """The block's commands: its lines joined where they end in a backslash or leave a
        quote open, without comments."""
        commands: list[str] = []
        pending = ""
        for line in self.text.splitlines():
            pending += line + "\n"
            if pending.rstrip().endswith("\\") or pending.count("'") % 2:
                continue
            command = re.sub(r"\s+#[^'\"]*$", "", pending.strip())
            if command and not command.startswith("#"):
                commands.append(command)
            pending = ""
        return commands

    @property
    def is_request(self) -> bool:
        return self.language == "sh" and any(SERVICE.search(c) for c in self.commands())


def pages() -> list[Path]:
    """The README and every guide page."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def blocks(page: Path) -> list[Block]:
    found: list[Block] = []
    lines = page.read_text(encoding="utf-8").splitlines()
    index = 0
    while index < len(lines):
        opened = FENCE.match(lines[index].strip()) if lines[index].startswith("```") else None
        if opened and lines[index].strip() != "```":
            end = next(i for i in range(index + 1, len(lines)) if lines[i].startswith("```"))
            language, title = opened.group(1) or "", opened.group(2)
            text = "\n".join(lines[index + 1 : end]) + "\n"
            found.append(Block(str(page.relative_to(ROOT)), index + 1, language, title, text))
            index = end + 1
        else:
            index += 1
    return found


def matches(shown: Any, real: Any, where: str = "answer") -> list[str]:
    """Where ``real`` differs from what ``shown`` shows of it (empty when it does not)."""
    if shown == "…":
        return []
    if isinstance(shown, dict):
        if not isinstance(real, dict):
            return [f"{where}: {real!r} is not an object"]
        return [
            miss
            for key, value in shown.items()
            for miss in (
                matches(value, real[key], f"{where}.{key}")
                if key in real
                else [f"{where}.{key} is missing"]
            )
        ]
    if isinstance(shown, list):
        if not isinstance(real, list):
            return [f"{where}: {real!r} is not a list"]
        open_ended = bool(shown) and shown[-1] == "…"
        items = shown[:-1] if open_ended else shown
        if len(real) < len(items) or (not open_ended and len(real) != len(items)):
            return [f"{where}: {len(real)} items, the page shows {len(items)}"]
        return [m for i, item in enumerate(items) for m in matches(item, real[i], f"{where}[{i}]")]
    if isinstance(shown, float | int) and not isinstance(shown, bool):
        return [] if same_figure(shown, real) else [f"{where}: {real!r}, the page says {shown!r}"]
    return [] if shown == real else [f"{where}: {real!r}, the page says {shown!r}"]


def same_figure(shown: float | int | str, real: Any) -> bool:
    """Whether ``real`` is the number ``shown``, to the digits shown."""
    if isinstance(real, bool) or not isinstance(real, int | float | str):
        return False
    digits = Decimal(str(shown)).as_tuple().exponent
    assert isinstance(digits, int)
    try:
        return round(Decimal(str(real)), -digits) == Decimal(str(shown))
    except ArithmeticError:
        return False


def same_output(shown: str, real: str) -> list[str]:
    """Where a program's output differs from what the page shows: word by word, numbers to
    the digits shown."""
    said, got = shown.split(), real.split()
    if len(said) != len(got):
        return [f"the output is {real!r}, the page shows {shown!r}"]
    pairs = zip(said, got, strict=True)
    return [f"{b!r}, the page says {a!r}" for a, b in pairs if not _same_word(a, b)]


def _same_word(shown: str, real: str) -> bool:
    """The same word but for its numbers, and each number to the digits shown."""
    number = re.compile(r"-?\d+(?:\.\d+)?")
    figures_a, figures_b = number.findall(shown), number.findall(real)
    return (
        number.split(shown) == number.split(real)
        and len(figures_a) == len(figures_b)
        and all(same_figure(a, b) for a, b in zip(figures_a, figures_b, strict=True))
    )


def last_json(text: str) -> Any:
    """The last JSON document a command printed."""
    decoder = json.JSONDecoder()
    found, index = None, 0
    text = text.strip()
    while index < len(text):
        found, end = decoder.raw_decode(text, index)
        index = end
        while index < len(text) and text[index].isspace():
            index += 1
    return found
