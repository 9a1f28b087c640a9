# Every target bootstraps .venv on first use, so a fresh machine needs only python3.11 and make.
PYTHON ?= python3.11
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: test bench serve openapi report lint clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check core app tests benchmarks
	$(BIN)/mypy core app

test: lint
	$(BIN)/python -m pytest

bench: $(STAMP)
	$(BIN)/python -m benchmarks

serve: $(STAMP)
	$(BIN)/uvicorn app.main:app --host $${COLDROUTE_HOST:-0.0.0.0} --port $${COLDROUTE_PORT:-8000}

openapi: $(STAMP)
	$(BIN)/python -m app.openapi > openapi/openapi.json

report: $(STAMP)
	$(BIN)/python -m app.report

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache
