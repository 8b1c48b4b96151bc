"""``gazebot mcap recover``: a recording cut anywhere (a killed recorder) becomes a finished MCAP
file the ``mcap`` library's default reader opens, holding every message of every complete chunk
before the cut, as the MCAP CLI's ``mcap recover`` does."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gazebot.apps.cli import main
from gazebot.io.recordings import RecordingError
from gazebot.io.recordings.mcap_recover import recover_mcap, recovered_path
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2.mcap_writer import McapRecorder


class _Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> Path:
    """60 messages on two topics, one chunk per second of the recorder's clock."""
    path = tmp_path_factory.mktemp("rec") / "run.mcap"
    clock = _Clock()
    with McapRecorder(path, clock=clock) as rec:
        for i in range(30):
            clock.now = i * 0.2
            rec.write("/gazebot/tracking/giver_hand", cv.point_stamped(i, [i, 0, 1], "w"), 5 + i)
            rec.write("/joint_states", cv.joint_state(i, {"head_pan": 0.01 * i}), 5 + i)
    return path


def _messages(path: Path) -> list[tuple[str, int, bytes]]:
    from mcap.reader import make_reader

    with path.open("rb") as f:
        reader = make_reader(f)
        assert reader.get_summary() is not None
        return [(ch.topic, m.log_time, m.data)
                for _, ch, m in reader.iter_messages(log_time_order=False)]


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(cut=st.floats(0.05, 1.0))
def test_a_recording_cut_anywhere_recovers_every_complete_chunk(
        recording, tmp_path_factory, bounded_memory, cut):
    from mcap.reader import make_reader

    whole = _messages(recording)
    data = recording.read_bytes()
    folder = tmp_path_factory.mktemp("cut")
    cut_file = folder / "cut.mcap"
    cut_file.write_bytes(data[: int(cut * len(data))])
    if cut < 1.0:
        with cut_file.open("rb") as f, pytest.raises(Exception):  # noqa: B017 - any mcap error
            make_reader(f).get_summary()  # why recover exists
    with bounded_memory(50e6):
        got = recover_mcap(cut_file)
    assert got.path == folder / "cut-recovered.mcap"
    fixed = _messages(got.path)
    assert fixed == whole[: len(fixed)] and got.messages == len(fixed)
    # Whole chunks (one per second of the recorder's clock): all of those before the cut.
    ends = _chunk_ends(recording)
    assert len(fixed) in [0, *ends]
    complete = [n for n, end_byte in ends.items() if end_byte <= int(cut * len(data))]
    assert len(fixed) == max(complete, default=0)
    assert (got.problem is None) == (cut == 1.0)


def _chunk_ends(path: Path) -> dict[int, int]:
    """Messages before the end of each chunk -> the byte where the chunk's record ends."""
    from mcap.reader import make_reader

    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    ends, count = {}, 0
    for index in sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset):
        count += len(_in_chunk(path, index))
        ends[count] = index.chunk_start_offset + index.chunk_length
    return ends


def _in_chunk(path: Path, index) -> list:
    from mcap.data_stream import ReadDataStream
    from mcap.records import Chunk

    from gazebot.io.recordings.mcap_records import chunk_records, decompress_chunk

    with path.open("rb") as f:
        f.seek(index.chunk_start_offset + 9)  # past the record's opcode and length
        chunk = Chunk.read(ReadDataStream(f))
    records = chunk_records(decompress_chunk(chunk, 1, 2**30, 1e9), 1)
    return [r for r in records if type(r).__name__ == "Message"]


def test_the_cli_recovers_to_a_file_and_says_what_it_kept(recording, tmp_path, capsys):
    cut = tmp_path / "killed.mcap"
    cut.write_bytes(recording.read_bytes()[: recording.stat().st_size * 2 // 3])
    assert main(["mcap", "recover", str(cut), "--out", str(tmp_path / "ok.mcap"),
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["file"] == str(tmp_path / "ok.mcap") and out["messages"] > 0
    assert out["problem"] and len(_messages(tmp_path / "ok.mcap")) == out["messages"]
    assert main(["mcap", "recover", str(cut)]) == 0
    text = capsys.readouterr().out
    assert f"to {recovered_path(cut)}" in text and "stopped at:" in text


def test_recover_refuses_its_input_as_output_and_a_file_that_is_not_mcap(tmp_path, capsys):
    f = tmp_path / "x.mcap"
    f.write_bytes(b"not an mcap file at all")
    with pytest.raises(RecordingError, match="another file"):
        recover_mcap(f, f)
    assert main(["mcap", "recover", str(f)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"gazebot: error: {f}: not an MCAP file") and err.count("\n") == 1
    assert not recovered_path(f).exists()
    assert main(["mcap", "recover", str(tmp_path / "missing.mcap")]) == 2
    assert "no such file" in capsys.readouterr().err
