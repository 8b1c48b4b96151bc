"""gazebot among ROS 2 nodes: an independent ROS 2-over-Zenoh implementation (``zenoh-ros2-sdk``,
a test dependency, run as its own process by ``ros2_peer.py``) meets gazebot's nodes at a
``gazebot router``. It lists gazebot's topics with their types and hashes, decodes the gaze
target and head commands through a handover (the target moves face -> hand -> face), and drives
``gazebot run`` with a recorded handover's tracking and joint states.

The SDK gets its message definitions from a local folder: ROS 2 Jazzy's standard ones as
rosbags ships them, and ``gazebot_msgs``' own files. It computes the type hashes itself; they
must equal ROS 2's, pinned in ``tests/io/ros2/test_ros2_type_hashes.py``.
"""

from __future__ import annotations

import importlib.util
import json
import os
import queue
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from drivers_fakes import free_port

from gazebot.io.ros2 import type_info, typestore
from gazebot.io.ros2.typestore import msgs_package_dir

pytestmark = [
    pytest.mark.zenoh,
    pytest.mark.skipif(importlib.util.find_spec("zenoh_ros2_sdk") is None,
                       reason="zenoh-ros2-sdk (test dependency) is not installed"),
]

PEER = Path(__file__).with_name("ros2_peer.py")
STANDARD = ("geometry_msgs/msg/PointStamped", "trajectory_msgs/msg/JointTrajectory",
            "sensor_msgs/msg/JointState")
GAZEBOT_TOPICS = {
    "/gazebot/gaze_target": "geometry_msgs/msg/PointStamped",
    "/gazebot/head/command": "trajectory_msgs/msg/JointTrajectory",
    "/gazebot/tracking/giver_hand": "geometry_msgs/msg/PointStamped",
    "/gazebot/tracking/giver_face": "geometry_msgs/msg/PointStamped",
    "/gazebot/eyes/state": "gazebot_msgs/msg/EyeState",
    "/gazebot/handover/phase": "gazebot_msgs/msg/HandoverPhase",
    "/gazebot/handover/events": "gazebot_msgs/msg/HandoverEvent",
    "/joint_states": "sensor_msgs/msg/JointState",
    "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray",
}


@pytest.fixture(scope="module")
def msgdir(tmp_path_factory) -> Path:
    """``<pkg>/msg/<Name>.msg`` for every type the peer uses, and their dependencies."""
    root = tmp_path_factory.mktemp("msgs")
    store = typestore()
    for name in STANDARD:
        text, _ = store.generate_msgdef(name, ros_version=2)
        sections = text.split("=" * 80 + "\n")
        for i, section in enumerate(sections):
            if i == 0:
                typ, body = name, section
            else:
                head, _, body = section.partition("\n")
                pkg, _, msg = head.removeprefix("MSG: ").partition("/")
                typ = f"{pkg}/msg/{msg}"
            pkg, _, msg = typ.split("/")
            path = root / pkg / "msg" / f"{msg}.msg"
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(body.strip() + "\n")
    shutil.copytree(msgs_package_dir() / "msg", root / "gazebot_msgs" / "msg")
    return root


