"""Async jobs: the job model and store (SQLAlchemy 2, Alembic migrations), the server's own
runner (the worker pool) and the Celery task (scale-out), behind one API (``/v1/jobs``)."""
