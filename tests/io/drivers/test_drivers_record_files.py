"""The recording's files: written under the final name from the start and flushed by the
clock (what a kill leaves is readable), split into ``NAME_0.mcap``, ``NAME_1.mcap``, ... by size
or duration (rosbag2's ``--max-bag-size`` / ``--max-bag-duration``), and the CLI options."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2.mcap_writer import McapRecorder, Split


class Clock:
    """A monotonic clock the test moves."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def _stream(path: Path) -> list[float]:
    """Log times (s) of the messages the stream reader reads in ``path`` as it is now."""
    from mcap.reader import NonSeekingReader

    out = []
    with path.open("rb") as f:
        try:
            for _, _, m in NonSeekingReader(f).iter_messages(log_time_order=False):
                out.append(m.log_time * 1e-9)
        except Exception:  # noqa: BLE001 - the end of what was written so far
            pass
    return out


def _indexed(path: Path) -> list[float]:
    from mcap.reader import make_reader

    with path.open("rb") as f:
        return [m.log_time * 1e-9 for _, _, m in make_reader(f).iter_messages()]


def test_the_file_has_its_final_name_and_each_period_is_on_disk_while_recording(tmp_path):
    clock = Clock()
    path = tmp_path / "run.mcap"
    rec = McapRecorder(path, flush_period=1.0, clock=clock)
    assert [p.name for p in tmp_path.iterdir()] == ["run.mcap"]
    assert _stream(path) == []  # the header is written: an empty MCAP file
    for i in range(25):  # 2.5 s at 10 Hz of the test's clock
        clock.now = i * 0.1
        rec.write("/a", cv.point_stamped(0.0, [i, 0, 0], "w"), 100 + i * 0.1)
    on_disk = _stream(path)  # flushed at clock 1.0 and 2.0: messages 0..20
    assert len(on_disk) == 21
    rec.flush()
    assert len(_stream(path)) == 25
    rec.close()
    assert len(_indexed(path)) == 25
    assert [p.name for p in tmp_path.iterdir()] == ["run.mcap"]


def test_a_recording_splits_by_duration_into_numbered_files(tmp_path):
    path = tmp_path / "bus.mcap"
    with McapRecorder(path, split=Split(max_duration_s=1.0)) as rec:
        for i in range(35):  # 3.4 s of log time at 10 Hz
            rec.write("/a", cv.point_stamped(0.0, [i, 0, 0], "w"), 10 + i * 0.1)
            rec.write("/b", cv.pose_stamped(0.0, [i, 0, 0], "w"), 10 + i * 0.1)
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"bus_{i}.mcap" for i in range(4)]
    assert rec.files == [tmp_path / f"bus_{i}.mcap" for i in range(4)]
    counts = []
    for f in rec.files:
        times = _indexed(f)
        assert max(times) - min(times) < 1.0
        counts.append(len(times))
    assert counts == [20, 20, 20, 10]  # both topics (schemas and channels) in every file


def test_a_recording_splits_by_size(tmp_path):
    path = tmp_path / "big.mcap"
    # Uncompressed 4 kB chunks: each file closes at 20 kB, one chunk over at most.
    with McapRecorder(path, compression="none", chunk_size=4096,
                      split=Split(max_bytes=20_000)) as rec:
        for i in range(1000):
            rec.write("/a", cv.point_stamped(0.0, [i, 0, 0], "w"), i * 0.01)
    assert len(rec.files) >= 3
    assert sum(len(_indexed(f)) for f in rec.files) == 1000
    for f in rec.files[:-1]:
        assert 20_000 <= f.stat().st_size <= 20_000 + 4096 + 2048  # + one chunk and summary


def test_split_limits_must_be_positive():
    with pytest.raises(ValueError, match="maximum file size"):
        Split(max_bytes=0)
    with pytest.raises(ValueError, match="maximum file duration"):
        Split(max_duration_s=float("nan"))
    assert not Split().splits


def test_the_cli_options_make_the_split(capsys):
    from gazebot.apps.cli.mcap import add_record_split_arguments, record_split

    p = argparse.ArgumentParser()
    add_record_split_arguments(p)
    assert record_split(p.parse_args([])) is None
    assert record_split(p.parse_args(["--record-max-size", "1000000"])) == Split(1_000_000)
    assert record_split(p.parse_args(["--record-max-duration", "60"])) == Split(None, 60.0)
    with pytest.raises(SystemExit):
        p.parse_args(["--record-max-size", "0"])
    assert "--record-max-size" in capsys.readouterr().err


def test_nothing_is_kept_per_message_beyond_the_chunk_in_progress(tmp_path):
    """Memory grows with chunks (one index entry each), not with messages: 150 s more of a
    100 Hz topic (15000 messages of ~100 bytes, 1.5 MB) keep less than 300 kB."""
    import tracemalloc

    clock = Clock()
    rec = McapRecorder(tmp_path / "soak.mcap", clock=clock)
    msg = cv.point_stamped(0.0, [1, 2, 3], "world")

    def run(start: int, stop: int) -> None:
        for i in range(start, stop):
            clock.now = i / 100
            rec.write("/a", msg, 100 + i / 100)

    run(0, 5000)  # warm up: schemas, codecs, the first chunks
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        run(5000, 20000)
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    rec.close()
    assert grown < 300_000, f"{grown} bytes kept over 15000 messages"


@pytest.mark.zenoh
def test_the_bus_recorder_splits_into_finished_files(bus, tmp_path):
    import time

    from drivers_fakes import wait_until

    from gazebot.io.drivers.recorder import BusRecorder
    from gazebot.io.drivers.rmw.node import RosNode
    from gazebot.io.ros2 import topics as tp

    recorder = BusRecorder(bus.listener(), bus.names, tmp_path / "bus.mcap",
                           split=Split(max_duration_s=0.5))
    bus.closers.append(recorder.close)
    node = RosNode(bus.connector(), bus.names, "publisher")
    bus.closers.append(node.close)
    pub = node.publisher(tp.GAZE_TARGET.name, tp.GAZE_TARGET.type)
    node.announce()
    i = 0

    def publish_until_split() -> bool:
        nonlocal i
        i += 1
        pub.publish(cv.point_stamped(0.0, [i, 0, 0], "world"))
        time.sleep(0.02)
        return len(recorder.files) >= 3

    assert wait_until(publish_until_split, timeout=60)
    recorder.close()
    files = recorder.files
    assert files[:3] == [tmp_path / f"bus_{k}.mcap" for k in range(3)]
    assert sorted(tmp_path.iterdir()) == sorted(files)
    assert sum(len(_indexed(f)) for f in files) == recorder.messages > 0
