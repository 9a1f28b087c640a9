"""``make serve``: the service under uvicorn, as the settings say.

Binds ``COLDROUTE_HOST`` (127.0.0.1 unless told otherwise) and ``COLDROUTE_PORT``. On SIGTERM
the server refuses new connections at once, lets requests under way finish within
``COLDROUTE_SHUTDOWN_GRACE_S`` (8 s), answers the rest 503 and exits: inside Docker's 10 s.
"""

from __future__ import annotations

import math

import uvicorn

from app.settings import get_settings


def main() -> None:
    settings = get_settings()
    uvicorn.run(
        "app.main:app",
        host=settings.host,
        port=settings.port,
        log_level=settings.log_level,
        # The app writes one JSON line per request itself, and every other line as JSON too.
        access_log=False,
        log_config=None,
        # uvicorn's own wait comes after the app's grace, so late requests still get their 503.
        timeout_graceful_shutdown=math.ceil(settings.shutdown_grace_s) + 1,
    )


if __name__ == "__main__":
    main()
