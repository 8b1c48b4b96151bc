# The two commands a new user runs: `make demo` and `make test`. Each sets up .venv itself, with
# every extra (`pip install -e ".[all]"`; `make test` adds the test and lint tools). `make
# test-core` tests the core install alone (no extra: what `pip install gazebot` gives a robot
# stack) in .venv-core.
# pyproject.toml declares version ranges; make installs the exact versions of the lock
# constraints.txt (resolved on Python 3.11; on Python 3.10, where NumPy 2.4 and SciPy 1.17 do not
# install, the lowest allowed versions that CI tests there). `make test-lowest` runs the suite on
# the lowest allowed versions (constraints-lowest.txt) in a venv of its own, on Python 3.10 when
# one is installed.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test
LOWEST := constraints-lowest.txt
LOCK := $(if $(filter 3.10,$(shell $(PYTHON) -c 'import sys; print("%d.%d" % sys.version_info[:2])' \
	2>/dev/null)),$(LOWEST),constraints.txt)
LOW_VENV := .venv-lowest
LOW_STAMP := $(LOW_VENV)/.installed-test
# The lowest-versions run installs every extra but gps (constraints-lowest.txt has no bounds for
# JAX and scikit-learn).
LOW_EXTRAS := render,sim,controllers,recordings,study,view,test
CORE_VENV := .venv-core
CORE_STAMP := $(CORE_VENV)/.installed-test
# The core install's tests: the core and I/O layers (a test that needs an extra skips, naming it:
# tests/conftest.py), the examples, and the checks that nothing of an extra is imported.
CORE_TESTS := tests/core tests/io tests/test_core_install.py tests/test_examples.py \
	tests/apps/cli/test_cli_extras.py
LINT_STAMP := $(VENV)/.installed-lint
DOCS_STAMP := $(VENV)/.installed-docs
# The lowest supported Python: python3.10 on PATH, else pyenv's 3.10, else $(PYTHON).
PYTHON_LOWEST ?= $(shell for p in python3.10 $$HOME/.pyenv/versions/3.10*/bin/python3.10; do \
	"$$p" -c "" >/dev/null 2>&1 && { echo "$$p"; exit 0; }; done; echo $(PYTHON))

.PHONY: demo test test-lowest test-core fuzz bench soak lint docs lock lock-upgrade check-gl browser-deps clean

$(STAMP): pyproject.toml $(LOCK)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c $(LOCK) -e ".[all]"
	touch $@

$(TEST_STAMP): $(STAMP) pyproject.toml $(LOCK)
	$(PY) -m pip install --quiet -c $(LOCK) -e ".[all,test,lint]"
	touch $@

$(LINT_STAMP): $(STAMP) pyproject.toml $(LOCK)
	$(PY) -m pip install --quiet -c $(LOCK) -e ".[lint]"
	touch $@

$(DOCS_STAMP): $(STAMP) pyproject.toml $(LOCK)
	$(PY) -m pip install --quiet -c $(LOCK) -e ".[all,docs]"
	touch $@

$(LOW_STAMP): pyproject.toml $(LOWEST)
	rm -rf $(LOW_VENV)
	$(PYTHON_LOWEST) -m venv $(LOW_VENV)
	$(LOW_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(LOW_VENV)/bin/python -m pip install --quiet --prefer-binary -c $(LOWEST) -e ".[$(LOW_EXTRAS)]"
	$(LOW_VENV)/bin/python -m pip check
	touch $@

$(CORE_STAMP): pyproject.toml $(LOWEST)
	rm -rf $(CORE_VENV)
	$(PYTHON_LOWEST) -m venv $(CORE_VENV)
	$(CORE_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(CORE_VENV)/bin/python -m pip install --quiet --prefer-binary -c $(LOWEST) -e ".[test]"
	$(CORE_VENV)/bin/python -m pip check
	touch $@

# Rewrite the lock from a scratch venv: `lock` keeps every locked version and resolves only what
# is new in pyproject.toml; `lock-upgrade` takes the newest versions the ranges allow.
lock lock-upgrade:
	@$(PYTHON) -c 'import sys; sys.exit(sys.version_info < (3, 11))' \
		|| { echo "make lock: the lock is resolved on Python >= 3.11 (PYTHON=python3.11)"; exit 1; }
	rm -rf .venv-lock
	$(PYTHON) -m venv .venv-lock
	.venv-lock/bin/python -m pip install --quiet --upgrade pip
	.venv-lock/bin/python -m pip install --quiet $(if $(filter lock,$@),-c constraints.txt) ".[all,test,lint]"
	{ sed -n '/^#/p;/^#/!q' constraints.txt; .venv-lock/bin/python -m pip freeze --exclude-editable \
		| grep -v '^gazebot'; } > constraints.txt.new
	mv constraints.txt.new constraints.txt
	rm -rf .venv-lock

check-gl: $(STAMP)
	$(PY) -m gazebot.apps.render.gl_check

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

# The lowest versions, with the extras and then the core install alone.
test-lowest: $(LOW_STAMP) browser-deps
	$(LOW_VENV)/bin/python -m gazebot.apps.render.gl_check
	$(LOW_VENV)/bin/python -m pytest
	$(MAKE) test-core

test-core: $(CORE_STAMP)
	$(CORE_VENV)/bin/python -m pytest $(CORE_TESTS)

# The property tests with fresh examples each round (`make test` draws the same ones every run):
# FUZZ_ROUNDS rounds, stopping at the first failure, which hypothesis prints with its example.
FUZZ_ROUNDS ?= 20
fuzz: $(TEST_STAMP)
	for i in $$(seq $(FUZZ_ROUNDS)); do \
		GAZEBOT_HYPOTHESIS=explore $(PY) -m pytest -q -p no:cacheprovider -x \
			$$(grep -rl --include="test_*.py" "^from hypothesis" tests) || exit 1; \
	done

bench: $(TEST_STAMP)
	$(PY) -m benchmarks --markdown docs/benchmark-results.md

# The bus soak (ten minutes: a router, a recording engine, 29 simulator runs, a 50-participant
# study load, then a SIGKILL of the engine): prints what it measured, exit 1 on a phantom
# handover, a lost event or message, a participant who could not finish, or 5 MB of engine growth.
soak: $(TEST_STAMP)
	$(PY) -m benchmarks.soak

# Style, the layers (import-linter's contracts in pyproject.toml: core < io < apps, no cycles) and
# the types of core and io (mypy, configured in pyproject.toml).
lint: $(LINT_STAMP)
	$(VENV)/bin/ruff check gazebot tests benchmarks examples
	$(VENV)/bin/lint-imports --no-logo
	$(VENV)/bin/mypy

# The documentation site (MkDocs Material; the CLI, topic and API references generated from the
# code at build time: docs/_hooks/generated.py) into out/site, strict: a broken link fails.
docs: $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict

clean:
	rm -rf $(VENV) $(LOW_VENV) $(CORE_VENV) .venv-lock out .pytest_cache
