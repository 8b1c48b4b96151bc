"""``gazebot topic`` and ``gazebot node`` against real buses on loopback: gazebot's own nodes
during a simulated handover (``gazebot sim --with-engine`` in its own process), a publisher built
with ``zenoh-ros2-sdk`` (an independent rmw_zenoh implementation, its own process, at a
``gazebot router``), and a publisher of garbage.

Helpers and fixtures are the driver tests' (``tests/io/drivers``): free ports, the ``gazebot``
subprocess, the router and the SDK's message folder."""

from __future__ import annotations

import importlib.util
import json
import re
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "io" / "drivers"))

import test_drivers_ros2_interop as interop  # noqa: E402
from drivers_fakes import free_port, wait_until  # noqa: E402

from gazebot.apps.cli import main  # noqa: E402

# The interoperability tests' fixtures: a `gazebot router` and the SDK's message definitions.
router = interop.router
msgdir = interop.msgdir

pytestmark = pytest.mark.zenoh

PEER = Path(__file__).with_name("topic_peer.py")
PHASES = {"idle", "reach", "transfer", "retreat", "done"}
needs_sdk = pytest.mark.skipif(importlib.util.find_spec("zenoh_ros2_sdk") is None,
                               reason="zenoh-ros2-sdk (test dependency) is not installed")


def run(capsys, *argv: str) -> tuple[int, str, str]:
    """``gazebot ARGV`` in this process: exit status, stdout, stderr."""
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def handover():
    """A simulated handover with its engine, one process, on a fresh port: its endpoint."""
    port = free_port()
    proc = interop._gazebot("sim", "--with-engine", "--headless", "--duration", "300",
                    "--listen", f"tcp/127.0.0.1:{port}")
    yield f"tcp/127.0.0.1:{port}"
    proc.terminate()
    proc.communicate(timeout=60)


def test_echo_decodes_the_handover_phase_and_the_gaze_target(handover, capsys):
    # Waits for the engine's publisher (the simulation takes a while to start on a busy host).
    rc, out, err = run(capsys, "topic", "echo", "handover/phase", "--json", "-n", "2",
                       "--timeout", "180", "--connect", handover)
    assert rc == 0, err
    phases = [json.loads(line) for line in out.splitlines()]
    assert len(phases) == 2 and all(m["phase"] in PHASES for m in phases)
    assert set(phases[0]) == {"header", "phase", "source", "phase_start", "expected_end"}
    rc, out, err = run(capsys, "topic", "echo", "gaze_target", "--once", "--connect", handover)
    assert rc == 0, err
    assert out.endswith("---\n")
    target = yaml.safe_load(out.removesuffix("---\n"))
    assert target["header"]["frame_id"] == "world"
    assert set(target["point"]) == {"x", "y", "z"}
    assert all(isinstance(v, float) for v in target["point"].values())
    assert "dropped" not in err


def test_list_info_and_node_list_show_gazebots_topics_types_and_nodes(handover, capsys):
    rc, _, err = run(capsys, "topic", "echo", "handover/phase", "--once", "--timeout", "180",
                     "--connect", handover)  # the engine is up
    assert rc == 0, err
    rc, out, err = run(capsys, "topic", "list", "-t", "--connect", handover)
    assert rc == 0, err
    lines = out.splitlines()
    for name, typ in interop.GAZEBOT_TOPICS.items():
        assert f"{name} [{typ}]" in lines
    rc, out, _ = run(capsys, "topic", "list", "--connect", handover)
    assert "/gazebot/gaze_target" in out.splitlines() and "[" not in out
    rc, out, _ = run(capsys, "topic", "list", "-v", "--connect", handover)
    published = out.split("Subscribed topics:")[0]
    assert (" * /gazebot/gaze_target [geometry_msgs/msg/PointStamped] 1 publisher: "
            "/gazebot/engine") in published
    assert (" * /gazebot/tracking/giver_hand [geometry_msgs/msg/PointStamped] 1 publisher: "
            "/gazebot/sim") in published
    subscribed = out.split("Subscribed topics:")[1]
    assert re.search(r"/gazebot/head/command \[trajectory_msgs/msg/JointTrajectory\] "
                     r"\d+ subscribers?: .*/gazebot/sim", subscribed)
    rc, out, _ = run(capsys, "node", "list", "--connect", handover)
    assert {"/gazebot/engine", "/gazebot/sim"} <= set(out.splitlines())
    rc, out, _ = run(capsys, "topic", "info", "/gazebot/handover/phase", "-v",
                     "--connect", handover)
    assert rc == 0
    assert out.splitlines()[:2] == ["Type: gazebot_msgs/msg/HandoverPhase", "Publisher count: 1"]
    assert "Node name: engine" in out and "Topic type hash: RIHS01_" in out
    rc, _, err = run(capsys, "topic", "info", "nothing/here", "--connect", handover)
    assert rc == 1 and "unknown topic /gazebot/nothing/here" in err