def _gazebot(*args: str, **kw) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[3])}
    return subprocess.Popen([sys.executable, "-m", "gazebot", *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


class Peer:
    """``ros2_peer.py`` in its own process, its stdout read line by line as it comes (and its
    stderr kept), so a test can wait for the line saying it is ready."""

    def __init__(self, mode: str, port: int, msgdir: Path, *args: str) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, str(PEER), mode, "--port", str(port), "--msgdir", str(msgdir),
             *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.lines: queue.Queue[str | None] = queue.Queue()
        self.out: list[str] = []
        self.err: list[str] = []
        self._readers = [threading.Thread(target=self._read, args=(f, sink), daemon=True)
                         for f, sink in ((self.proc.stdout, self.out),
                                         (self.proc.stderr, self.err))]
        for th in self._readers:
            th.start()

    def _read(self, stream, sink: list[str]) -> None:
        for line in stream:
            sink.append(line)
            if sink is self.out:
                self.lines.put(line.strip())
        if sink is self.out:
            self.lines.put(None)  # end of output

    def wait_line(self, text: str, timeout: float) -> None:
        """Until the peer printed ``text`` on a line of its own (``timeout`` only bounds a
        failing test)."""
        try:
            while (line := self.lines.get(timeout=timeout)) != text:
                if line is None:
                    pytest.fail(f"the peer ended without {text!r}:\n{''.join(self.err)[-3000:]}")
        except queue.Empty:
            self.proc.kill()
            pytest.fail(f"the peer did not print {text!r} in {timeout} s:\n"
                        f"{''.join(self.err)[-3000:]}")

    def result(self, timeout: float) -> dict:
        """The JSON object on the peer's last line, once it exited 0."""
        try:
            self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            pytest.fail(f"the peer did not finish in {timeout} s:\n{''.join(self.err)[-3000:]}")
        for th in self._readers:
            th.join(timeout=30)
        assert self.proc.returncode == 0, f"the peer failed:\n{''.join(self.err)[-3000:]}"
        return json.loads(self.out[-1])


def _finish(proc: subprocess.Popen, timeout: float) -> tuple[str, str]:
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        pytest.fail(f"{proc.args} did not finish in {timeout} s:\n{err[-3000:]}")
    assert proc.returncode == 0, f"{proc.args} failed:\n{err[-3000:]}"
    return out, err


@pytest.fixture
def router():
    port = free_port()
    proc = _gazebot("router", "--listen", f"tcp/127.0.0.1:{port}")
    yield port
    proc.terminate()
    proc.communicate(timeout=30)


def _labels(targets, points) -> list[str]:
    """Each gaze target as ``face`` or ``hand``: the nearer of the giver's face and hand at its
    stamp; consecutive repeats collapsed."""
    face = {round(t, 6): np.array(p) for t, *p in points["giver_face"]}
    hand = {round(t, 6): np.array(p) for t, *p in points["giver_hand"]}
    runs: list[str] = []
    for t, x, y, z, _ in targets:
        key = round(t, 6)
        if key not in face or key not in hand:
            continue
        p = np.array([x, y, z])
        label = "face" if np.linalg.norm(p - face[key]) < np.linalg.norm(p - hand[key]) else "hand"
        if not runs or runs[-1] != label:
            runs.append(label)
    return runs


def _face_hand_face(runs: list[str]) -> bool:
    want = iter(["face", "hand", "face"])
    step = next(want)
    for label in runs:
        if label == step:
            step = next(want, None)
            if step is None:
                return True
    return False


def _check_graph(topics: dict) -> None:
    for name, typ in GAZEBOT_TOPICS.items():
        assert name in topics, f"{name} not in the ROS graph: {sorted(topics)}"
        assert topics[name]["types"] == [typ]
        assert topics[name]["hashes"] == [type_info(typestore(), typ).hash]


def test_a_ros2_node_sees_gazebots_topics_and_decodes_a_handovers_gaze(router, msgdir):
    peer = Peer("listen", router, msgdir, "--duration", "90")
    peer.wait_line("ready", 120)  # subscribed first: it sees the handover from its start
    # 24 s simulated: the handover ends near 8 s, and on a machine whose cores are busy the
    # engine's `done` (re-sent with every heartbeat) must still reach the peer before the end.
    sim = _gazebot("sim", "--with-engine", "--headless", "--duration", "24", "--speed", "2",
                   "--listen", "tcp/127.0.0.1:0", "--connect", f"tcp/127.0.0.1:{router}",
                   "--json")
    sim_out, _ = _finish(sim, 180)
    out = peer.result(120)
    _check_graph(out["topics"])
    assert "sim" in out["topics"]["/gazebot/tracking/giver_hand"]["publishers"]
    assert "engine" in out["topics"]["/gazebot/gaze_target"]["publishers"]
    # the SDK's own type hashes (from the .msg files) found gazebot's keys
    for topic, h in out["sdk_hashes"].items():
        assert h == out["topics"][topic]["hashes"][0]
    assert out["targets"] and all(frame == "world" for *_, frame in out["targets"])
    assert _face_hand_face(_labels(out["targets"], out["points"])), out["phases"]
    heads = out["heads"]
    assert heads and all(h["joint_names"] == ["head_pan"] and len(h["positions"]) == 1
                         and len(h["velocities"]) == 1 and h["time_from_start"] > 0
                         for h in heads)
    assert out["phases"][-1] == "done"
    assert json.loads(sim_out)["handover_done"] is True


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> Path:
    """A simulated handover's tracking and joint states, tick by tick (120 Hz)."""
    from gazebot.apps.sim import HandoverSimulation

    ticks = []
    with HandoverSimulation("sawyer", "default", seed=3) as sim:
        done_at = None
        while sim.t < 16.0:
            sim.step(1 / 120)
            f = sim.tracking()
            tick = {"t": f.t, "joints": {k: float(v) for k, v in sim.joint_state().items()},
                    "gripper_closed": bool(f.gripper_closed), "load_share": float(f.load_share)}
            for body in ("giver_hand", "receiver_hand", "giver_face"):
                p = np.asarray(getattr(f, body), float)
                tick[body] = p.tolist() if np.all(np.isfinite(p)) else None
            ticks.append(tick)
            if done_at is None and sim.done:
                done_at = sim.t
            if done_at is not None and sim.t > done_at + 3.0:
                break
    assert done_at is not None
    path = tmp_path_factory.mktemp("rec") / "handover.json"
    path.write_text(json.dumps(ticks))
    return path


def test_a_handover_driven_from_a_ros2_node_ends_the_same_way(router, msgdir, recording):
    # No --duration: the engine runs until the peer is done, then SIGTERM ends it (summary).
    run = _gazebot("run", "--robot", "sawyer", "--behavior", "face-hand-face",
                   "--listen", "tcp/127.0.0.1:0", "--connect", f"tcp/127.0.0.1:{router}",
                   "--no-eye-frames", "--json")
    try:
        peer = Peer("drive", router, msgdir, "--recording", str(recording), "--speed", "1",
                    "--duration", "30")
        out = peer.result(180)
    finally:
        run.terminate()
    run_out, run_err = run.communicate(timeout=60)
    assert run.returncode == 0, run_err[-3000:]
    _check_graph(out["topics"])
    assert "engine" in out["topics"]["/gazebot/head/command"]["publishers"]
    ticks = json.loads(recording.read_text())
    points = {b: [[k["t"], *k[b]] for k in ticks if k[b] is not None]
              for b in ("giver_hand", "giver_face")}
    # the peer stamps with whole nanoseconds: match targets to samples by stamp
    assert _face_hand_face(_labels(out["targets"], points)), out["phases"]
    assert out["phases"][-1] == "done" and "reach" in out["phases"]
    assert out["heads"]
    # What the engine received: one sample per tick (processed, or skipped when it lagged),
    # nothing dropped on the tracking topics. The peer's first puts may precede the router's
    # route to the engine (the graph lists a subscription before its route is in place, and a
    # volatile ROS 2 publisher loses them the same way): at most 0.1 s of samples at 120 Hz.
    summary = json.loads(run_out.strip().splitlines()[-1])
    received = summary["frames"] + summary["tracking_skipped"]
    assert len(ticks) - 12 <= received <= len(ticks), summary
    assert not any("/tracking/" in topic for topic in summary["dropped"]), summary["dropped"]
    assert summary["phase"] in (None, "done")
