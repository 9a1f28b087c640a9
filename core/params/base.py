"""The base of every parameter model, and the text types requests use for dates and times.

Constructing a model directly from Python with a bad value raises
:class:`core.exceptions.InvalidParameterError` naming the field and the rule. (When the web
layer validates a request, pydantic's own error with the full field path is used instead.)
"""

from __future__ import annotations

import datetime as dt
import re
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Annotated, Any

from pydantic import (
    AwareDatetime,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PlainSerializer,
    ValidationError,
    WithJsonSchema,
    model_validator,
)

from core.exceptions import InvalidParameterError

#: ISO 8601 calendar dates and instants as the API takes them: ASCII digits only (Python's and
#: pydantic's own parsers also take other scripts' digits, a time of day after a date, numbers).
DATE_PATTERN = r"^[0-9]{4}-[0-9]{2}-[0-9]{2}$"
DATETIME_PATTERN = (
    r"^[0-9]{4}-[0-9]{2}-[0-9]{2}[Tt ][0-9]{2}:[0-9]{2}(:[0-9]{2}([.,][0-9]{1,6})?)?"
    r"([Zz]|[+-][0-9]{2}:?[0-9]{2})$"
)


def _iso_text(pattern: str, example: str) -> Any:
    """A check that a date or instant comes as ISO 8601 text of ``pattern`` (or as Python's own
    object), never as a number or in another form."""

    def check(value: Any) -> Any:
        if isinstance(value, dt.date | dt.time):
            return value
        if isinstance(value, str) and re.fullmatch(pattern, value):
            return value
        if isinstance(value, str) and re.search(r":[0-9]{2}[.,][0-9]{7,}", value):
            raise ValueError(
                "at most 6 digits after the seconds (microseconds): a finer instant would be cut"
            )
        raise ValueError(f"expected ISO 8601 text like {example}")

    return BeforeValidator(check)


#: A calendar date from ISO text ("2026-07-15"); see :data:`IsoDateTime`.
IsoDate = Annotated[
    dt.date,
    _iso_text(DATE_PATTERN, "2026-07-15"),
    Field(strict=False),
    WithJsonSchema({"type": "string", "format": "date", "pattern": DATE_PATTERN}),
]
#: An instant with its UTC offset from ISO text ("2026-07-15T09:00:00+02:00").
IsoDateTime = Annotated[
    AwareDatetime,
    _iso_text(DATETIME_PATTERN, "2026-07-15T09:00:00+02:00"),
    Field(strict=False),
    WithJsonSchema({"type": "string", "format": "date-time", "pattern": DATETIME_PATTERN}),
]

#: A local clock time as the API writes it: HH:MM, 00:00–23:59, ASCII digits.
HHMM_PATTERN = r"^([01][0-9]|2[0-3]):[0-5][0-9]$"


def clock_time(value: Any) -> dt.time:
    """``"09:30"`` → ``time(9, 30)``; a :class:`datetime.time` passes as it is."""
    if isinstance(value, dt.time):
        return value
    if isinstance(value, str) and re.fullmatch(HHMM_PATTERN, value):
        hour, minute = (int(part) for part in value.split(":"))
        return dt.time(hour, minute)
    raise ValueError("expected a local clock time HH:MM (00:00–23:59)")


#: A local clock time from "HH:MM" text.
ClockTime = Annotated[
    dt.time,
    BeforeValidator(clock_time),
    Field(strict=False),
    WithJsonSchema({"type": "string", "pattern": HHMM_PATTERN}),
    PlainSerializer(lambda value: value.strftime("%H:%M"), return_type=str),
]


def clock_field(default: str, description: str) -> Any:
    """A :data:`ClockTime` field with its default as the API writes it ("08:00"), so that the
    JSON schema shows it so too."""
    return Field(default, validate_default=True, description=description)


#: Standard gravity [m/s²] (CGPM 1901).
GRAVITY_MPS2 = 9.80665
#: Duration of the New European Driving Cycle [s] (UNECE R83/R101), the paper's t_NEDC.
NEDC_DURATION_S = 1180.0


#: How a tagged union's branch names begin (``Tag(BRANCH_TAG + name)``): pydantic puts the
#: branch in an error's location, which is not a field of the request.
BRANCH_TAG = "~"


