"""Eye vergence distance on the bus, the shared ``open()`` of bus nodes, and the warning when no
robot is ever seen."""

from __future__ import annotations

import argparse
import json
import math

import numpy as np
import pytest
from drivers_fakes import FakeEngine, free_port

from gazebot.core.runtime import GazeLoop
from gazebot.core.types import TrackingFrame
from gazebot.io.drivers.base import RobotDriver
from gazebot.io.drivers.engine_node import EngineNode, EngineNodeConfig
from gazebot.io.ros2.values import EyeState


class MemoryDriver(RobotDriver):
    """An in-memory robot: records what the engine node sends; no robot data ever arrives."""

    node = "engine"

    def __init__(self) -> None:
        self.eyes: list[EyeState] = []
        self.events: list = []
        self.statuses: list = []
        self.frames = False

    def send_head(self, msg) -> None:
        pass

    def send_eyes(self, msg) -> None:
        self.eyes.append(msg)

    def send_eye_frame(self, msg) -> None:
        pass

    def wants_eye_frames(self) -> bool:
        return self.frames

    def send_arm(self, msg) -> None:
        pass

    def wait_tracking(self, timeout):
        return None

    def joint_state(self):
        return None

    def poll_events(self):
        return []

    def publish_event(self, msg) -> None:
        self.events.append(msg)

    def event_history(self, timeout=1.0):
        return []

    def publish_status(self, msg) -> None:
        self.statuses.append(msg)

    def peers(self):
        return {}

    def dropped(self):
        return {}


class RecordingRenderer:
    def __init__(self) -> None:
        self.calls: list[dict] = []

    def render(self, yaw, pitch, blink=0.0, distance=None):
        self.calls.append({"yaw": yaw, "pitch": pitch, "blink": blink, "distance": distance})
        return np.zeros((8, 8, 3), np.uint8)


# -- on the wire --------------------------------------------------------------------------
def test_eye_state_distance_round_trips_and_unknown_is_nan_on_the_wire():
    from gazebot.io.ros2 import convert
    from gazebot.io.ros2.codec import Codec
    from gazebot.io.ros2.typestore import typestore

    codec = Codec.for_type(typestore(), convert.EYE_STATE)
    msg = EyeState(t=0.5, yaw=0.1, pitch=-0.2, blink=0.0, distance=0.8)
    back = convert.eyes_of(codec.decode(codec.encode(convert.eye_state(msg, "gaze"))))
    assert (back.t, back.yaw, back.pitch, back.distance) == (0.5, 0.1, -0.2, 0.8)
    unknown = EyeState(t=0.5, yaw=0.0, pitch=0.0)
    ros = convert.eye_state(unknown, "gaze")
    assert math.isnan(ros.distance) and convert.eyes_of(ros).distance is None


@pytest.mark.parametrize("bad", [0.0, -0.5, math.inf])
def test_eye_state_distance_must_be_positive_finite_metres(bad):
    with pytest.raises(ValueError, match="distance"):
        EyeState(t=0.5, yaw=0.0, pitch=0.0, distance=bad)


# -- engine node computes the distance ----------------------------------------------------
def _tracking(t: float) -> TrackingFrame:
    return TrackingFrame.make(t, giver_hand=[1.0, 0.1, 1.0], giver_face=[1.1, 0.2, 1.6])


def test_engine_node_sends_the_distance_from_the_gaze_site_to_the_target_and_renders_it():
    from gazebot.core.engine import GazeEngine

    engine = GazeEngine.from_config(robot="sawyer", behavior="face")
    drv = MemoryDriver()
    drv.frames = True
    renderer = RecordingRenderer()
    node = EngineNode(GazeLoop(engine), drv, EngineNodeConfig(eye_frame_rate=1e6),
                      eye_renderer=renderer)
    commands = []
    original = engine.step

    def step(frame, arm=None):
        commands.append(original(frame, arm=arm))
        return commands[-1]

    engine.step = step
    for i in range(5):
        node.on_tracking(_tracking(i / 30))
    assert len(drv.eyes) == 5 and len(renderer.calls) >= 1
    for cmd, eyes in zip(commands, drv.eyes, strict=True):
        origin = engine.robot.gaze_pose(engine.robot.head_vector(cmd.head)).position
        expected = float(np.linalg.norm(cmd.target_point - origin))
        assert eyes.distance == pytest.approx(expected, rel=1e-9)
        assert 0.5 < eyes.distance < 2.5  # the face about 1.1 m in front of the head
    assert renderer.calls[-1]["distance"] == pytest.approx(drv.eyes[-1].distance)


