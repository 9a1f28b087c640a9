# coldroute web service: slim Python 3.11, non-root, served by uvicorn on port 8000.
FROM python:3.11-slim

ENV PYTHONDONTWRITEBYTECODE=1 PYTHONUNBUFFERED=1 PIP_NO_CACHE_DIR=1 \
    COLDROUTE_HOST=0.0.0.0 COLDROUTE_PORT=8000 \
    COLDROUTE_DATABASE_URL=sqlite:////srv/coldroute/data/coldroute.db
WORKDIR /srv/coldroute

COPY pyproject.toml README.md ./
COPY core ./core
COPY app ./app
RUN pip install . && useradd --create-home --uid 10001 coldroute \
    && mkdir -p /srv/coldroute/data && chown coldroute /srv/coldroute/data

USER coldroute
EXPOSE 8000
VOLUME /srv/coldroute/data
HEALTHCHECK --interval=30s --timeout=3s --start-period=15s --retries=3 \
    CMD python -c "import urllib.request, sys; sys.exit(urllib.request.urlopen('http://127.0.0.1:8000/healthz', timeout=2).status != 200)"
# On SIGTERM (docker stop) the server refuses new connections at once, lets requests under
# way finish within COLDROUTE_SHUTDOWN_GRACE_S (8 s), answers the rest 503 and exits within
# Docker's 10 s. Solving happens in COLDROUTE_WORKERS processes (default: the CPU count).
STOPSIGNAL SIGTERM
CMD ["python", "-m", "app.serve"]
