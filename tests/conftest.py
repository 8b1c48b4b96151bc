"""Shared test fixtures.

Off-screen back ends are chosen here so tests run on a machine without a screen.
"""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

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