def test_the_inspecting_node_is_no_peer_of_the_robot(handover, capsys):
    # The command-line node lives in the root namespace (as ros2's do): gazebot's nodes count
    # the nodes of their namespace as peers, and would report it lost once it exits.
    rc, out, err = run(capsys, "topic", "echo", "/diagnostics", "--json", "-n", "6",
                       "--timeout", "180", "--connect", handover)
    assert rc == 0, err
    keys = {v["key"] for line in out.splitlines() for s in json.loads(line)["status"]
            for v in s["values"]}
    assert "peer/sim" in keys or "peer/engine" in keys
    assert not [k for k in keys if k.startswith("peer/_gazebot_cli")], keys
    rc, out, _ = run(capsys, "node", "list", "--all", "--connect", handover)
    assert rc == 0 and not [n for n in out.split() if n.startswith("/gazebot/_")]


class SdkPeer:
    """``topic_peer.py``: an SDK publisher in its own process."""

    def __init__(self, port: int, msgdir: Path, topic: str, rate: float, count: int) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, str(PEER), "--port", str(port), "--msgdir", str(msgdir),
             "--topic", topic, "--rate", str(rate), "--count", str(count)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def sent(self, timeout: float = 180) -> list[float]:
        """The monotonic times of its publish calls, once it exited 0."""
        try:
            out, err = self.proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            out, err = self.proc.communicate()
            pytest.fail(f"the SDK peer did not finish in {timeout} s:\n{err[-3000:]}")
        assert self.proc.returncode == 0, err[-3000:]
        return json.loads(out.strip().splitlines()[-1])["sent"]

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.communicate()


@needs_sdk
def test_list_and_echo_show_a_topic_published_by_zenoh_ros2_sdk(router, msgdir, capsys):
    peer = SdkPeer(router, msgdir, "/sdk/points", rate=20, count=60)
    bus = f"tcp/127.0.0.1:{router}"
    try:
        # The peer waits for a subscriber before it publishes: its publisher is in the graph.
        def listed() -> bool:
            rc, out, _ = run(capsys, "topic", "list", "-t", "--connect", bus)
            return "/sdk/points [geometry_msgs/msg/PointStamped]" in out.splitlines()

        assert wait_until(listed, timeout=120, poll=0.5)
        rc, out, _ = run(capsys, "topic", "list", "-v", "--connect", bus)
        assert (" * /sdk/points [geometry_msgs/msg/PointStamped] 1 publisher: /sdk_talker"
                in out.split("Subscribed topics:")[0])
        rc, out, _ = run(capsys, "node", "list", "--connect", bus)
        assert "/sdk_talker" in out.splitlines()
        rc, out, err = run(capsys, "topic", "echo", "/sdk/points", "--json", "-n", "3",
                           "--timeout", "180", "--connect", bus)
        assert rc == 0, err
        msgs = [json.loads(line) for line in out.splitlines()]
        assert len(msgs) == 3
        for m in msgs:
            x = m["point"]["x"]
            assert m["point"] == {"x": x, "y": 2 * x, "z": 3 * x}
            assert m["header"]["frame_id"] == "sdk" and m["header"]["stamp"]["sec"] > 0
        assert [m["point"]["x"] for m in msgs] == [msgs[0]["point"]["x"] + i for i in range(3)]
        assert len(peer.sent()) == 60
    finally:
        peer.kill()


