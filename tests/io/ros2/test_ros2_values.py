"""The values the bus adds to the core's (gazebot.io.ros2.values): each checks its fields
(finiteness, ranges) and names the one it refuses; events and commands convert to and from the
core's values without loss."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.core.types import Event, EventKind, GazeCommand, Phase
from gazebot.io.ros2.values import (
    ArmCommand,
    BusEvent,
    EyeState,
    JointGoal,
    NodeStatus,
    finite_point,
    plain,
)


def command(t: float, pan: float) -> GazeCommand:
    return GazeCommand(t=t, phase=Phase.REACH, target="hand",
                       target_point=np.array([0.7, 0.0, 1.0]), head={"head_pan": pan},
                       eye_yaw=0.05, eye_pitch=-0.02, blink=0.3, distance=0.8)


def test_head_goal_carries_the_goal_its_rate_of_change_and_the_time_to_reach_it() -> None:
    first = JointGoal.head_of(command(2.0, 0.2))
    assert first.velocities == {"head_pan": 0.0}
    assert first.time_from_start == pytest.approx(1 / 120)
    second = JointGoal.head_of(command(2.01, 0.21), first)
    assert second.velocities["head_pan"] == pytest.approx(1.0)
    assert second.time_from_start == pytest.approx(0.01)
    # after a pause the goal's rate of change is unknown: arrive at rest
    later = JointGoal.head_of(command(5.0, 0.5), second)
    assert later.velocities == {"head_pan": 0.0}


@pytest.mark.parametrize("fields, where", [
    ({"positions": {"head_pan": math.nan}}, "positions.head_pan"),
    ({"velocities": {"head_pan": math.inf}}, "velocities.head_pan"),
    ({"positions": {"": 0.0}}, "joint name"),
    ({"time_from_start": -0.1}, "time_from_start"),
    ({"t": math.nan}, "t"),
])
def test_a_bad_joint_goal_is_refused_with_the_field_named(fields, where) -> None:
    with pytest.raises(ValueError, match=where):
        JointGoal(**{"t": 0.0, "positions": {"head_pan": 0.1}, **fields})


def test_eye_state_is_the_commands_and_refuses_what_a_display_cannot_draw() -> None:
    assert EyeState.of(command(1.0, 0.0)) == EyeState(1.0, 0.05, -0.02, 0.3, 0.8)
    for fields, where in (({"blink": 1.5}, "blink"), ({"yaw": math.nan}, "yaw"),
                          ({"distance": 0.0}, "distance"), ({"distance": math.inf}, "distance")):
        with pytest.raises(ValueError, match=where):
            EyeState(**{"t": 0.0, "yaw": 0.0, "pitch": 0.0, **fields})


def test_bus_event_restores_engine_events_only() -> None:
    ev = Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.1, {"planned_duration": np.float64(1.5)})
    msg = BusEvent.of(ev, "sim", 5.0)
    assert msg.category == "robot" and msg.info == {"planned_duration": 1.5}
    assert msg.to_event() == Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.1,
                                   {"planned_duration": 1.5})
    fault = BusEvent("engine", "fault", "tracking_timeout", 0.0, 0.0, 0.0)
    assert fault.to_event() is None


@pytest.mark.parametrize("fields, where", [
    ({"source": ""}, "source"),
    ({"kind": "k" * 65}, "kind"),
    ({"category": "weather"}, "category"),
    ({"t": math.nan}, "not finite"),
    ({"seq": -1}, "seq"),
])
def test_a_bad_bus_event_is_refused_with_the_field_named(fields, where) -> None:
    with pytest.raises(ValueError, match=where):
        BusEvent(**{"source": "sim", "category": "fault", "kind": "x", "t": 0.0,
                    "detected_at": 0.0, "stamp": 0.0, **fields})


def test_arm_command_needs_exactly_one_goal() -> None:
    assert ArmCommand(pose="home", gripper=0.0).pose == "home"
    with pytest.raises(ValueError, match="exactly one"):
        ArmCommand(pose="home", resume=True)
    with pytest.raises(ValueError, match="pose"):
        ArmCommand(pose="wave")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="gripper"):
        ArmCommand(resume=True, gripper=2.0)


def test_status_rejects_unknown_state_and_tracking() -> None:
    with pytest.raises(ValueError, match="state"):
        NodeStatus("x", "fine")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="tracking"):
        NodeStatus("x", "ok", tracking="maybe")  # type: ignore[arg-type]


def test_points_and_info_are_made_plain() -> None:
    assert finite_point(np.array([1.0, 2.0, 3.0])) == (1.0, 2.0, 3.0)
    assert finite_point(np.full(3, np.nan)) is None and finite_point(None) is None
    assert plain({"a": np.float64(math.nan), "b": (np.int64(2), Phase.REACH)}) == {
        "a": None, "b": [2, "reach"]}
