"""``gazebot demo`` writes ``handover.mcap``: every topic of the run as ROS 2 messages, decodable
by mcap-ros2-support and by rosbags, log time = the run's wall clock (simulation time in the
header stamps); ``gazebot phases`` reads the phases the demo's timeline shows back out of it."""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import json
import time

import numpy as np
import pytest

from gazebot.apps.cli import demo, main
from gazebot.io.ros2 import topics as tp

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo_mcap")
    parser = argparse.ArgumentParser()
    demo.register(parser.add_subparsers())
    # A small video: this test is about the MCAP beside it.
    args = parser.parse_args(["demo", "--out", str(out), "--no-progress", "--json",
                              "--width", "64", "--height", "48"])
    started = time.time_ns()
    with contextlib.redirect_stdout(io.StringIO()) as stdout:
        assert args.func(args) == 0
    wall = (started, time.time_ns())
    with (out / "timeline.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    return out, rows, {**json.loads(stdout.getvalue()), "wall_ns": wall}


def _phase_changes(rows) -> list[tuple[str, float]]:
    out: list[tuple[str, float]] = []
    for r in rows:
        if not out or out[-1][0] != r["phase"]:
            out.append((r["phase"], float(r["t"])))
    return out


def test_demo_mcap_decodes_with_mcap_ros2_support_on_every_topic(demo_run):
    decoder = pytest.importorskip("mcap_ros2.decoder", reason="mcap-ros2-support not installed")
    from mcap.reader import make_reader

    out, rows, summary = demo_run
    assert summary["mcap"] == str(out / "handover.mcap")
    counts: dict[str, int] = {}
    with (out / "handover.mcap").open("rb") as f:
        reader = make_reader(f, decoder_factories=[decoder.DecoderFactory()])
        for _, channel, message, msg in reader.iter_decoded_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            if channel.topic == "/gazebot/tracking/giver_hand":
                stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
                # Log time = the run's wall clock (rosbag2's); simulation time in the header.
                assert summary["wall_ns"][0] <= message.log_time <= summary["wall_ns"][1]
                assert stamp < 10**12  # seconds of simulation, not an epoch
    # Every topic (/tf: the head's frames) but the arm goals no operator sends in a demo.
    expected = {t.resolve() for t in tp.ALL} - {
        t.resolve() for t in (tp.ARM_COMMAND, tp.ARM_MODE)}
    assert set(counts) == expected
    ticks = len(rows)
    for topic in ("/gazebot/head/command", "/gazebot/eyes/state", "/gazebot/handover/phase",
                  "/joint_states", "/gazebot/tracking/giver_hand"):
        assert counts[topic] == pytest.approx(ticks, abs=2)
    # Eye images at 5 Hz from t = 0.
    seconds = float(rows[-1]["t"])
    assert counts["/gazebot/eyes/image/compressed"] == pytest.approx(5 * seconds + 1, abs=1)
    assert counts["/diagnostics"] == pytest.approx(seconds + 1, abs=1)


def test_demo_mcap_decodes_with_rosbags_and_its_phase_topic_follows_the_timeline(demo_run):
    from rosbags.highlevel import AnyReader

    out, rows, _ = demo_run
    phases: list[str] = []
    with AnyReader([out / "handover.mcap"]) as reader:
        conns = [c for c in reader.connections if c.topic == "/gazebot/handover/phase"]
        for conn, _, raw in reader.messages(connections=conns):
            p = reader.deserialize(raw, conn.msgtype).phase
            if not phases or phases[-1] != p:
                phases.append(p)
        for conn, _, raw in reader.messages():  # everything decodes
            reader.deserialize(raw, conn.msgtype)
    assert phases == [p for p, _ in _phase_changes(rows)]
    assert phases == ["idle", "reach", "transfer", "retreat", "done"]


def test_gazebot_phases_finds_the_timelines_phases_in_the_demo_mcap(demo_run, capsys):
    out, rows, _ = demo_run
    assert main(["phases", str(out / "handover.mcap"), "--online", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    segments = [(s["phase"], s["detected_at"]) for s in doc["segments"]]
    shown = [(p, t) for p, t in _phase_changes(rows) if p in ("reach", "transfer", "retreat")]
    # The same online detector on the recorded tracking: the same phases, detected on the
    # same ticks as the demo's engine did.
    assert [p for p, _ in segments] == [p for p, _ in shown]
    for (_, detected), (_, t) in zip(segments, shown, strict=True):
        assert detected == pytest.approx(t, abs=1e-6)
    assert main(["phases", str(out / "handover.mcap")]) == 0
    lines = capsys.readouterr().out.splitlines()[2:]
    assert [line.split()[1] for line in lines] == ["reach", "transfer", "retreat"]


def _decoded(path, topics: set[str]) -> dict[str, list]:
    decoder = pytest.importorskip("mcap_ros2.decoder", reason="mcap-ros2-support not installed")
    from mcap.reader import make_reader

    out: dict[str, list] = {t: [] for t in topics}
    with path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[decoder.DecoderFactory()])
        for _, channel, message, msg in reader.iter_decoded_messages(topics=sorted(topics)):
            out[channel.topic].append((message.log_time, msg))
    return out


def _pose(tf) -> tuple[np.ndarray, np.ndarray]:
    """A TransformStamped as (rotation, translation), with Pinocchio's quaternion."""
    import pinocchio as pin

    q, p = tf.transform.rotation, tf.transform.translation
    return pin.Quaternion(q.w, q.x, q.y, q.z).toRotationMatrix(), np.array([p.x, p.y, p.z])


def test_demo_mcap_holds_what_foxglove_draws_the_robot_hands_and_gaze_from(demo_run):
    import pinocchio as pin

    out, rows, summary = demo_run
    topics = {"/tf", "/tf_static", "/robot_description", "/gazebot/markers"}
    got = _decoded(out / "handover.mcap", topics)
    start, end = summary["wall_ns"]
    for topic in topics:
        assert got[topic], topic
        # Log time: the run's wall clock (within the run, so within a minute of it).
        assert all(start <= t <= end for t, _ in got[topic]), topic
    (_, desc), = got["/robot_description"]
    (_, static), = got["/tf_static"]
    # The description is a URDF Pinocchio loads; its links are the frames on /tf and /tf_static.
    model = pin.buildModelFromXML(desc.data)
    links = {f.name for f in model.frames if f.type == pin.FrameType.BODY}
    moving = {tf.child_frame_id for tf in got["/tf"][0][1].transforms}
    assert {tf.header.frame_id for tf in got["/tf"][0][1].transforms} == {"world"}
    assert moving | {"gaze", "world"} == links
    (gaze_tf,) = static.transforms
    assert gaze_tf.child_frame_id == "gaze" and gaze_tf.header.frame_id in moving
    # /tf and markers at 30 Hz of simulation time.
    seconds = float(rows[-1]["t"])
    assert len(got["/tf"]) == pytest.approx(30 * seconds + 1, abs=2)
    assert len(got["/gazebot/markers"]) == len(got["/tf"])
    # Each scene's gaze ray starts at the gaze origin the frames put it at, and the hands are
    # there once tracked.
    hands = 0
    parents = {}
    for (_, tf_msg), (_, markers) in zip(got["/tf"], got["/gazebot/markers"], strict=True):
        for tf in tf_msg.transforms:
            parents[tf.child_frame_id] = _pose(tf)
        R, p = parents[gaze_tf.header.frame_id]
        Rg, pg = _pose(gaze_tf)
        origin = R @ pg + p
        by_id = {m.id: m for m in markers.markers}
        ray = by_id[0]
        assert ray.header.frame_id == "world"
        if ray.action == 0:  # ADD
            start_pt = ray.points[0]
            np.testing.assert_allclose([start_pt.x, start_pt.y, start_pt.z], origin, atol=1e-9)
        hands += by_id[2].action == 0
    assert hands > len(got["/tf"]) // 2


def test_the_foxglove_layout_shows_topics_and_fields_the_demo_mcap_has(demo_run):
    import json
    from pathlib import Path

    from mcap.reader import make_reader

    out, _, _ = demo_run
    layout = json.loads((Path(__file__).parents[3] / "docs" / "foxglove-layout.json").read_text())
    panels = layout["configById"]
    with (out / "handover.mcap").open("rb") as f:
        channels = {c.topic for c in make_reader(f).get_summary().channels.values()}
    three_d = panels["3D!gazebot"]
    shown = {t for t, cfg in three_d["topics"].items() if cfg["visible"]}
    assert shown <= channels and {"/robot_description", "/gazebot/markers"} <= shown
    assert three_d["followTf"] == "world"  # the shipped robots' base frame
    paths = [p["value"] for p in panels["StateTransitions!phase"]["paths"]]
    from gazebot.io.ros2.typestore import typestore

    fields = {"/gazebot/handover/phase": set(
        typestore().types[tp.PHASE.type].__dataclass_fields__)}
    for path in paths:
        topic, _, field = path.partition(".")
        assert topic in channels and field in fields[topic]
    for key in ("RawMessages!phase", "RawMessages!events"):
        assert panels[key]["topicPath"] in channels
    assert panels["Image!eyes"]["imageMode"]["imageTopic"] in channels
