"""The ``panda`` robot of the handover scene (the GPS learner's arm on a pedestal with a pan-tilt
display head): its MJCF is generated from the learner, its gaze site follows the frame
convention, the look-at IK points it, and its torque arm reaches position goals by joint
impedance within Franka's torque bounds (the joint-space handover completes)."""

from __future__ import annotations

import mujoco
import numpy as np

from gazebot.apps.gps import panda
from gazebot.apps.gps.config import load_gps_config
from gazebot.apps.gps.handover_robot import ASSET, handover_robot_mjcf
from gazebot.apps.sim.arm_controller import ControllerState
from gazebot.apps.sim.simulation import HandoverSimulation
from gazebot.core.kinematics import RobotModel, solve_ik


def test_the_panda_asset_is_the_gps_learner_as_generated():
    assert ASSET.read_text(encoding="utf-8") == handover_robot_mjcf(load_gps_config().scene), (
        "stale: regenerate it with python -m gazebot.apps.gps.handover_robot"
    )


def test_the_arm_is_the_learners_torque_arm_on_its_pedestal():
    m = mujoco.MjModel.from_xml_path(str(ASSET))
    for i, tau in enumerate(panda.TAU_MAX_NM):
        act = m.actuator(f"tau{i + 1}")
        assert int(m.actuator_biastype[act.id]) == int(mujoco.mjtBias.mjBIAS_NONE)
        np.testing.assert_allclose(m.actuator_ctrlrange[act.id], [-tau, tau])
    np.testing.assert_allclose(m.dof_damping[:7], load_gps_config().scene.joint_damping)
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    np.testing.assert_allclose(d.xpos[m.body("link0").id], [0.0, 0.0, 0.7])


def test_the_gaze_site_looks_forward_with_the_display_up_and_ik_points_it():
    m = mujoco.MjModel.from_xml_path(str(ASSET))
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    rot = d.site("gaze").xmat.reshape(3, 3)
    np.testing.assert_allclose(rot[:, 0], [1, 0, 0], atol=1e-9)  # line of sight +x
    np.testing.assert_allclose(rot[:, 2], [0, 0, 1], atol=1e-9)  # display up
    face = [1.1, 0.0, 1.6]  # to the right of and above the head at (0, 0.38, 1.23)
    sol = solve_ik(RobotModel.load("panda"), face)
    assert sol.valid and sol.joints["head_pan"] < 0 and sol.joints["head_tilt"] < 0  # right, up
    assert np.degrees(sol.residual) < 0.01


def test_the_joint_space_handover_completes_on_the_torque_arm_within_its_bounds():
    sim = HandoverSimulation("panda", "default")
    torques, states = [], set()
    while sim.t < 12.0 and not sim.done:
        sim.step(0.02)
        torques.append(sim.data.ctrl[sim._arm_act].copy())
        states.add(sim.controller.state)
    assert sim.done and ControllerState.HOLDING in states
    torques = np.array(torques)
    assert np.all(np.isfinite(torques))
    assert np.all(np.abs(torques) <= np.array(panda.TAU_MAX_NM) + 1e-9)
    # Back home at the end: the impedance tracked the retreat's goal.
    np.testing.assert_allclose(sim.data.qpos[sim._arm_qpos], sim.home, atol=0.02)


def test_the_impedance_holds_the_measured_posture_for_a_non_finite_goal():
    from gazebot.apps.sim.torque_arm import JointImpedance

    imp = JointImpedance(np.full(7, 100.0), np.full(7, 10.0), np.array(panda.TAU_MAX_NM))
    q, dq = np.linspace(-1, 1, 7), np.zeros(7)
    goal = q + 0.5
    goal[2] = np.nan
    tau = imp.torque(goal, q, dq)
    assert np.all(np.isfinite(tau)) and tau[2] == 0.0
    assert np.all(np.abs(tau) <= np.array(panda.TAU_MAX_NM))  # 50 N m asked, 12 on the wrist
    assert tau[6] == panda.TAU_MAX_NM[6]


def test_the_handover_robots_home_is_the_pose_the_policy_was_trained_from():
    """``configs/robots/panda.yaml``'s ``arm_home_deg`` and ``configs/gps.yaml``'s
    ``scene.home_deg`` are one posture: the learned reach starts where it was trained to."""
    from gazebot.apps.sim.robot import load_sim_robot

    home = load_sim_robot("panda").home
    np.testing.assert_allclose(home, np.deg2rad(load_gps_config().scene.home_deg), atol=1e-12)
