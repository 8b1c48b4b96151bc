"""HandoverMcap: one tick -> the messages of every topic, phase starts carried over ticks,
periodic topics on a fixed time grid."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from gazebot.core.types import Event, EventKind, GazeCommand, Phase, TrackingFrame
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2.handover_log import HandoverMcap


def Cmd(t: float, phase: Phase, events: tuple[Event, ...] = ()) -> GazeCommand:  # noqa: N802
    """The engine's command at ``t`` in ``phase``, looking at a point ahead."""
    return GazeCommand(t=t, phase=phase, target="face", target_point=np.array([0.8, 0.0, 1.2]),
                       head={"head_pan": 0.2}, eye_yaw=0.1, eye_pitch=0.0, distance=1.0,
                       events=events)


def _messages(path: Path) -> dict[str, list]:
    out: dict[str, list] = {}
    with AnyReader([path]) as reader:
        for conn, _, raw in reader.messages():
            out.setdefault(conn.topic, []).append(reader.deserialize(raw, conn.msgtype))
    return out


def test_ticks_become_every_topic_with_phase_starts_and_periodic_topics(tmp_path: Path) -> None:
    path = tmp_path / "log.mcap"
    log = HandoverMcap(path, "world", "gaze", 1 / 120, eye_image=lambda *a: np.zeros(
        (16, 16, 3), np.uint8), eye_image_period=0.1, diagnostics_period=1.0)
    for i in range(241):  # 2 s at 120 Hz
        t = i / 120
        phase = Phase.IDLE if t < 1.0 else Phase.REACH
        frame = TrackingFrame.make(t, giver_hand=[0.5, 0, 1], receiver_hand=[0.7, 0, 1],
                                   gripper_closed=False, load_share=0.0)
        robot = [Event(EventKind.ROBOT_REACH_STARTED, t, t)] if i == 60 else []
        events = (Event(EventKind.REACH_STARTED, 0.9, t),) if i == 120 else ()
        cmd = None if i == 5 else Cmd(t, phase, events=events)  # tick 5: nothing safe to send
        log.tick(t, frame, {"head_pan": 0.1, "right_j0": 0.0}, robot, cmd)
    log.close()
    msgs = _messages(path)
    assert len(msgs["/gazebot/tracking/giver_hand"]) == 241
    assert "/gazebot/tracking/giver_face" not in msgs  # never tracked: never sent
    assert len(msgs["/gazebot/head/command"]) == 240
    assert len(msgs["/gazebot/eyes/image/compressed"]) == 21  # 10 Hz over 0..2 s
    assert len(msgs["/diagnostics"]) == 3  # t = 0, 1, 2
    assert [cv.event_of(m).kind for m in msgs["/gazebot/robot/events"]] == [
        "robot_reach_started"]
    assert [cv.event_of(m).kind for m in msgs["/gazebot/handover/events"]] == ["reach_started"]
    phases = [cv.phase_of(m) for m in msgs["/gazebot/handover/phase"]]
    assert {p.phase_start for p in phases if p.phase is Phase.IDLE} == {0.0}
    (reach_start,) = {p.phase_start for p in phases if p.phase is Phase.REACH}
    assert reach_start == pytest.approx(1.0)
    target = msgs["/gazebot/gaze_target"][0]
    assert target.header.frame_id == "world"
    assert msgs["/gazebot/eyes/state"][0].header.frame_id == "gaze"
