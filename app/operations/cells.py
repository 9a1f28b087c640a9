"""The cells of a CSV file as spreadsheets and telematics exports write them: comma or
semicolon between cells (with semicolons a decimal comma is read as a point), numbers in ASCII
digits; a bad cell is an error naming its field."""

from __future__ import annotations

import math
import re

from core.exceptions import InvalidParameterError


def delimiter_of(header: str) -> str:
    """The file's delimiter, from its header row: a semicolon where it has more of them."""
    return ";" if header.count(";") > header.count(",") else ","


def header_of(row: list[str], field: str) -> list[str]:
    """The column names of a header row, trimmed; a name twice is an error naming ``field``
    (which column would a reader take? the last, silently, gave stops at latitude 0)."""
    header = [cell.strip() for cell in row]
    twice = next((name for k, name in enumerate(header) if name in header[:k]), None)
    if twice is not None:
        raise InvalidParameterError(
            f"the column {twice[:40]!r} is named twice in the header row", field
        )
    return header


#: A number as a spreadsheet writes one: ASCII digits, one point, an exponent. Python's
#: float() also reads ``1_0`` and other scripts' digits (``١٠``) as 10: not a telematics cell.
_CSV_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


def _infinite(text: str) -> float:
    """``inf`` or ``nan`` as float() reads them (refused as not finite), else ValueError."""
    value = float(text)
    if math.isfinite(value):
        raise ValueError(text)
    return value


def number(cell: str, delimiter: str, field: str) -> float:
    text = cell.strip()
    if delimiter == ";":
        text = text.replace(",", ".")
    try:
        value = float(text) if _CSV_NUMBER.fullmatch(text) else _infinite(text)
    except ValueError:
        raise InvalidParameterError(f"{cell[:40]!r} is not a number", field) from None
    if not math.isfinite(value):
        raise InvalidParameterError(f"{cell[:40]!r} is not a finite number", field)
    return value