@needs_sdk
def test_hz_reports_the_rate_the_publisher_achieved(router, msgdir, capsys, monkeypatch):
    # Independent of delivery delays (a busy host): hz's rate window is recorded (each receipt
    # time it was given, the message it was, how many it held at each report), so the printed
    # statistics are checked exactly against the receipt times hz itself used (recomputed
    # here, not by RateWindow). The receipts are tied to the publisher by the messages' indexes
    # (each once, in order, none missing in between) and by the median period on each side,
    # within a factor of 1.5: a stall at either end moves a few periods, not the median; a
    # wrong clock or a factor-of-2 is still caught (the arithmetic, n - 1 periods of n
    # receipts, is unit-tested on given times in tests/io/drivers/test_drivers_rmw_introspect).
    from gazebot.io.drivers.rmw import introspect
    from gazebot.io.ros2 import typestore
    from gazebot.io.ros2.codec import Codec

    windows: list[Recorded] = []

    class Recorded(introspect.RateWindow):
        def __init__(self, *args, **kw) -> None:
            super().__init__(*args, **kw)
            self.ticks: list[float] = []  # every receipt time the window was given
            self.reports: list[tuple[introspect.RateStats | None, int]] = []  # (stats, ticks)
            self.each = threading.Lock()
            windows.append(self)

        def tick(self, t: float | None = None) -> None:
            t = self.clock() if t is None else t
            with self.each:
                self.ticks.append(t)
                super().tick(t)

        def stats(self) -> introspect.RateStats | None:
            with self.each:
                s = super().stats()
                self.reports.append((s, len(self.ticks)))
            return s

    ids: list[int] = []  # point.x of each message hz's handler got: the peer's index
    decode = Codec.for_type(typestore(), "geometry_msgs/msg/PointStamped").decode
    received = threading.Lock()
    subscribe = introspect.Inspector.subscribe

    def recording_subscribe(self, topic, ros_type, handler, raw=False):
        def handle(msg, rx):
            with received:  # the index and the tick of one message, together
                ids.append(int(decode(msg).point.x))
                handler(msg, rx)
        return subscribe(self, topic, ros_type, handle, raw=raw)

    monkeypatch.setattr(introspect, "RateWindow", Recorded)
    monkeypatch.setattr(introspect.Inspector, "subscribe", recording_subscribe)
    count, rate = 200, 50.0
    peer = SdkPeer(router, msgdir, "/sdk/rate", rate=rate, count=count)
    try:
        # Stops after every message or after the duration (the peer is done in 5 s: it
        # publishes 1 s after it sees the subscription); the first few may go out before the
        # route is in place, the last ones may never (the peer exits right after them).
        rc, out, err = run(capsys, "topic", "hz", "/sdk/rate", "-n", str(count), "--window",
                           "1000", "--duration", "20", "--timeout", "180",
                           "--connect", f"tcp/127.0.0.1:{router}")
        sent = peer.sent()
    finally:
        peer.kill()
    assert rc == 0, err
    assert len(windows) == 1
    w = windows[0]
    # Each message received once, in order, none lost between the first and the last received
    # (those before the route was up are lost, and the peer's last ones may be: it exits
    # without flushing): one receipt time per message (ids[i] is the message of w.ticks[i]).
    assert ids and ids == list(range(ids[0], ids[0] + len(ids))) and ids[-1] < count, ids
    assert len(w.ticks) == len(ids) == w.count
    assert len(ids) >= 20, f"{len(ids)} messages received, too few for a rate: test void"

    printed = re.findall(r"no new messages|average rate: ([\d.]+)\n\tmin: ([\d.]+)s max: "
                         r"([\d.]+)s std dev: ([\d.]+)s window: (\d+)", out)
    assert len(printed) == len(w.reports), out  # one line (or two) per report
    last = max(i for i, p in enumerate(printed) if p[0])  # the last rate printed
    rate_, lo, hi, std, window = printed[last]
    _, n = w.reports[last]
    assert n == len(w.ticks), "the last rate left out messages received before it"
    times = w.ticks[:n][-1001:]  # the window: the last 1000 periods (all of them here)
    periods = np.diff(times)
    assert int(window) == periods.size == n - 1, out
    assert float(rate_) == pytest.approx(periods.size / (times[-1] - times[0]),
                                         abs=5e-4 + 1e-9), out
    assert (float(lo), float(hi)) == pytest.approx((periods.min(), periods.max()),
                                                   abs=5e-4 + 1e-9), out
    assert float(std) == pytest.approx(periods.std(), abs=5e-6 + 1e-9), out
    # The same messages' periods as published, on the peer's clock (the system's, as ours).
    published = float(np.median(np.diff([sent[i] for i in ids])))
    ratio = float(np.median(periods)) / published
    assert 1 / 1.5 < ratio < 1.5, (ratio, published, rate)


