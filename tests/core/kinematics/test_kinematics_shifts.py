"""Gaze shifts: minimum-jerk neck and eyes, eyes leading and counter-rotating, limits, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.core.kinematics import GazeController, GazeShiftConfig, RobotModel, solve_ik
from gazebot.core.kinematics.shifts import MinJerkTrajectory, min_jerk_duration
from gazebot.core.minimum_jerk import minimum_jerk

DT = 0.002
HALF_DEG = math.radians(0.5)


@pytest.fixture(scope="module")
def jaco2() -> RobotModel:
    return RobotModel.load("jaco2")


@pytest.fixture(scope="module")
def sawyer() -> RobotModel:
    return RobotModel.load("sawyer")


def _run(controller, targets, t0=0.0, dt=DT):
    """Feed ``targets(t)`` for a while; returns times and the states."""
    out = []
    for k, target in enumerate(targets):
        t = t0 + k * dt
        out.append((t, controller.update(t, target)))
    return out


def _pan_shift(robot, deg):
    """Targets straight ahead of the head and ``deg`` to its right, 1.2 m away."""
    origin = robot.gaze_pose(robot.rest).position
    a = origin + [1.2, 0.0, 0.0]
    b = origin + 1.2 * np.array([math.cos(math.radians(deg)), -math.sin(math.radians(deg)), 0.0])
    return a, b


def test_min_jerk_trajectory_meets_its_boundary_conditions_and_shape():
    p0, p1 = np.array([0.2, -1.0]), np.array([1.0, 0.5])
    v0, a0 = np.array([0.5, -0.3]), np.array([2.0, 1.0])
    traj = MinJerkTrajectory(1.0, 0.6, p0, p1, v0, a0)
    p, v, a = traj.evaluate(1.0)
    np.testing.assert_allclose([p, v, a], [p0, v0, a0], atol=1e-12)
    p, v, a = traj.evaluate(1.6 - 1e-12)
    np.testing.assert_allclose([p, v, a], [p1, [0, 0], [0, 0]], atol=1e-9)
    np.testing.assert_allclose(traj.position(5.0), p1)  # holds the goal afterwards
    rest = MinJerkTrajectory(0.0, 0.5, np.zeros(1), np.ones(1))
    for s in np.linspace(0, 1, 11):
        assert rest.position(0.5 * s)[0] == pytest.approx(10 * s**3 - 15 * s**4 + 6 * s**5)
    # peak speed of a rest-to-rest move is 1.875 amplitude / duration
    speeds = [rest.evaluate(t)[1][0] for t in np.linspace(0, 0.5, 501)]
    assert max(speeds) == pytest.approx(1.875 / 0.5, rel=1e-4)
    assert minimum_jerk(0.5) == pytest.approx(0.5)
    assert minimum_jerk(-1) == 0 and minimum_jerk(2) == 1


def test_durations_stretch_to_respect_velocity_limits():
    assert min_jerk_duration(0.1, 0.6, 3.0, 1.0) == 0.6
    assert min_jerk_duration(np.array([2.0, 0.1]), 0.6, np.array([2.0, 2.0]), 1.0) == pytest.approx(
        1.875
    )


def test_neck_follows_a_minimum_jerk_profile_with_the_neck_duration(jaco2):
    cfg = GazeShiftConfig(eye_duration_s=0.15, neck_duration_s=0.6)
    a, b = _pan_shift(jaco2, 30.0)
    c = GazeController(jaco2, cfg)
    c.reset(solve_ik(jaco2, a).joints)
    _run(c, [a] * 10)
    onset = 9 * DT  # plans start from the previous command
    states = _run(c, [b] * 500, t0=10 * DT)
    q0 = c.robot.head_vector(solve_ik(jaco2, a).joints)
    goal = np.array(list(states[-1][1].head_goal.values()))
    for t, s in states:
        expected = q0 + (goal - q0) * minimum_jerk((t - onset) / 0.6)
        np.testing.assert_allclose(list(s.head.values()), expected, atol=1e-9)
    # done after the neck duration, not before
    for t, s in states:
        gap = np.max(np.abs(np.array(list(s.head.values())) - goal))
        if t - onset < 0.55:
            assert gap > 1e-4
        if t - onset >= 0.6:
            assert gap == 0.0


def test_eye_saccade_is_minimum_jerk_with_the_eye_duration(sawyer):
    """Sawyer cannot tilt: a pitch-only shift is done by the eyes alone, a clean saccade."""
    cfg = GazeShiftConfig(eye_duration_s=0.2, neck_duration_s=0.6)
    c = GazeController(sawyer, cfg)
    origin = sawyer.gaze_pose(sawyer.rest).position
    up, down = origin + [1.0, 0.0, 0.3], origin + [1.0, 0.0, -0.3]
    _run(c, [up] * 200)
    e0 = c.update(200 * DT, up).eye_pitch
    states = _run(c, [down] * 200, t0=201 * DT)
    onset = 200 * DT
    e1 = math.atan2(0.3, 1.0)
    for t, s in states:
        expected = e0 + (e1 - e0) * minimum_jerk((t - onset) / 0.2)
        assert s.eye_pitch == pytest.approx(expected, abs=1e-6)
        assert s.head["head_pan"] == pytest.approx(0.0, abs=1e-9)


def test_eyes_lead_then_counter_rotate_while_the_neck_keeps_the_gaze_on_target(jaco2):
    cfg = GazeShiftConfig(eye_duration_s=0.15, neck_duration_s=0.65)
    a, b = _pan_shift(jaco2, 25.0)  # within the +-30 deg eye range
    c = GazeController(jaco2, cfg)
    c.reset(solve_ik(jaco2, a).joints)
    _run(c, [a] * 10)
    onset = 9 * DT
    states = _run(c, [b] * 450, t0=10 * DT)
    pan0 = states[0][1].head["head_pan"]
    pan_goal = states[-1][1].head_goal["head_pan"]

    def at(t):
        return min(states, key=lambda ts: abs(ts[0] - t))[1]

    # eyes lead: at the end of the saccade the gaze is on target, the neck has barely moved
    landed = at(onset + 0.15 + DT)
    assert landed.residual < HALF_DEG
    neck_progress = (landed.head["head_pan"] - pan0) / (pan_goal - pan0)
    assert neck_progress < 0.2
    assert abs(landed.eye_yaw) > math.radians(20)
    # counter-rotation: while the neck turns right, the eyes turn back left, gaze stays on target
    during = [s for t, s in states if onset + 0.17 < t < onset + 0.6]
    for prev, cur in zip(during, during[1:], strict=False):
        assert cur.residual < HALF_DEG
        d_pan = cur.head["head_pan"] - prev.head["head_pan"]
        d_eye = cur.eye_yaw - prev.eye_yaw
        assert d_pan < 0 and d_eye > 0
    # at the end, the neck did the shift and the eyes are centred again
    assert abs(states[-1][1].eye_yaw) < 1e-3 and states[-1][1].residual < HALF_DEG


def test_shift_amplitude_is_reported_once_per_gaze_shift(jaco2):
    a, b = _pan_shift(jaco2, 20.0)
    c = GazeController(jaco2)
    states = _run(c, [a] * 50 + [b] * 50)
    shifts = [s.shift_amplitude for _, s in states if s.shift_amplitude > 1e-6]
    assert len(shifts) == 1  # the first target is straight ahead of the rest pose: no shift
    assert shifts[0] == pytest.approx(math.radians(20.0), abs=math.radians(1.0))


@pytest.mark.parametrize("name", ["sawyer", "jaco2"])
def test_velocity_and_joint_limits_hold_through_random_target_jumps(name):
    robot = RobotModel.load(name)
    c = GazeController(robot)
    rng = np.random.default_rng(7)
    target = robot.points["face"]
    prev, t = None, 0.0
    for k in range(1500):
        if k % 60 == 0:
            target = rng.uniform([-1.5, -2.0, 0.0], [2.5, 2.0, 3.0])
        dt = rng.choice([0.001, 0.004, 0.01, 0.033])
        t += dt
        s = c.update(t, target)
        q = np.array(list(s.head.values()))
        assert np.all(np.isfinite(q))
        assert np.all(q >= robot.lower) and np.all(q <= robot.upper)
        lo_y, hi_y = robot.eye_yaw_range
        lo_p, hi_p = robot.eye_pitch_range
        assert lo_y <= s.eye_yaw <= hi_y and lo_p <= s.eye_pitch <= hi_p
        if prev is not None:
            q_prev, e_prev = prev
            assert np.all(np.abs(q - q_prev) <= robot.velocity_limits * dt * (1 + 1e-9) + 1e-12)
            eyes = np.array([s.eye_yaw, s.eye_pitch])
            assert np.all(
                np.abs(eyes - e_prev) <= robot.eye_velocity_limit * dt * (1 + 1e-9) + 1e-12
            )
        prev = (q, np.array([s.eye_yaw, s.eye_pitch]))


def test_large_shifts_take_longer_instead_of_breaking_the_velocity_limit(jaco2):
    a, b = _pan_shift(jaco2, 140.0)
    c = GazeController(jaco2, GazeShiftConfig(neck_duration_s=0.5, eye_duration_s=0.15))
    c.reset(solve_ik(jaco2, a).joints)
    states = _run(c, [a] * 5 + [b] * 1500)
    pans = np.array([s.head["head_pan"] for _, s in states])
    speed = np.abs(np.diff(pans)) / DT
    assert speed.max() <= jaco2.velocity_limits[0] * (1 + 1e-9)
    assert speed.max() > 0.8 * jaco2.velocity_limits[0]  # it did go fast, just not too fast
    moving = np.flatnonzero(speed > 1e-9)
    assert (moving[-1] - moving[0]) * DT > 0.5


def test_moving_target_is_tracked_smoothly_with_the_gaze_on_it(jaco2):
    c = GazeController(jaco2)
    face = jaco2.points["face"]
    ts = np.arange(0.0, 4.0, 0.01)
    targets = [face + [0.0, 0.3 * math.sin(1.5 * t), 0.1 * math.sin(3.0 * t)] for t in ts]
    states = _run(c, targets, dt=0.01)
    after = [s for t, s in states if t > 1.0]
    assert max(s.residual for s in after) < HALF_DEG
    pans = np.array([s.head["head_pan"] for s in after])
    acc = np.diff(pans, 2) / 0.01**2
    assert np.abs(acc).max() < 20.0, "no jerky neck re-plans"
    assert np.ptp(pans) > math.radians(10), "the neck follows, not only the eyes"


def test_nan_target_keeps_the_last_target_and_is_flagged(jaco2):
    c = GazeController(jaco2)
    face = jaco2.points["face"]
    _run(c, [face] * 100)
    states = _run(c, [np.array([np.nan, 0.0, 1.0])] * 300 + [None] * 10, t0=100 * DT)
    for _, s in states:
        assert not s.target_valid
        assert np.all(np.isfinite(list(s.head.values()))) and math.isfinite(s.residual)
    assert states[-1][1].residual < HALF_DEG  # still converged on the last valid target
    with pytest.raises(ValueError, match="3D point"):
        c.update(1.0, [1.0, 2.0])


def test_time_going_backwards_holds_the_pose_then_continues_smoothly(jaco2):
    c = GazeController(jaco2)
    a, b = _pan_shift(jaco2, 30.0)
    _run(c, [a] * 100)
    s1 = c.update(0.3, b)
    back = c.update(0.1, b)
    assert back.head == s1.head
    same = c.update(0.1, b)
    assert same.head == s1.head
    later = c.update(0.11, b)
    dq = np.abs(np.array(list(later.head.values())) - np.array(list(s1.head.values())))
    assert np.all(dq <= jaco2.velocity_limits * 0.01 + 1e-12)
    nan_time = c.update(float("nan"), b)
    assert nan_time.head == later.head


def test_reset_puts_the_head_where_asked_and_rejects_unknown_joints(jaco2):
    c = GazeController(jaco2)
    c.reset({"head_pan": 0.4, "neck_tilt": 9.0})  # out of range: clamped
    s = c.update(0.0, None)
    assert s.head["head_pan"] == pytest.approx(0.4)
    assert s.head["neck_tilt"] == pytest.approx(jaco2.upper[1])
    assert s.residual == 0.0 and not s.target_valid
    with pytest.raises(ValueError, match="unknown head joints"):
        c.reset({"wrist": 0.0})
    with pytest.raises(ValueError, match="finite"):
        c.reset({"head_pan": float("nan")})


def test_sawyer_head_follows_the_arm_joint_that_carries_it(sawyer):
    """Sawyer's head sits on right_l0: turning right_j0 turns the head; the pan compensates."""
    c = GazeController(sawyer)
    face = sawyer.points["face"]
    _run(c, [face] * 500)
    s = None
    for k in range(500):
        s = c.update(1.0 + k * DT, face, arm={"right_j0": 0.3})
    assert s.head["head_pan"] == pytest.approx(-0.3, abs=1e-3)
    assert s.residual < HALF_DEG
    c.set_arm({"right_j0": 0.0})


