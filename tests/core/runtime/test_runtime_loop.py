"""The one runtime loop: the behavior's own tracking-loss timings, the safety checks, vergence
and blinks (the same command stream over Zenoh:
``tests/io/drivers/test_drivers_same_stream.py``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.core.runtime import GazeLoop
from gazebot.core.types import GazeCommand, Phase, TrackingFrame


def test_silence_holds_for_the_behaviors_hold_time_then_looks_at_its_target():
    loop = GazeLoop.from_config("sawyer", "face-hand-face")
    spec = loop.engine.behavior_spec.tracking_lost
    gap = loop.engine.detector.config.max_gap_hold
    face = np.array([1.1, -0.3, 1.6])
    hand = np.array([1.0, 0.3, 0.9])
    t = 0.0
    for _ in range(120):  # 1 s of tracking: the gaze settles on the face
        cmd = loop.tick(TrackingFrame.make(t, giver_hand=hand, receiver_hand=[0.4, 0, 0.9],
                                              giver_face=face))
        t += 1 / 120
    last = t - 1 / 120
    assert cmd.tracking == "ok" and cmd.target == "face"
    states = []
    while t < last + gap + spec.hold_s + 1.0:  # silence at 30 Hz
        cmd = loop.tick(None, t=t)
        states.append((t, cmd.tracking, cmd.target))
        assert not cmd.answers_sample
        t += 1 / 30
    # bridged by the detector for max_gap_hold, then held for the behavior's hold_s, then lost
    first_hold = next(t for t, s, _ in states if s == "hold")
    first_lost = next(t for t, s, _ in states if s == "lost")
    assert last + gap < first_hold <= last + gap + 1 / 30 + 1e-9
    # the behavior's hold counts from the last valid sample (the tracking_lost event's time)
    lost_at = max(last + spec.hold_s, first_hold)
    assert lost_at - 1e-9 <= first_lost <= lost_at + 1 / 30 + 1e-9
    assert all(s == "ok" for t, s, _ in states if t <= last + gap)
    lost = [c for c in states if c[1] == "lost"]
    assert lost and all(target == spec.target for _, _, target in lost)
    np.testing.assert_allclose(cmd.target_point, face)
    # samples return: ok again
    cmd = loop.tick(TrackingFrame.make(t, giver_hand=hand, receiver_hand=[0.4, 0, 0.9],
                                          giver_face=face))
    assert cmd.tracking == "ok" and cmd.answers_sample


class _Engine:
    """Returns whatever command it is given, on a real robot model."""

    def __init__(self, robot) -> None:
        self.robot = robot
        self.next: GazeCommand | None = None
        self.phase = Phase.IDLE

    def step(self, frame, arm=None) -> GazeCommand:
        return self.next

    tracking = "ok"


@pytest.fixture(scope="module")
def sawyer():
    from gazebot.core.kinematics import RobotModel

    return RobotModel.load("sawyer")


def _cmd(head, yaw=0.0, pitch=0.0, t=1.0, point=(1.0, 0.0, 1.5), shift=0.0):
    return GazeCommand(t=t, phase=Phase.IDLE, target="face", target_point=np.array(point),
                       head=head, eye_yaw=yaw, eye_pitch=pitch, gaze_shift=shift)


@pytest.mark.parametrize("bad", [
    {"head_pan": math.nan}, {"head_pan": math.inf},
])
def test_a_non_finite_head_goal_is_never_returned(sawyer, bad):
    engine = _Engine(sawyer)
    loop = GazeLoop(engine)
    engine.next = _cmd(bad)
    assert loop.tick(TrackingFrame(t=1.0)) is None
    engine.next = _cmd({"head_pan": 0.1}, yaw=math.nan)
    assert loop.tick(TrackingFrame(t=1.1)) is None
    assert loop.unsafe == 2


def test_out_of_limit_head_and_eye_commands_are_refused_not_clipped_again(sawyer):
    # The gaze controller is the one clip; the loop only checks what any engine hands it.
    engine = _Engine(sawyer)
    loop = GazeLoop(engine)
    for t, cmd in enumerate([
        _cmd({"head_pan": 50.0}),
        _cmd({"head_pan": 0.0}, yaw=3.0),
        _cmd({"head_pan": 0.0}, pitch=-3.0),
        _cmd({"head_pan": 0.0, "elbow": 0.0}),  # a joint the robot lacks
    ]):
        engine.next = cmd.replaced(t=float(t))
        assert loop.tick(TrackingFrame(t=float(t))) is None
    assert loop.unsafe == 4
    hi = float(sawyer.upper[0])
    engine.next = _cmd({"head_pan": hi}, yaw=sawyer.eyes.yaw_range[1], t=5.0)
    cmd = loop.tick(TrackingFrame(t=5.0))  # at the limits is within them
    assert cmd.head == {"head_pan": hi} and 0.0 <= cmd.blink <= 1.0 and loop.unsafe == 4


def test_distance_is_from_the_gaze_frame_at_the_commanded_head_pose(sawyer):
    engine = _Engine(sawyer)
    loop = GazeLoop(engine)
    point = np.array([1.2, 0.4, 1.3])
    engine.next = _cmd({"head_pan": 0.3}, point=point)
    cmd = loop.tick(TrackingFrame(t=1.0))
    origin = sawyer.gaze_pose(sawyer.head_vector({"head_pan": 0.3})).position
    assert cmd.distance == pytest.approx(float(np.linalg.norm(point - origin)))
    engine.next = _cmd({"head_pan": 0.3}, point=(math.nan,) * 3, t=1.1)
    assert loop.tick(TrackingFrame(t=1.1)).distance is None


def test_big_gaze_shifts_bring_blinks_and_the_blink_stream_is_seeded(sawyer):
    def blinks(seed):
        loop = GazeLoop(_Engine(sawyer), seed=seed)
        out = []
        for i in range(600):  # the target jumps 60 degrees every second
            y = 1.0 if (i // 120) % 2 else -1.0
            jump = math.radians(60.0) if i % 120 == 0 and i else 0.0  # the engine's gaze_shift
            loop.engine.next = _cmd({"head_pan": 0.0}, t=i / 120, point=(1.0, y, 1.5),
                                    shift=jump)
            out.append(loop.tick(TrackingFrame(t=i / 120)).blink)
        return out, loop.blinks.blink_times

    a, times = blinks(0)
    b, _ = blinks(0)
    assert a == b and max(a) == 1.0
    hit = sum(any(abs(bt - k) < 0.05 for bt in times) for k in range(1, 5))
    assert hit >= 2  # shift_probability 0.9: most jumps blink at once


def test_the_loop_fills_the_engines_command_without_copying_its_fields_by_hand(sawyer):
    engine = _Engine(sawyer)
    loop = GazeLoop(engine)
    engine.next = _cmd({"head_pan": 0.2})
    cmd = loop.tick(TrackingFrame(t=1.0))
    assert type(cmd) is GazeCommand and cmd.head == {"head_pan": 0.2}
    assert engine.next.blink == 0.0 and engine.next.distance is None  # the engine's is untouched
    assert cmd.replaced(blink=0.5).blink == 0.5
    with pytest.raises(TypeError, match="no fields"):
        cmd.replaced(blinks=0.5)


def test_distance_follows_the_measured_head_and_the_arm_carrying_it():
    # The display is where the measured head is (when every head joint is measured) and moves
    # with the arm joint that carries the head, even while the commanded pose stays the same.
    from gazebot.core.kinematics import RobotModel

    robot = RobotModel.load("sawyer")
    engine = _Engine(robot)
    loop = GazeLoop(engine)
    point = np.array([1.2, 0.4, 1.3])

    def expected(arm: float, pan: float) -> float:
        probe = RobotModel.load("sawyer")
        probe.set_arm({"right_j0": arm})
        origin = probe.gaze_pose(probe.head_vector({"head_pan": pan})).position
        return float(np.linalg.norm(point - origin))

    cases = [
        ({"right_j0": 0.0, "head_pan": 0.5}, 0.0, 0.5),  # measured head: its pose
        ({"right_j0": 0.6, "head_pan": 0.5}, 0.6, 0.5),  # the arm moved, the head did not
        ({"right_j0": 0.6}, 0.6, 0.3),  # head not measured: the commanded pose
        ({"right_j0": 0.6, "head_pan": math.nan}, 0.6, 0.3),  # nor when not a number
        ({"right_j0": -0.4, "head_pan": 99.0}, -0.4, float(robot.upper[0])),  # clipped
    ]
    for i, (joints, arm, pan) in enumerate(cases):
        robot.set_arm({"right_j0": arm})  # (the engine does this with the tick's joints)
        engine.next = _cmd({"head_pan": 0.3}, point=point, t=float(i))
        cmd = loop.tick(TrackingFrame(t=float(i)), joints=joints)
        assert cmd.distance == pytest.approx(expected(arm, pan), abs=1e-12), joints
