"""The core's functions stay readable: at most :data:`MOST_PARAMETERS` parameters each
(``self`` and ``cls`` aside), Numba kernels aside (their arrays are their arguments; a
kernel cannot take a dataclass). Related inputs travel together as one frozen dataclass
(``Drive``, ``Along``, ``SweepTrips``, ``GridAxes``)."""

from __future__ import annotations

import ast
from pathlib import Path

MOST_PARAMETERS = 7
CORE = Path(__file__).resolve().parents[2] / "core"


def parameters(function: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    args = function.args
    names = [*args.posonlyargs, *args.args, *args.kwonlyargs, args.vararg, args.kwarg]
    return sum(a is not None and a.arg not in ("self", "cls") for a in names)


def compiled(function: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    return any("jit" in ast.unparse(d) for d in function.decorator_list)


def too_many(source: str) -> list[str]:
    """The functions of ``source`` with more than :data:`MOST_PARAMETERS` parameters."""
    return [
        f"{node.name} ({parameters(node)})"
        for node in ast.walk(ast.parse(source))
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
        and parameters(node) > MOST_PARAMETERS
        and not compiled(node)
    ]


def test_the_count_sees_every_kind_of_parameter_and_spares_kernels():
    source = (
        "def f(self, a, /, b, c=1, *d, e, f, g, **h): ...\n"  # eight besides self
        "def k(a, b, c, d, e, f, g, h): ...\n"
        "@njit(cache=True)\ndef kernel(a, b, c, d, e, f, g, h): ...\n"
        "def fine(a, b, c, d, e, f, g): ...\n"
    )
    assert too_many(source) == ["f (8)", "k (8)"]


def test_no_function_in_the_core_takes_more_than_seven_parameters():
    found = {
        str(path.relative_to(CORE)): broken
        for path in sorted(CORE.rglob("*.py"))
        if (broken := too_many(path.read_text()))
    }
    assert found == {}
