"""The Celery worker's entry point: ``celery -A app.jobs.worker worker`` (``make worker``)."""

from __future__ import annotations

from app.jobs.celery_app import celery_for
from app.jobs.store import store_for
from app.settings import get_settings

_settings = get_settings()
store_for(_settings.database_url).migrate()
app = celery_for(_settings)
