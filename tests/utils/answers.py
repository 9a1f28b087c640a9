"""An answer as canonical JSON without its timing fields: what two answers that must be the
same are compared by (a replay, a job beside the synchronous call, a recorded fingerprint)."""

from __future__ import annotations

import json
from typing import Any

#: The answer's fields that report timing: they differ between runs.
TIMING = ("runtime_s", "route_days_per_s")


def without_timing(answer: Any, digits: int | None = None) -> str:
    """``answer`` as canonical JSON text (keys sorted, compact) without its timing fields;
    with ``digits``, every float to that many significant digits."""

    def canonical(value: Any) -> Any:
        if isinstance(value, dict):
            return {k: canonical(v) for k, v in value.items() if k not in TIMING}
        if isinstance(value, list):
            return [canonical(v) for v in value]
        if isinstance(value, float) and digits is not None:
            return float(f"{value:.{digits}g}")
        return value

    return json.dumps(canonical(answer), sort_keys=True, separators=(",", ":"))
