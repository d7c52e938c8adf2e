# The two commands a newcomer runs: `make demo` and `make test`.  Each creates .venv when it is missing and
# installs the package (editable) with the extras it needs; nothing but Python 3.11+ is required.

PYTHON ?= $(shell for p in python3.13 python3.12 python3.11 python3; do \
             command -v $$p >/dev/null 2>&1 && $$p -c 'import sys; sys.exit(sys.version_info < (3, 11))' \
             && { echo $$p; break; }; done)
VENV   := .venv
BIN    := $(VENV)/bin

.PHONY: demo test lint bench docs clean

$(BIN)/python:
	@test -n "$(PYTHON)" || { echo "error: Python 3.11 or newer is required (set PYTHON=...)"; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# One stamp per extra set, so `make test` after `make demo` installs only what is missing.
$(VENV)/.stamp-demo: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[cli,io,ulog,rosbag,geomag,plot]'
	@touch $@

$(VENV)/.stamp-test: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[test]'
	@touch $@

$(VENV)/.stamp-bench: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[bench]'
	@touch $@

$(VENV)/.stamp-docs: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[docs]'
	@touch $@

demo: $(VENV)/.stamp-demo
	$(BIN)/strapdown warmup --quiet
	$(BIN)/strapdown demo

test: $(VENV)/.stamp-test
	$(BIN)/python -m pytest

lint: $(VENV)/.stamp-test
	$(BIN)/ruff check src tests benchmarks docs/conf.py docs/_apigen.py docs/_cligen.py examples
	$(BIN)/ruff format --check src tests benchmarks docs/conf.py docs/_apigen.py docs/_cligen.py examples

bench: $(VENV)/.stamp-bench
	$(BIN)/python benchmarks/bench_representations.py
	$(BIN)/python benchmarks/bench_integrate.py
	$(BIN)/python benchmarks/bench_thread_policy.py
	$(BIN)/python benchmarks/bench_wahba.py
	$(BIN)/python benchmarks/bench_estimators.py
	$(BIN)/python benchmarks/bench_attitude.py
	$(BIN)/python benchmarks/bench_io.py

# The site in docs/_build/html, warnings as errors; the gallery's examples run as part of it.
docs: $(VENV)/.stamp-docs
	$(BIN)/python -m sphinx -b html -W --keep-going docs docs/_build/html
	@echo "open docs/_build/html/index.html"

clean:
	rm -rf $(VENV) build dist .pytest_cache .ruff_cache .hypothesis docs/_build docs/api docs/cli docs/auto_examples
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
