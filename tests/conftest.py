"""Shared test fixtures.

Off-screen back ends are chosen here so tests run on a machine without a screen.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

REPO = Path(__file__).resolve().parents[1]
# Reference data lives beside the repo (never inside it); a user's clone does not have it.
SHARED_DATA = Path(os.environ.get("GAZEBOT_SHARED_DATA", REPO.parent / "shared" / "data"))


def documentation_text() -> str:
    """The README and every page of the documentation site (``docs/``), as one text: tests that
    pin what the documentation says look here, wherever a section lives."""
    pages = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
    return "\n".join(p.read_text(encoding="utf-8") for p in pages)


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
