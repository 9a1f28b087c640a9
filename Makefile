# Every target bootstraps .venv on first use, so a fresh machine needs only python3.11 and make.
PYTHON ?= python3.11
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

OSRM := .router/osrm/bin/osrm-routed
PBF ?=
ROUTER_DIR ?= .router/region

.PHONY: test check bench serve worker openapi report lint clean router router-serve wheelhouse image \
	test-image docs

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check core app tests testbed benchmarks tools report image_tests
	$(BIN)/mypy core app report
	$(BIN)/lint-imports

# The OSRM programs from the pinned osrm-bindings wheel (tests run a real router on Monaco).
$(OSRM): | $(STAMP)
	$(BIN)/python -m tools.osrm install

# Debian's Chromium for the browser tests of Swagger UI and ReDoc (Playwright drives it; no
# browser download).
CHROMIUM := /usr/bin/chromium
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
$(CHROMIUM):
	$(SUDO) apt-get install -y --no-install-recommends chromium \
		|| ($(SUDO) apt-get update && $(SUDO) apt-get install -y --no-install-recommends chromium)

# The documentation site (MkDocs), offline, warnings as errors, into app/guide: the service
# serves it at /guide.
GUIDE := app/guide/index.html
$(GUIDE): $(STAMP) mkdocs.yml openapi/openapi.json $(shell find docs -type f)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --quiet
	touch $(GUIDE)

docs: $(GUIDE)

# The fast tier (a few minutes): every test but those marked slow — servers started, full
# searches, outside services; `make check` runs everything (what CI runs).
test: lint $(GUIDE) $(OSRM)
	$(BIN)/python -m pytest -n 2 --dist worksteal -m "not slow"

check: lint $(GUIDE) $(OSRM) $(CHROMIUM)
	$(BIN)/python -m pytest -n 2 --dist worksteal

BENCH_STAMP := $(VENV)/.bench-installed
$(BENCH_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[dev,bench]'
	touch $(BENCH_STAMP)

bench: $(BENCH_STAMP) $(OSRM)
	$(BIN)/python -m benchmarks

# A road router for your region: make router PBF=region.osm.pbf, then make router-serve.
router: $(OSRM)
	test -n "$(PBF)" || (echo "usage: make router PBF=region.osm.pbf" && false)
	$(BIN)/python -m tools.osrm prepare "$(PBF)" --out $(ROUTER_DIR)

router-serve: $(OSRM)
	$(BIN)/python -m tools.osrm serve $(ROUTER_DIR) --port $${OSRM_PORT:-5000}

serve: $(STAMP) $(GUIDE)
	$(BIN)/python -m app.serve

# A Celery worker for the jobs (needs COLDROUTE_BROKER_URL and a PostgreSQL COLDROUTE_DATABASE_URL).
worker: $(STAMP)
	$(BIN)/celery -A app.jobs.worker worker --pool=threads --loglevel=INFO --concurrency=$${COLDROUTE_WORKERS:-$$(nproc)}

# The Swagger answer examples (a real run), then the committed OpenAPI document.
openapi: $(STAMP)
	$(BIN)/python -m app.examples
	$(BIN)/python -m app.openapi > openapi/openapi.json

report: $(STAMP)
	$(BIN)/python -m report.paper

# The container image, built without network from a wheelhouse made here (the base's Python
# 3.11.2 wants async-timeout, which this 3.11's markers leave out). BASE: any Debian-like image
# with Python 3.11 and its venv module.
IMAGE ?= coldroute
BASE ?= python:3.11-slim
wheelhouse: $(STAMP) $(GUIDE)
	rm -rf wheelhouse
	$(BIN)/python -m pip wheel --quiet . 'async-timeout>=4' -w wheelhouse

image: wheelhouse
	docker build --network none --build-arg BASE=$(BASE) -t $(IMAGE) .

# The image tried as an operator would, with this machine's own dockerd and a base made by
# debootstrap from Debian's packages (root; Debian's docker.io and debootstrap). Not in `make
# test`: a laptop without Docker runs the test suite.
DOCKERD := /usr/sbin/dockerd
DEBOOTSTRAP := /usr/sbin/debootstrap
$(DOCKERD) $(DEBOOTSTRAP):
	$(SUDO) apt-get install -y --no-install-recommends docker.io debootstrap \
		|| ($(SUDO) apt-get update && $(SUDO) apt-get install -y --no-install-recommends docker.io debootstrap)

test-image: wheelhouse $(DOCKERD) $(DEBOOTSTRAP)
	$(BIN)/python -m pytest image_tests -p no:cacheprovider
	rm -rf wheelhouse

clean:
	rm -rf $(VENV) .router .pytest_cache .mypy_cache .ruff_cache wheelhouse app/guide
