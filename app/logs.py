"""One JSON line per event, for every logger of the service — the request log, the job
runners, uvicorn, Alembic, and Python's warnings (a numpy ``RuntimeWarning`` included) — in
the server and in its worker processes."""

from __future__ import annotations

import datetime as dt
import json
import logging
import sys
from collections.abc import Callable
from contextvars import ContextVar
from typing import Any

#: The id of the request being served (for the lines written while serving it).
REQUEST_ID: ContextVar[str] = ContextVar("coldroute_request_id", default="-")
#: The attributes every log record has; whatever else a record carries (``extra=``) is the
#: event's own fields.
_STANDARD = set(vars(logging.makeLogRecord({}))) | {"message", "asctime", "taskName"}


def _ours(handler: logging.Handler) -> bool:
    return isinstance(handler.formatter, JsonLines)


class JsonLines(logging.Formatter):
    """A record as one JSON object on one line: the event's own fields (``extra=``) first,
    then its time, level, logger and message, the request it belongs to, and a traceback."""

    def format(self, record: logging.LogRecord) -> str:
        fields: dict[str, Any] = {k: v for k, v in vars(record).items() if k not in _STANDARD}
        fields.setdefault("request_id", REQUEST_ID.get())  # a record made before ours
        entry = fields | {
            "time": dt.datetime.fromtimestamp(record.created, dt.UTC).isoformat(),
            "level": record.levelname.lower(),
            "logger": record.name,
            "message": record.getMessage(),
        }
        if record.exc_info:
            entry["error"] = self.formatException(record.exc_info)
        return json.dumps(entry, default=str)


def _stamped(factory: Callable[..., logging.LogRecord]) -> Callable[..., logging.LogRecord]:
    """A record factory that stamps each record with the request being served when it is
    made, so a record formatted later (or elsewhere) still names its request."""
    if getattr(factory, "stamps_request_id", False):
        return factory

    def make(*args: Any, **kwargs: Any) -> logging.LogRecord:
        record = factory(*args, **kwargs)
        record.request_id = REQUEST_ID.get()
        return record

    make.stamps_request_id = True  # type: ignore[attr-defined]
    return make


def configure_logging(level: str) -> None:
    """Every log record of this process as a JSON line on stdout (where containers and
    process managers collect a service's log), warnings included (a plain stream handler
    someone installed before is replaced; a test's capturing handler stays)."""
    root = logging.getLogger()
    root.handlers[:] = [
        h for h in root.handlers if type(h) is not logging.StreamHandler and not _ours(h)
    ]
    handler = logging.StreamHandler(sys.stdout)
    handler.setFormatter(JsonLines())
    root.addHandler(handler)
    root.setLevel(level.upper())
    logging.setLogRecordFactory(_stamped(logging.getLogRecordFactory()))
    logging.captureWarnings(True)
    # One line per request is ours to write; the router and weather calls are not news.
    logging.getLogger("httpx").setLevel(logging.WARNING)
    for name in ("uvicorn", "uvicorn.error"):
        logging.getLogger(name).handlers[:] = []
        logging.getLogger(name).propagate = True
    # uvicorn's access line would repeat our request line, without the request's id.
    logging.getLogger("uvicorn.access").handlers[:] = []
    logging.getLogger("uvicorn.access").propagate = False
