"""gazebot values <-> ROS 2 messages (gazebot.io.ros2.convert), through real CDR bytes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.core.types import Event, EventKind, GazeCommand, Phase, TrackingFrame
from gazebot.io.ros2 import Codec, MessageError, typestore
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2.values import BusEvent, EyeState, JointGoal, JointState, NodeStatus


def wire(msg: object) -> object:
    """``msg`` through CDR bytes and back, as a subscriber receives it."""
    codec = Codec.for_type(typestore(), msg.__msgtype__)
    return codec.decode(codec.encode(msg))


def Command(**changes: object) -> GazeCommand:  # noqa: N802 - reads as the value it builds
    """An engine command looking at a hand, with ``changes``."""
    cmd = GazeCommand(t=2.25, phase=Phase.REACH, target="hand",
                      target_point=np.array([0.8, 0.1, 1.1]),
                      head={"head_pan": 0.3, "head_tilt": -0.1}, eye_yaw=0.05, eye_pitch=-0.02,
                      blink=0.25, distance=0.9)
    return cmd.replaced(**changes)


def test_time_is_split_into_sec_and_nanosec_and_back() -> None:
    for t in (0.0, 1.5, 12.000000001, -0.25):
        stamp = cv.to_time(t)
        assert 0 <= stamp.nanosec < 1_000_000_000
        assert cv.from_time(stamp) == pytest.approx(t, abs=1e-9)


@pytest.mark.parametrize("t", [math.nan, math.inf, 3e9])
def test_time_that_ros_cannot_hold_is_a_message_error(t: float) -> None:
    with pytest.raises(MessageError):
        cv.to_time(t)


def test_tracking_frame_becomes_one_point_per_tracked_body_and_back() -> None:
    frame = TrackingFrame.make(1.0, giver_hand=[0.5, 0.0, 1.0], giver_face=[1.2, 0.1, 1.6])
    points = cv.tracking_points(frame)
    assert sorted(points) == ["giver_face", "giver_hand"]  # the missing hand is not sent
    received = {}
    for body, p in points.items():
        t, received[body] = cv.point_of(wire(cv.point_stamped(frame.t, p, "world")))
        assert t == 1.0
    back = cv.tracking_frame(1.0, received)
    np.testing.assert_array_equal(back.giver_hand, frame.giver_hand)
    assert np.isnan(back.receiver_hand).all()


def test_pose_stamped_and_tf_carry_the_same_points() -> None:
    frame = TrackingFrame.make(0.5, giver_hand=[0.5, 0.0, 1.0], receiver_hand=[0.6, 0.1, 1.0])
    t, p = cv.point_of(wire(cv.pose_stamped(0.5, frame.giver_hand, "world")))
    assert t == 0.5 and p.tolist() == [0.5, 0.0, 1.0]
    tf = wire(cv.tracking_tf(frame, "world", {"giver_hand": "mocap/hand_l"}))
    got = cv.tf_points(tf)
    assert set(got) == {"mocap/hand_l", "receiver_hand"}
    assert got["receiver_hand"][1].tolist() == [0.6, 0.1, 1.0]


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_coordinates_are_a_message_error_both_ways(bad: float) -> None:
    with pytest.raises(MessageError, match="not finite"):
        cv.point_stamped(0.0, [bad, 0.0, 1.0], "world")
    msg = cv.point_stamped(0.0, [0.0, 0.0, 1.0], "world")
    msg.point.y = bad  # what a foreign publisher may send
    with pytest.raises(MessageError, match="not finite"):
        cv.point_of(wire(msg))


def test_joint_states_round_trip_and_inconsistent_arrays_are_refused() -> None:
    state = cv.joint_positions(wire(cv.joint_state(3.0, {"right_j0": 0.1, "head_pan": -0.4})))
    assert state == JointState(3.0, {"right_j0": 0.1, "head_pan": -0.4})
    msg = cv.joint_state(3.0, {"a": 0.1, "b": 0.2})
    msg.position = np.array([0.1])
    with pytest.raises(MessageError, match="2 names but 1 positions"):
        cv.joint_positions(wire(msg))


def test_head_command_is_one_trajectory_point_in_the_commands_joint_order() -> None:
    msg = wire(cv.joint_trajectory(JointGoal(2.25, {"head_pan": 0.3, "head_tilt": -0.1}, {},
                                             time_from_start=0.05)))
    assert list(msg.joint_names) == ["head_pan", "head_tilt"]
    (point,) = msg.points
    assert point.positions.tolist() == [0.3, -0.1]
    assert point.velocities.tolist() == [0.0, 0.0]
    assert cv.from_time(point.time_from_start) == pytest.approx(0.05)
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (0, 0)  # start on receipt
    goal = cv.trajectory_goal(msg)
    assert goal.positions == {"head_pan": 0.3, "head_tilt": -0.1}
    assert goal.time_from_start == pytest.approx(0.05) and goal.t == 0.0
    assert goal.velocities == {"head_pan": 0.0, "head_tilt": 0.0}
    head = JointGoal.head_of(Command(), None, period=0.05)
    stamped = cv.joint_trajectory(JointGoal(head.t, head.positions, {"head_pan": 0.2}, 0.05),
                                  stamped=True)
    assert cv.stamp_of(stamped) == 2.25
    assert stamped.points[0].velocities.tolist() == [0.2, 0.0]


def test_a_non_finite_head_command_never_becomes_a_message() -> None:
    with pytest.raises(ValueError, match="not finite"):
        JointGoal.head_of(Command(head={"head_pan": math.nan}))
    msg = cv.joint_trajectory(JointGoal(0.0, {"head_pan": 0.1}))
    msg.points[0].positions = np.array([math.nan])  # what a foreign publisher may send
    with pytest.raises(MessageError, match="not finite"):
        cv.trajectory_goal(wire(msg))


def test_gaze_target_is_in_the_robot_base_frame() -> None:
    msg = wire(cv.gaze_target(Command(), "world"))
    assert msg.header.frame_id == "world" and cv.stamp_of(msg) == 2.25
    assert [msg.point.x, msg.point.y, msg.point.z] == [0.8, 0.1, 1.1]
    with pytest.raises(MessageError):
        cv.gaze_target(Command(target_point=np.full(3, np.nan)), "world")


def test_eye_state_round_trips_with_unknown_distance_as_nan() -> None:
    eyes = cv.eyes_of(wire(cv.eye_state(EyeState.of(Command()), "gaze")))
    assert eyes == EyeState(2.25, 0.05, -0.02, 0.25, 0.9)
    msg = wire(cv.eye_state(EyeState.of(Command(distance=None)), "gaze"))
    assert math.isnan(msg.distance) and cv.eyes_of(msg).distance is None
    msg.blink = 1.5
    with pytest.raises(MessageError, match="blink"):
        cv.eyes_of(msg)
    with pytest.raises(ValueError, match="blink"):
        EyeState.of(Command(blink=1.5))
    for bad in (0.0, -1.0, math.inf):
        with pytest.raises(ValueError, match="distance"):
            EyeState(0.5, 0.0, 0.0, distance=bad)


def test_events_round_trip_with_their_info() -> None:
    event = Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.25, {"planned_duration": 1.2,
                                                            "target": "handover", "ok": True})
    value = cv.event_of(wire(cv.event_msg(event, "sim", stamp=1.3)))
    assert (value.source, value.category, value.kind) == ("sim", "robot", "robot_reach_started")
    assert value.to_event() == event
    phase = cv.event_of(wire(cv.event_msg(Event(EventKind.REACH_STARTED, 0.5, 0.7), "e", 0.7)))
    assert phase.category == "phase"
    fault = cv.event_of(wire(cv.handover_event(BusEvent(
        "engine", "fault", "peer_lost", 2.0, 2.0, 2.0, {"peer": "sim", "dropped": [1, 2]}))))
    assert fault.to_event() is None and fault.info == {"peer": "sim", "dropped": [1, 2]}
    assert fault.identity == ("engine", "peer_lost", 2_000_000_000, 2_000_000_000)


def test_an_event_gazebot_cannot_use_is_a_message_error() -> None:
    msg = cv.handover_event(BusEvent("engine", "fault", "x", 0.0, 0.0, 0.0))
    msg.kind = ""
    with pytest.raises(MessageError, match="kind"):
        cv.event_of(wire(msg))
    msg.kind, msg.source = "x", "s" * 65
    with pytest.raises(MessageError, match="source"):
        cv.event_of(wire(msg))


def test_unknown_event_category_is_a_message_error() -> None:
    msg = cv.handover_event(BusEvent("engine", "fault", "x", 0.0, 0.0, 0.0))
    msg.category = "weather"
    with pytest.raises(MessageError, match="category"):
        cv.event_of(wire(msg))


def test_phase_round_trips_with_its_source_and_unknown_end() -> None:
    state = cv.phase_of(wire(cv.handover_phase(3.0, Phase.TRANSFER, 2.5, 3.4)))
    assert state == cv.PhaseState(3.0, Phase.TRANSFER, "tracking", 2.5, pytest.approx(3.4))
    state = cv.phase_of(wire(cv.handover_phase(3.0, Phase.RETREAT, 2.9, source="gripper")))
    assert (state.phase, state.source) == (Phase.RETREAT, "gripper")
    assert math.isnan(state.expected_end)
    # The engine's command names the source beside the phase.
    assert cv.command_phase(Command(phase=Phase.TRANSFER)) == (Phase.TRANSFER, "tracking")
    sourced = Command(phase=Phase.TRANSFER, phase_source="robot")
    assert cv.command_phase(sourced) == (Phase.TRANSFER, "robot")
    with pytest.raises(MessageError, match="source"):
        cv.handover_phase(3.0, Phase.TRANSFER, 2.5, source="weather")


def test_gripper_and_load_share_round_trip_and_share_outside_0_1_is_refused() -> None:
    assert wire(cv.gripper_state(1.0, True)).closed is True
    assert cv.share_of(wire(cv.load_share(1.0, 0.4))) == (1.0, 0.4)
    with pytest.raises(MessageError):
        cv.load_share(1.0, 1.2)
    msg = cv.load_share(1.0, 0.4)
    msg.share = math.nan
    with pytest.raises(MessageError):
        cv.share_of(wire(msg))


def test_node_status_becomes_a_diagnostic_status() -> None:
    status = NodeStatus("engine", "degraded", tracking="hold", phase="reach", uptime=12.5,
                        peers={"sim": False}, dropped={"/gazebot/tracking/giver_hand": 3})
    (health,) = cv.health_of(wire(cv.diagnostics(status, t=4.0)))
    assert (health.node, health.level, health.state) == ("engine", 1, "degraded")
    assert health.values == {"tracking": "hold", "phase": "reach", "uptime": 12.5,
                             "peer/sim": "lost", "dropped//gazebot/tracking/giver_hand": 3}
    with pytest.raises(ValueError, match="state"):
        NodeStatus("engine", "fine")  # type: ignore[arg-type]


def test_eye_frame_round_trips_as_a_compressed_image() -> None:
    img = np.zeros((48, 64, 3), np.uint8)
    img[:, :32] = (255, 0, 0)
    msg = wire(cv.compressed_image(img, 1.0, "display", fmt="png"))
    assert msg.format == "png"
    np.testing.assert_array_equal(cv.image_of(msg), img)
    msg.data = np.frombuffer(b"not an image", np.uint8)
    with pytest.raises(MessageError, match="not a decodable image"):
        cv.image_of(msg)


def test_a_command_becomes_its_messages() -> None:
    cmd = Command(events=(Event(EventKind.REACH_STARTED, 2.0, 2.25),))
    out = cv.command_messages(cmd, "world", "gaze", 0.05)
    assert out.head is not None and out.gaze_target is not None
    assert cv.eyes_of(out.eyes) == EyeState.of(cmd)
    assert cv.event_of(out.events[0]).kind == "reach_started"
    lost = cv.command_messages(Command(target_point=np.full(3, np.nan), head={}), "w", "g", 0.05)
    assert lost.head is None and lost.gaze_target is None and lost.events == []


def test_the_phase_stream_kinds_are_one_set_for_the_wire_and_the_values():
    from gazebot.core.types import PHASE_OF_EVENT, PHASE_STREAM_KINDS
    from gazebot.io.ros2 import values

    assert values.category_of is cv.category_of  # one rule, not a copy
    assert set(PHASE_OF_EVENT) < PHASE_STREAM_KINDS
    for kind in EventKind:
        expected = ("fault" if kind is EventKind.FAULT
                    else "phase" if kind in PHASE_STREAM_KINDS else "robot")
        assert cv.category_of(kind.value) == expected, kind
    assert cv.category_of("tracking_lost") == "phase"