# -- no robot seen -------------------------------------------------------------------------
class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_no_robot_seen_warns_once_and_degrades_the_status():
    clock = Clock()
    drv = MemoryDriver()
    warnings: list[str] = []
    cfg = EngineNodeConfig(no_robot_warning=3.0, heartbeat_period=0.5, resync=False)
    node = EngineNode(GazeLoop(FakeEngine()), drv, cfg, warn=warnings.append, clock=clock)
    node.start()
    for now in (0.5, 1.0, 2.9):
        clock.now = now
        node.tick()
    assert warnings == [] and not [e for e in drv.events if e.kind == "no_robot"]
    for now in (3.1, 3.6, 10.0):
        clock.now = now
        node.tick()
    assert len(warnings) == 1 and "no robot seen after 3.1 s" in warnings[0]
    [event] = [e for e in drv.events if e.kind == "no_robot"]
    assert event.category == "fault" and event.info["peers"] == {}
    status = drv.statuses[-1]
    assert status.state == "degraded" and status.info["robot_seen"] is False
    assert status.info["warnings"] == warnings
    # the robot shows up: seen, no longer degraded by it
    node.on_tracking(_tracking(0.0))
    clock.now = 11.0
    node.tick()
    assert node.robot_seen and drv.statuses[-1].info["robot_seen"] is True


def test_robot_seen_in_time_gives_no_warning():
    clock = Clock()
    drv = MemoryDriver()
    warnings: list[str] = []
    node = EngineNode(
        GazeLoop(FakeEngine()), drv, EngineNodeConfig(resync=False), warn=warnings.append,
        clock=clock
    )
    node.start()
    clock.now = 1.0
    node.on_tracking(_tracking(0.0))
    for now in (2.0, 5.0, 20.0):
        clock.now = now
        node.tick()
    assert warnings == [] and node.robot_seen


def test_no_robot_warning_delay_must_be_positive():
    with pytest.raises(ValueError, match="no_robot_warning"):
        EngineNodeConfig(no_robot_warning=float("nan"))


# -- over Zenoh ----------------------------------------------------------------------------
@pytest.mark.zenoh
def test_open_is_shared_by_the_bus_nodes_and_closes_its_session(bus):
    from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
    from gazebot.io.drivers.zenoh_node import ZenohNode
    from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint

    assert "open" in ZenohNode.__dict__
    assert "open" not in ZenohRobotDriver.__dict__ and "open" not in ZenohRobotEndpoint.__dict__
    ep = ZenohRobotEndpoint.open(bus.config(listen=(bus.endpoint,)))
    drv = ZenohRobotDriver.open(bus.config(connect=(bus.endpoint,)))
    try:
        assert (ep.node, drv.node) == ("sim", "engine")
        assert isinstance(ep, ZenohRobotEndpoint) and isinstance(drv, ZenohRobotDriver)
    finally:
        drv.close()
        ep.close()
    assert drv.session.is_closed() and ep.session.is_closed()
    named = ZenohRobotEndpoint.open(bus.config(listen=(bus.endpoint,)), "display")
    named.close()
    assert named.node == "display" and named.session.is_closed()


@pytest.mark.zenoh
def test_run_cli_with_unreachable_connect_warns_and_reports_it_in_json(capsys):
    from gazebot.apps.cli import run as run_cli

    parser = argparse.ArgumentParser(prog="gazebot")
    run_cli.register(parser.add_subparsers())
    nowhere = f"tcp/127.0.0.1:{free_port()}"
    args = parser.parse_args(
        ["run", "--robot", "sawyer", "--duration", "1.2", "--no-robot-warning", "0.4",
         "--namespace", "/nobody", "--connect", nowhere, "--no-eye-frames", "--json"]
    )  # fmt: skip
    assert args.func(args) == 0
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    assert summary["robot_seen"] is False and summary["peers"] == {}
    assert len(summary["warnings"]) == 1 and "no robot seen" in summary["warnings"][0]
    assert "gazebot run: warning: no robot seen" in captured.err and nowhere in captured.err


# -- another message type ----------------------------------------------------------------
class OtherTypeRobot(MemoryDriver):
    def type_mismatches(self):
        from gazebot.io.drivers.rmw.node import TypeMismatch

        return {"/gazebot/tracking/giver_hand": TypeMismatch(
            "/gazebot/tracking/giver_hand", ("geometry_msgs/msg/PointStamped (RIHS01_aa)",),
            "geometry_msgs/msg/Vector3Stamped (RIHS01_bb)")}


def test_a_robot_speaking_another_message_type_is_reported_as_such_at_once():
    clock = Clock()
    drv = OtherTypeRobot()
    warnings: list[str] = []
    cfg = EngineNodeConfig(no_robot_warning=3.0, resync=False)
    node = EngineNode(GazeLoop(FakeEngine()), drv, cfg, warn=warnings.append, clock=clock)
    node.start()
    clock.now = 0.1
    node.tick()
    assert len(warnings) == 1  # at once, not after the no-robot delay
    assert "type mismatch on /gazebot/tracking/giver_hand" in warnings[0]
    assert "PointStamped" in warnings[0] and "Vector3Stamped" in warnings[0]
    for now in (0.2, 5.0, 9.0):
        clock.now = now
        node.tick()
    [event] = [e for e in drv.events if e.kind == "type_mismatch"]
    assert event.info["topic"] == "/gazebot/tracking/giver_hand"
    assert event.info["received"] == "geometry_msgs/msg/Vector3Stamped (RIHS01_bb)"
    # the type mismatch is reported once; the missing robot is reported too, later
    assert len([w for w in warnings if "type mismatch" in w]) == 1
    assert [e for e in drv.events if e.kind == "no_robot"]
