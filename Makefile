# The two commands a new user runs: `make demo` and `make test`. Each sets up .venv itself.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test

.PHONY: demo test bench lint check-gl clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e .
	touch $@

$(TEST_STAMP): $(STAMP) pyproject.toml
	$(PY) -m pip install --quiet -e ".[test]"
	touch $@

check-gl: $(STAMP)
	$(PY) -m gazebot.sim.gl_check

demo: $(STAMP) check-gl
	$(PY) -m gazebot demo --out out/demo

test: $(TEST_STAMP) check-gl
	$(PY) -m pytest

bench: $(TEST_STAMP)
	$(PY) -m benchmarks

lint: $(TEST_STAMP)
	$(VENV)/bin/ruff check gazebot tests benchmarks examples

clean:
	rm -rf $(VENV) out .pytest_cache