def field_path(loc: Sequence[int | str]) -> str:
    """A field's path as requests name it: ``stops[3].time_windows[1].start``."""
    path = ""
    for part in loc:
        if part == "" or (isinstance(part, str) and part.startswith(BRANCH_TAG)):
            continue
        path += f"[{part}]" if isinstance(part, int) else (f".{part}" if path else str(part))
    return path


#: What pydantic puts before a validator's own words.
_RULE_PREFIXES = ("Value error, ", "Assertion failed, ")
#: Pydantic's errors that name a class of ours ("a valid dictionary or instance of Weekdays").
_OBJECT_EXPECTED = frozenset({"model_type", "model_attributes_type", "dataclass_type"})


def plain_rule(item: Any) -> str:
    """A pydantic error's rule in the request's words: no class names, no "Value error, "."""
    if item["type"] in _OBJECT_EXPECTED:
        return "must be an object ({…}) with the fields the schema names"
    rule = str(item["msg"])
    for prefix in _RULE_PREFIXES:
        rule = rule.removeprefix(prefix)
    return rule


def describe_validation_error(error: ValidationError, prefix: str = "") -> str:
    """One line per pydantic error: ``field.path: rule`` (:func:`plain_rule`)."""
    parts = []
    for item in error.errors():
        path = field_path((prefix, *item["loc"]))
        parts.append(f"{path or 'input'}: {plain_rule(item)}")
    return "; ".join(parts)


_INSIDE_VALIDATION: ContextVar[bool] = ContextVar("coldroute_inside_validation", default=False)


@contextmanager
def inside_validation() -> Iterator[None]:
    """Mark a larger model's validation: nested parameter models then keep pydantic's own
    error, with its full field path, for the outer model to report."""
    token = _INSIDE_VALIDATION.set(True)
    try:
        yield
    finally:
        _INSIDE_VALIDATION.reset(token)


#: Most samples of one trace any server takes (11.6 days at 1 Hz); a server's own limit
#: (``COLDROUTE_MAX_TRACE_SAMPLES``) is at most this.
MAX_TRACE_SAMPLES = 1_000_000
#: Unknown properties of one object a 422 names: every one costs an entry, and a body of a
#: million made-up keys would otherwise take seconds to refuse and megabytes to answer.
MAX_UNKNOWN_NAMED = 5


def few_unknown(model: type[BaseModel], data: Any) -> Any:
    """``data`` keeping only the first :data:`MAX_UNKNOWN_NAMED` of the properties ``model``
    does not have: the object is refused all the same, naming those."""
    if not isinstance(data, dict) or len(data) <= len(model.model_fields) + MAX_UNKNOWN_NAMED:
        return data
    known = {name for name in model.model_fields} | {
        info.alias for info in model.model_fields.values() if info.alias
    }
    unknown = [key for key in data if key not in known]
    dropped = set(unknown[MAX_UNKNOWN_NAMED:])
    return {key: value for key, value in data.items() if key not in dropped}


class Result(BaseModel):
    """Base of the results an answer shows field by field: frozen, each field described once
    here (the web layer's answer models derive from these). NaN passes (the answer refuses it)."""

    model_config = ConfigDict(frozen=True, extra="forbid")


class Params(BaseModel):
    """Base of every parameter model: frozen, no unknown fields, no NaN or infinity."""

    # Strict: no number from a string or a boolean (JSON clients get what the schema says);
    # dates and times still come from their ISO text (strict=False on those fields).
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False, strict=True)

    @model_validator(mode="before")
    @classmethod
    def _few_unknown(cls, data: Any) -> Any:
        return few_unknown(cls, data)

    @classmethod
    def changed_values(cls, current: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
        """The values of ``current`` (a model's dump) with ``changes`` (a request's changes to a
        preset) applied."""
        return current | changes

    def __init__(self, **data: Any) -> None:
        if _INSIDE_VALIDATION.get():
            super().__init__(**data)
            return
        try:
            with inside_validation():
                super().__init__(**data)
        except ValidationError as error:
            first = error.errors()[0]["loc"]
            raise InvalidParameterError(
                describe_validation_error(error), field=field_path(first) or None
            ) from None
