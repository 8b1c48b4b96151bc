# The two commands a new user runs: `make demo` and `make test`. Each sets up .venv itself.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test

.PHONY: demo test bench lint check-gl browser-deps clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e .
	touch $@

$(TEST_STAMP): $(STAMP) pyproject.toml
	$(PY) -m pip install --quiet -e ".[test,gps]"
	touch $@

check-gl: $(STAMP)
	$(PY) -m gazebot.sim.gl_check

# The browser tests (pytest -m browser) drive Debian's Chromium through its chromedriver. As root
# on Debian, install both when missing; elsewhere say so, and those tests skip with that reason.
browser-deps:
	@if command -v chromium >/dev/null 2>&1 && command -v chromedriver >/dev/null 2>&1; then \
		true; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
		echo "installing chromium and chromium-driver for the browser tests"; \
		{ apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver >/dev/null; } \
			|| echo "note: apt-get could not install chromium: the browser tests will skip"; \
	else \
		echo "note: no chromium/chromedriver and cannot apt-get them: the browser tests will skip"; \
	fi

demo: $(STAMP) check-gl
	$(PY) -m gazebot demo --out out/demo

test: $(TEST_STAMP) check-gl browser-deps
	$(PY) -m pytest

bench: $(TEST_STAMP)
	$(PY) -m benchmarks

lint: $(TEST_STAMP)
	$(VENV)/bin/ruff check gazebot tests benchmarks examples

clean:
	rm -rf $(VENV) out .pytest_cache
