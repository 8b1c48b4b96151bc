"""MCAP recording as rosbag2 writes it: readable by mcap-ros2-support and by rosbags, schemas
embedded with their dependencies, log time = the time given, no file after a failed run."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from gazebot.core.types import Event, EventKind
from gazebot.io.ros2 import MessageError
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2.mcap_writer import McapRecorder
from gazebot.io.ros2.values import EyeState


def _record(path: Path) -> None:
    with McapRecorder(path) as rec:
        for i in range(10):
            t = 0.5 + i / 120
            rec.write("/gazebot/tracking/giver_hand", cv.point_stamped(t, [0.1 * i, 0, 1], "world"),
                      t)
            rec.write("/joint_states", cv.joint_state(t, {"head_pan": 0.01 * i}), t)
        rec.write("/gazebot/handover/events",
                  cv.event_msg(Event(EventKind.REACH_STARTED, 0.5, 0.55, {"x": 1.5}), "e", 0.55),
                  0.55)
        rec.write("/gazebot/eyes/state", cv.eye_state(EyeState(0.6, 0.1, -0.05), "gaze"), 0.6)


@pytest.fixture
def mcap_file(tmp_path: Path) -> Path:
    path = tmp_path / "run.mcap"
    _record(path)
    return path


def test_mcap_decodes_with_mcap_ros2_support(mcap_file: Path) -> None:
    mcap_ros2 = pytest.importorskip("mcap_ros2.decoder", reason="mcap-ros2-support not installed")
    from mcap.reader import make_reader

    with mcap_file.open("rb") as f:
        reader = make_reader(f, decoder_factories=[mcap_ros2.DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        got = [(ch.topic, schema.name, m.log_time, d)
               for schema, ch, m, d in reader.iter_decoded_messages()]
    assert len(got) == 22
    hands = [g for g in got if g[0] == "/gazebot/tracking/giver_hand"]
    assert hands[3][1] == "geometry_msgs/msg/PointStamped"
    assert hands[3][2] == round((0.5 + 3 / 120) * 1e9)  # log time = the message's time, ns
    assert hands[3][3].point.x == pytest.approx(0.3)
    (event,) = [g[3] for g in got if g[0] == "/gazebot/handover/events"]
    assert event.kind == "reach_started" and event.info[0].value == "1.5"
    (eyes,) = [g[3] for g in got if g[0] == "/gazebot/eyes/state"]
    assert math.isnan(eyes.distance) and eyes.yaw == 0.1


def test_mcap_decodes_with_rosbags(mcap_file: Path) -> None:
    from rosbags.highlevel import AnyReader

    with AnyReader([mcap_file]) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        msgs = [(c.topic, t, reader.deserialize(raw, c.msgtype))
                for c, t, raw in reader.messages()]
    assert types == {
        "/gazebot/tracking/giver_hand": "geometry_msgs/msg/PointStamped",
        "/joint_states": "sensor_msgs/msg/JointState",
        "/gazebot/handover/events": "gazebot_msgs/msg/HandoverEvent",
        "/gazebot/eyes/state": "gazebot_msgs/msg/EyeState",
    }
    joints = [m for topic, _, m in msgs if topic == "/joint_states"]
    assert np.allclose([j.position[0] for j in joints], 0.01 * np.arange(10))


def test_schemas_embed_the_full_definition_with_dependencies(mcap_file: Path) -> None:
    from mcap.reader import make_reader

    with mcap_file.open("rb") as f:
        schemas = {s.name: s for s in make_reader(f).get_summary().schemas.values()}
    event = schemas["gazebot_msgs/msg/HandoverEvent"]
    assert event.encoding == "ros2msg"
    text = event.data.decode()
    for dep in ("MSG: std_msgs/Header", "MSG: builtin_interfaces/Time",
                "MSG: diagnostic_msgs/KeyValue"):
        assert dep in text


def test_a_failed_recording_leaves_no_file(tmp_path: Path) -> None:
    path = tmp_path / "failed.mcap"
    with pytest.raises(RuntimeError), McapRecorder(path) as rec:
        rec.write("/x", cv.point_stamped(0.0, [0, 0, 0], "w"), 0.0)
        raise RuntimeError("the run failed")
    assert list(tmp_path.iterdir()) == []


def test_a_topic_keeps_its_type_and_times_must_be_finite(tmp_path: Path) -> None:
    with McapRecorder(tmp_path / "x.mcap") as rec:
        rec.write("/a", cv.point_stamped(0.0, [0, 0, 0], "w"), 0.0)
        with pytest.raises(MessageError, match="recorded as geometry_msgs/msg/PointStamped"):
            rec.write("/a", cv.pose_stamped(0.0, [0, 0, 0], "w"), 0.0)
        for bad in (math.nan, -1.0):
            with pytest.raises(MessageError, match="log time"):
                rec.write("/a", cv.point_stamped(0.0, [0, 0, 0], "w"), bad)
        assert rec.topics == {"/a": "geometry_msgs/msg/PointStamped"}


def test_received_cdr_bytes_are_recorded_as_they_are(tmp_path: Path) -> None:
    from mcap.reader import make_reader

    from gazebot.io.ros2 import Codec, typestore

    codec = Codec.for_type(typestore(), cv.POINT_STAMPED)
    raw = codec.encode(cv.point_stamped(2.0, [1, 2, 3], "world"))
    with McapRecorder(tmp_path / "bus.mcap") as rec:
        rec.write_cdr("/gazebot/gaze_target", cv.POINT_STAMPED, raw, 2.0)
        with pytest.raises(MessageError, match="does not decode"):
            rec.write_cdr("/gazebot/gaze_target", cv.POINT_STAMPED, raw[:-3], 2.1)
    with (tmp_path / "bus.mcap").open("rb") as f:
        (msg,) = [m for _, _, m in make_reader(f).iter_messages()]
    assert msg.data == raw and msg.log_time == 2 * 10**9
