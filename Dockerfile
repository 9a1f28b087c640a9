# coldroute web service, built without network: the project and every dependency come from
# the wheelhouse `make image` makes on the host, the base from BASE (any Debian-like image with
# Python 3.11 and its venv module; `make test-image` makes one from Debian's packages).
# Non-root, served by uvicorn on port 8000, the job database on the volume /srv/coldroute/data.
ARG BASE=python:3.11-slim

FROM ${BASE} AS build
ENV PIP_NO_CACHE_DIR=1 PIP_DISABLE_PIP_VERSION_CHECK=1 \
    NUMBA_CACHE_DIR=/opt/coldroute/numba-cache
COPY wheelhouse /wheelhouse
# The round-trip search is compiled here once, not in every container's first solve; pip is
# not needed once the project is in.
RUN python3 -m venv /opt/coldroute \
    && /opt/coldroute/bin/pip install --quiet --no-index --find-links /wheelhouse coldroute \
    && /opt/coldroute/bin/python -c "from core.routing.tsp import prepare; prepare()" \
    && rm -rf /opt/coldroute/lib/python3*/site-packages/pip* /opt/coldroute/bin/pip*

FROM ${BASE}
# Everything but the installed project first: each step is cheap before it (on storage
# drivers that copy layers, such as vfs).
ENV PYTHONDONTWRITEBYTECODE=1 PYTHONUNBUFFERED=1 \
    PATH=/opt/coldroute/bin:/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    NUMBA_CACHE_DIR=/opt/coldroute/numba-cache \
    COLDROUTE_HOST=0.0.0.0 COLDROUTE_PORT=8000 \
    COLDROUTE_DATABASE_URL=sqlite:////srv/coldroute/data/coldroute.db
RUN useradd --create-home --uid 10001 coldroute \
    && mkdir -p /srv/coldroute/data && chown coldroute /srv/coldroute/data
WORKDIR /srv/coldroute
USER coldroute
EXPOSE 8000
VOLUME /srv/coldroute/data
HEALTHCHECK --interval=5s --timeout=3s --start-period=60s --retries=3 \
    CMD ["python", "-c", "import os, sys, urllib.request; port = os.environ['COLDROUTE_PORT']; sys.exit(urllib.request.urlopen(f'http://127.0.0.1:{port}/healthz', timeout=2).status != 200)"]
# On SIGTERM (docker stop) the server refuses new connections at once, lets requests under
# way finish within COLDROUTE_SHUTDOWN_GRACE_S (8 s), answers the rest 503 and exits within
# Docker's 10 s. Solving happens in COLDROUTE_WORKERS processes (default: the CPU count).
STOPSIGNAL SIGTERM
CMD ["python", "-m", "app.serve"]
COPY --from=build /opt/coldroute /opt/coldroute
