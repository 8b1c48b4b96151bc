"""Fixtures of the annotation tests."""

from __future__ import annotations

from pathlib import Path

import pytest
from annotation_helpers import handover_rows, write_xlsx


@pytest.fixture
def synthetic_dir(tmp_path: Path) -> Path:
    """Two pairs x two handovers in the published folder layout."""
    root = tmp_path / "handover-gaze-annotations"
    for pair in ("volunteer_1_volunteer_2", "volunteer_3_volunteer_4"):
        for n in (1, 2):
            write_xlsx(root / pair / f"{pair} {n}.xlsx", handover_rows())
    return root
