"""The README names what the service has: every setting in its table, and no setting that
does not exist (a renamed or removed one would leave readers a knob that does nothing)."""

from __future__ import annotations

import re
from pathlib import Path

from app.settings import Settings

README = (Path(__file__).resolve().parents[2] / "README.md").read_text(encoding="utf-8")


def test_every_setting_is_in_the_readmes_table_and_every_one_named_exists():
    settings = {f"COLDROUTE_{name.upper()}" for name in Settings.model_fields}
    table = set(re.findall(r"^\| `(COLDROUTE_[A-Z0-9_]+)`", README, flags=re.MULTILINE))
    named = set(re.findall(r"COLDROUTE_[A-Z0-9_]+", README))
    assert sorted(settings - table) == []
    assert sorted(named - settings) == []


def test_the_readmes_defaults_are_the_codes():
    """Each plain default in the table (a number or a text in backticks) is the setting's."""
    rows = dict(re.findall(r"^\| `(COLDROUTE_[A-Z0-9_]+)` \| `([^`|]*)` \|", README, re.MULTILINE))
    compared = 0
    for name, field in Settings.model_fields.items():
        said = rows.get(f"COLDROUTE_{name.upper()}")
        default = field.default
        if said is None or isinstance(default, bool) or default is None:
            continue
        if isinstance(default, int | float):
            assert float(said) == float(default), name
            compared += 1
        elif isinstance(default, str):
            assert said == default, name
            compared += 1
    assert compared >= 20  # the table's plain defaults were read