@pytest.fixture
def garbage_bus():
    """A gazebot node publishing PointStamped on ``/junk``, every other message not CDR."""
    from gazebot.io.drivers.rmw.names import Names
    from gazebot.io.drivers.rmw.node import RosNode
    from gazebot.io.drivers.session import BusConfig, open_session

    endpoint = f"tcp/127.0.0.1:{free_port()}"
    session = open_session(BusConfig(Names(), listen=(endpoint,)))
    node = RosNode(session, Names(), "junk")
    pub = node.publisher("/junk", "geometry_msgs/msg/PointStamped")
    node.announce()
    stop = threading.Event()

    def loop() -> None:
        i = 0
        while not stop.wait(0.02):
            i += 1
            if i % 2:
                pub.publish_raw(b"\x00\x01\x00\x00garbage")
            else:
                pub.publish(node.store.types[pub.codec.type_name](
                    header=node.store.types["std_msgs/msg/Header"](
                        stamp=node.store.types["builtin_interfaces/msg/Time"](sec=i, nanosec=0),
                        frame_id="junk"),
                    point=node.store.types["geometry_msgs/msg/Point"](x=1.0, y=2.0, z=3.0)))

    th = threading.Thread(target=loop, daemon=True)
    th.start()
    yield endpoint
    stop.set()
    th.join(timeout=10)
    node.close()
    session.close()


def test_echo_counts_messages_that_do_not_decode_and_says_so_in_two_lines(garbage_bus, capsys):
    rc, out, err = run(capsys, "topic", "echo", "/junk", "--json", "-n", "3", "--timeout",
                       "60", "--connect", garbage_bus)
    assert rc == 0, err
    assert [json.loads(line)["point"] for line in out.splitlines()] == [
        {"x": 1.0, "y": 2.0, "z": 3.0}] * 3
    assert "Traceback" not in err
    about = [line for line in err.splitlines() if "/junk" in line]
    assert len(about) == 2, err  # however many: one line at the first, one at the end
    assert about[0].startswith("gazebot topic: dropping messages on /junk: does not decode")
    assert re.fullmatch(r"gazebot topic: \d+ messages? on /junk dropped, the last one: "
                        r"does not decode .*", about[1])


def test_an_unknown_topic_waits_then_says_so(garbage_bus, capsys):
    rc, out, err = run(capsys, "topic", "hz", "/nobody", "--timeout", "3",
                       "--connect", garbage_bus)
    assert rc == 1 and out == ""
    assert "no publisher on /nobody yet; waiting (at most 3 s)" in err
    assert "no publisher appeared on /nobody in 3 s" in err
