"""``--record`` survives a SIGKILL: a recorder process killed at a random moment leaves its file
under its final name, no part file beside it, readable by ``mcap``'s stream reader and, after
``gazebot mcap recover``, by its default reader, with every message published up to the
recorder's flush period (1 s) before the kill.

The child runs the real :class:`BusRecorder` on a loopback Zenoh session and a publisher on a
second session connected to it (so messages cross TCP), at 100 Hz; it prints each message's
number and wall-clock send time after publishing it, so the pipe holds, after the kill, what
was sent up to the end."""

from __future__ import annotations

import os
import random
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from drivers_fakes import free_port

from gazebot.apps.cli import main
from gazebot.io.ros2.mcap_writer import FLUSH_PERIOD_S

# Time a message may take from the publisher's put() to the recorder's callback on a loaded
# 2-core machine (loopback TCP, two Zenoh threads): messages sent this long plus the flush
# period before the end are required in the file.
DELIVERY_ALLOWANCE_S = 0.5

CHILD = r"""
import os, sys, time
from gazebot.io.drivers.recorder import BusRecorder
from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.rmw.node import RosNode
from gazebot.io.drivers.session import EPHEMERAL_ENDPOINT, BusConfig, open_session
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2 import topics as tp

ns, port, path = sys.argv[1:4]
names = Names(ns)
endpoint = f"tcp/127.0.0.1:{port}"
rec_session = open_session(BusConfig(names, listen=(endpoint,)))
pub_session = open_session(BusConfig(names, listen=(EPHEMERAL_ENDPOINT,), connect=(endpoint,)))
recorder = BusRecorder(rec_session, names, path)
node = RosNode(pub_session, names, "publisher")
pub = node.publisher(tp.GAZE_TARGET.name, tp.GAZE_TARGET.type)
node.announce()
i = 0
ready = False
tick = time.monotonic()
while True:
    i += 1
    pub.publish(cv.point_stamped(1.0, [float(i), 0.0, 0.0], "world"))
    if ready:
        os.write(1, f"{i} {time.time()}\n".encode())
    elif recorder.messages > 0:  # the recorder hears the publisher: from the next message on
        ready = True
        os.write(1, b"ready\n")
    tick += 0.01
    time.sleep(max(0.0, tick - time.monotonic()))
"""


def _read_until_ready(proc: subprocess.Popen, timeout: float = 60.0) -> bytes:
    """Wait for the child's ``ready`` line; returns what it printed after it."""
    buf = b""
    end = time.monotonic() + timeout
    while b"ready\n" not in buf:
        left = end - time.monotonic()
        assert left > 0 and proc.poll() is None, f"the recorder child did not start: {buf!r}"
        if select.select([proc.stdout], [], [], left)[0]:
            chunk = os.read(proc.stdout.fileno(), 65536)
            assert chunk, "the recorder child exited"
            buf += chunk
    return buf.split(b"ready\n", 1)[1]


def _gaze_targets(messages) -> list[int]:
    """The numbers (x) of the gaze-target messages among ``(schema, channel, message)``."""
    from gazebot.io.ros2 import convert as cv
    from gazebot.io.ros2.codec import Codec
    from gazebot.io.ros2.typestore import typestore

    codec = Codec.for_type(typestore(), cv.POINT_STAMPED)
    return [int(codec.decode(m.data).point.x) for _, ch, m in messages
            if ch.topic.endswith("/gaze_target")]


@pytest.mark.parametrize("seed", [1, 2])
def test_a_recorder_killed_at_a_random_moment_keeps_all_but_its_last_second(tmp_path, seed):
    from mcap.reader import NonSeekingReader, make_reader

    folder = tmp_path / "rec"
    folder.mkdir()
    path = folder / "bus.mcap"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path.cwd()), *sys.path])}
    proc = subprocess.Popen(
        [sys.executable, "-c", CHILD, f"/kill{seed}", str(free_port()), str(path)],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env)
    try:
        rest = _read_until_ready(proc)
        wait = random.Random(seed).uniform(1.2, 4.0)  # a random moment of the recording
        time.sleep(wait)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
        rest += proc.stdout.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        proc.stdout.close()
    sent = [(int(i), float(t)) for i, t in (line.split() for line in rest.decode().splitlines()
                                              if len(line.split()) == 2)]
    assert len(sent) > 50, f"the child published only {len(sent)} messages in {wait:.1f} s"
    last = sent[-1][1]
    # Under its final name, nothing else beside it.
    assert [p.name for p in folder.iterdir()] == ["bus.mcap"]

    with path.open("rb") as f:  # the stream reader reads every complete chunk directly
        streamed = []
        try:
            for item in NonSeekingReader(f).iter_messages(log_time_order=False):
                streamed.append(item)
        except Exception:  # noqa: BLE001 - the cut: whatever mcap raises on a partial record
            pass
    assert main(["mcap", "recover", str(path), "-o", str(tmp_path / "fixed.mcap")]) == 0
    with (tmp_path / "fixed.mcap").open("rb") as f:  # the default reader, after recover
        reader = make_reader(f)
        assert reader.get_summary() is not None
        recovered = list(reader.iter_messages(log_time_order=False))
    got = _gaze_targets(recovered)
    assert got == _gaze_targets(streamed)
    required = [i for i, t in sent if t <= last - FLUSH_PERIOD_S - DELIVERY_ALLOWANCE_S]
    assert required, "the recording was too short to check"
    missing = sorted(set(required) - set(got))
    assert not missing, (f"killed after {wait:.2f} s: {len(missing)} messages sent over "
                         f"{FLUSH_PERIOD_S} s before the kill are missing (first {missing[:5]})")
    assert set(got) <= {i for i, _ in sent} | set(range(min(i for i, _ in sent)))
