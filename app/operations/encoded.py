"""Answers serialised in the worker process that made them.

A large answer (a 400-stop round: 400 legs and stops, 0.6 MB of JSON) takes the server's
process about 0.1 s to build as models and write out, holding Python's GIL: done on the event
loop, ``/healthz`` and every waiting request stall for it. Made and written in the worker, the
event loop only sends the bytes (:class:`Encoded`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel

JSON = "application/json"


@dataclass(frozen=True)
class Encoded:
    """An answer's body as the client gets it.

    Parameters
    ----------
    body
        The JSON text, as FastAPI writes a response model (by alias, UTF-8).
    media_type
        Its content type.
    runtime_s
        The search's time for the metrics [s] (0 where no search made it).
    """

    body: bytes
    media_type: str = JSON
    runtime_s: float = 0.0


def encoded(model: BaseModel, media_type: str = JSON, runtime_s: float = 0.0) -> Encoded:
    """``model`` written out as FastAPI writes a response model."""
    body = model.__pydantic_serializer__.to_json(model, by_alias=True)
    return Encoded(body, media_type, runtime_s)


def answered(make: Callable[..., BaseModel], *args: Any) -> Encoded:
    """``make(*args)``'s answer, written out where it was made (run it in a worker)."""
    return encoded(make(*args))
