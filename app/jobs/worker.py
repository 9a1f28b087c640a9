"""The Celery worker's entry point: ``celery -A app.jobs.worker worker`` (``make worker``)."""

from __future__ import annotations

from typing import Any

from celery.signals import worker_shutdown

from app.jobs.celery_app import celery_for, stop_pool
from app.jobs.store import store_for
from app.settings import get_settings

_settings = get_settings()
store_for(_settings.database_url).migrate()
app = celery_for(_settings)


@worker_shutdown.connect  # type: ignore[untyped-decorator]
def _stop_the_process_pool(**_: Any) -> None:
    # Celery's warm shutdown lets the running jobs end; the pool's threads must then go too.
    stop_pool()
