"""A real render's progress bar counts frames against a total it never passes."""

from __future__ import annotations

import re

from gazebot.apps.sim.record import record_handover


def test_recording_a_handover_draws_n_of_total_frames_throughout(tmp_path, capsys):
    rec = record_handover(
        "sawyer", "face-hand-face", "default", tmp_path / "v.mp4", width=64, height=48, fps=30.0
    )
    err = capsys.readouterr().err
    pairs = [(int(a), int(b)) for a, b in re.findall(r"(\d+)/(\d+) ?\[", err)]
    assert pairs and pairs[0][0] == 0
    assert all(n <= total for n, total in pairs)
    assert max(n for n, _ in pairs) <= rec.frames
    assert not re.search(r"\d+ ?frame \[", err)  # tqdm's format once a count passed its total
