"""The demo's progress bar knows its total from the start (issue 32: it jumped 234 -> 243)."""

from __future__ import annotations

import pytest

import gazebot.apps.render.progress as progress_module
from gazebot.apps.render.progress import FrameProgress
from gazebot.apps.sim.record import record_handover


@pytest.mark.parametrize("robot", ["sawyer", "jaco2"])
def test_the_progress_total_is_the_frame_count_from_the_first_frame(tmp_path, monkeypatch, robot):
    totals: list[int] = []

    class Watched(FrameProgress):
        def advance(self, end_s=None):
            totals.append(self.total)  # the total the user sees before this frame
            super().advance(end_s)

    monkeypatch.setattr(progress_module, "FrameProgress", Watched)
    rec = record_handover(
        robot=robot, behavior="face-hand-face", out_path=tmp_path / "h.mp4", width=64,
        height=48, progress=True,
    )
    assert rec.completed and rec.frames > 100
    assert set(totals) == {rec.frames}
