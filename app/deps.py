"""The FastAPI dependencies every router shares, declared once as ``Annotated`` aliases."""

from __future__ import annotations

import secrets
from typing import Annotated

from fastapi import Depends, Request

from app.execution import Executor
from app.jobs.store import JobStore, store_for
from app.settings import Settings, get_settings

SettingsDep = Annotated[Settings, Depends(get_settings)]


def _executor(http: Request) -> Executor:
    """The server's worker pool."""
    pool: Executor = http.app.state.executor
    return pool


ExecutorDep = Annotated[Executor, Depends(_executor)]


def _job_store(settings: SettingsDep) -> JobStore:
    return store_for(settings.database_url)


StoreDep = Annotated[JobStore, Depends(_job_store)]


def api_key_refusal(settings: Settings, sent: list[str]) -> str | None:
    """Why the ``X-API-Key`` values ``sent`` do not open the API, or None when they do (no key
    configured: open). The key is a security scheme in the OpenAPI document
    (app.openapi_doc), checked by :class:`app.main.ApiKey` before a body is read."""
    if settings.api_key is None:
        return None
    expected = settings.api_key.get_secret_value().encode()
    # Bytes: compare_digest refuses non-ASCII text, and any key a client sends is just wrong. A
    # repeated header is refused whatever its values: one server may read the first, a proxy
    # the last.
    if len(sent) != 1 or not secrets.compare_digest(sent[0].encode("latin-1"), expected):
        return "missing, repeated or wrong X-API-Key"
    return None
