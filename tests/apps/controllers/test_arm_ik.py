"""Differential IK tracking of an end-effector velocity within joint limits and speeds."""

from __future__ import annotations

import numpy as np
import pytest


def _ik(robot="jaco2", speed=2.0):  # rad/s
    from gazebot.apps.controllers.arm_ik import ArmIK
    from gazebot.apps.sim.robot import load_sim_robot

    r = load_sim_robot(robot)
    return ArmIK(r.mjcf, r.arm_joints, r.gripper_site, speed), r


@pytest.mark.parametrize("robot", ["jaco2", "sawyer"])
def test_end_effector_follows_the_commanded_velocity_holding_its_orientation(robot):
    ik, r = _ik(robot)
    q = r.home.copy()
    start = ik.pose(q)
    v = np.array([0.1, 0.05, -0.05])
    dt, x_set = 1 / 120, start.translation.copy()
    for _ in range(120):  # 1 s
        x_set = x_set + v * dt
        q = ik.step(q, v, x_set, start.rotation, dt)
    end = ik.pose(q)
    assert end.translation - start.translation == pytest.approx(v, abs=0.01)
    assert np.linalg.norm(end.rotation - start.rotation) < 0.05


def test_joint_speed_and_range_limits_hold_for_an_impossible_request():
    speed = np.deg2rad(30.0)
    ik, r = _ik("jaco2", speed)
    q = r.home.copy()
    rot = ik.pose(q).rotation
    for _ in range(200):
        q_next = ik.step(q, np.array([5.0, 0, 0]), np.array([10.0, 0, 0]), rot, 0.01)
        assert np.all(np.isfinite(q_next))
        assert np.all(np.abs(q_next - q) <= speed * 0.01 + 1e-12)
        assert np.all(q_next >= ik.lower - 1e-12) and np.all(q_next <= ik.upper + 1e-12)
        q = q_next


def test_unknown_site_names_the_field():
    from gazebot.apps.controllers.arm_ik import ArmIK
    from gazebot.apps.sim.robot import load_sim_robot
    from gazebot.core.config import ConfigError

    r = load_sim_robot("jaco2")
    with pytest.raises(ConfigError, match="gripper_site"):
        ArmIK(r.mjcf, r.arm_joints, "no_such_site", 1.0)
