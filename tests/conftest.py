"""Shared test fixtures.

Off-screen back ends are chosen here so tests run on a machine without a screen.
"""

from __future__ import annotations

import gc
import importlib.util
import os
import sys
import threading
import time
from pathlib import Path

import pytest
from hypothesis import settings

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

# Property tests draw the same examples on every run ("repeatable"), so a test run's verdict
# depends on the code, not on the draw: a fuzzer's new find fails `make fuzz` (profile
# "explore", fresh examples each run) and becomes a pinned test, never a red CI run by chance.
settings.register_profile("repeatable", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False, database=None)
settings.load_profile(os.environ.get("GAZEBOT_HYPOTHESIS", "repeatable"))

REPO = Path(__file__).resolve().parents[1]
# Reference data lives beside the repo (never inside it); a user's clone does not have it.
SHARED_DATA = Path(os.environ.get("GAZEBOT_SHARED_DATA", REPO.parent / "shared" / "data"))


@pytest.fixture(scope="session")
def annotations_dir() -> Path:
    """The human-human gaze annotations (288 handovers), or a skip saying where they were
    looked for."""
    path = SHARED_DATA / "handover-gaze-annotations"
    if not path.is_dir():
        pytest.skip(
            f"reference data not present at {path} (set GAZEBOT_SHARED_DATA to the folder "
            "holding handover-gaze-annotations/ to run this test)"
        )
    return path


@pytest.fixture(scope="session")
def seed_text() -> str:
    """The seed dissertation text, or a skip saying where it was looked for."""
    path = SHARED_DATA.parent / "seed" / "handover-dissertation-excerpt.txt"
    if not path.is_file():
        pytest.skip(f"seed text not present at {path}")
    return path.read_text(encoding="utf-8")


@pytest.fixture(scope="session")
def bounded_memory():
    """``with bounded_memory(limit_bytes): ...`` fails the test if the block's peak of traced
    allocations (Python objects and numpy arrays) exceeds the limit: a parser fed hostile input
    must not allocate without bound."""
    import tracemalloc
    from contextlib import contextmanager

    @contextmanager
    def limit(limit_bytes: float = 100e6):
        tracemalloc.start()
        try:
            yield
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert peak < limit_bytes, f"peak {peak / 1e6:.0f} MB over {limit_bytes / 1e6:.0f} MB"

    return limit


# The core install (`make test-core`: no extras) runs the core and I/O tests; a test, or a test
# module, that needs a package of an extra skips there with the extra's name instead of failing:
# it raised ModuleNotFoundError for it, or ran a gazebot command that said the extra is missing.
# Only a package of an extra (gazebot.apps.cli.extras) that is not installed counts: any other
# missing module, and any failure where the package is installed, still fails.
def _needs_extra(text: str) -> str | None:
    import re

    from gazebot.apps.cli.extras import extra_for

    said = re.search(r"needs the \[(\w+)\] extra \(no module '([\w.]+)'\)", text)
    raised = re.search(r"No module named '([\w.]+)'", text)
    module = said.group(2) if said else raised.group(1) if raised else None
    if module is None or extra_for(module) is None:
        return None
    if importlib.util.find_spec(module.partition(".")[0]) is not None:
        return None  # installed here: the failure is real (e.g. a test of that very message)
    extra = said.group(1) if said else extra_for(module)
    return f"needs the [{extra}] extra (no module {module!r})"


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    outcome = yield
    report = outcome.get_result()
    reason = _needs_extra(str(report.longrepr)) if report.failed else None
    if reason is not None:
        report.outcome = "skipped"
        report.longrepr = (str(collector.path), 0, f"Skipped: {reason}")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if report.failed and call.excinfo is not None:
        reason = _needs_extra(f"{report.longrepr}\n{report.capstderr}\n{report.capstdout}")
        if reason is not None:
            report.outcome = "skipped"
            report.longrepr = (str(item.path), item.location[1] or 0, f"Skipped: {reason}")


# A thread that is not a daemon keeps the interpreter alive after the last test: a Zenoh callback
# thread whose subscriber outlives its session does (eclipse-zenoh 1.5: an advanced subscriber
# left to the session's close), and the run then never exits. Any such thread still running
# at the end fails the run instead of hanging it, naming the test module that started it.
#: How long the threads left at the end may take to finish (s).
THREAD_GRACE_S = 5.0
#: Thread -> the test module during which it was first seen running.
_THREAD_ORIGIN: dict[threading.Thread, str] = {}


def _live_threads() -> set[threading.Thread]:
    return {t for t in threading.enumerate()
            if not t.daemon and t is not threading.main_thread() and t.is_alive()}


@pytest.fixture(scope="module", autouse=True)
def _note_threads_started(request):
    """Remembers which module started the threads still running after it (for the report)."""
    before = _live_threads()
    yield
    for t in _live_threads() - before:
        _THREAD_ORIGIN.setdefault(t, request.module.__name__)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    gc.collect()  # a Zenoh callback thread ends once its subscriber object is freed
    deadline = time.monotonic() + THREAD_GRACE_S
    for t in _live_threads():
        t.join(max(0.0, deadline - time.monotonic()))
    left = _live_threads()
    if left:
        names = sorted(f"{t.name} (from {_THREAD_ORIGIN.get(t, 'unknown')})" for t in left)
        sys.stderr.write(f"tests left threads running, so the run would never exit: {names}; "
                         "undeclare Zenoh subscribers before closing their session\n")
        sys.stderr.flush()
        os._exit(3)
