"""A NUL byte in a CSV recording is a clear error on every supported Python (3.10's csv reader
raises on it, 3.11+ reads it into a cell)."""

from __future__ import annotations

from pathlib import Path

import pytest

from gazebot.io.recordings import load_recording
from gazebot.io.recordings.base import RecordingError


@pytest.mark.parametrize("cell", ["\x00", "1.0\x00", "\x002.0"])
def test_a_nul_byte_in_a_csv_recording_is_an_error_naming_the_file(tmp_path: Path, cell: str):
    path = tmp_path / "nul.csv"
    path.write_text(f"t,giver_hand_x,giver_hand_y,giver_hand_z\n0.0,{cell},0,1\n", encoding="utf-8")
    with pytest.raises(RecordingError) as info:
        load_recording(path)
    message = str(info.value)
    assert message.startswith(str(path)) and "line 2" in message and "\n" not in message