def test_shift_config_rejects_eyes_slower_than_the_neck():
    with pytest.raises(ValueError, match="eyes lead"):
        GazeShiftConfig(eye_duration_s=0.4, neck_duration_s=0.3)


def test_non_numeric_time_is_a_clear_error(jaco2):
    c = GazeController(jaco2)
    with pytest.raises(ValueError, match="time must be a number"):
        c.update(None, jaco2.points["face"])


def test_a_trajectory_rests_exactly_on_its_goal_after_its_end_and_at_its_start_before():
    traj = MinJerkTrajectory(0.25, 1, [0.1, -0.4], [0.6, 0.2], [0.05, -0.3], (1.5, 0.0))
    assert traj.duration == 1.0 and traj.end_time == 1.25
    for t in (1.25, 2.0):
        pos, vel, acc = traj.evaluate(t)
        assert pos.tolist() == [0.6, 0.2] and not vel.any() and not acc.any()
    pos, vel, acc = traj.evaluate(0.0)
    assert pos.tolist() == [0.1, -0.4] and vel.tolist() == [0.05, -0.3]
    assert acc.tolist() == [1.5, 0.0]


def test_a_trajectory_refuses_boundary_conditions_of_other_lengths():
    with pytest.raises(ValueError, match="same length"):
        MinJerkTrajectory(0.0, 1.0, [0.1, -0.4], [0.6])
    with pytest.raises(ValueError, match="positive"):
        MinJerkTrajectory(0.0, 0.0, [0.1], [0.6])
