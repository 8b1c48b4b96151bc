"""The robot's handover controller reaches once the giver starts, grasps when the object is close,
retreats home after the giver lets go, and reports each step as a robot event."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.sim.arm_controller import ControllerState, HandoverController, Sensed
from gazebot.apps.sim.giver import GiverState
from gazebot.apps.sim.scene_config import ControllerConfig, TrackingNoiseConfig
from gazebot.apps.sim.simulation import HandoverSimulation, nearest_equivalent
from gazebot.core.types import EventKind

ORDER = [
    EventKind.ROBOT_REACH_STARTED,
    EventKind.ROBOT_REACH_ENDED,
    EventKind.ROBOT_GRASPED,
    EventKind.ROBOT_RETREAT_STARTED,
    EventKind.ROBOT_RETREAT_ENDED,
]


def _run(sim: HandoverSimulation, until: float = 15.0, dt: float = 1 / 120):
    events, frames = [], []
    while not sim.done and sim.t < until:
        sim.step(dt)
        frames.append(sim.tracking())
        for e in sim.robot_events():
            events.append((e, sim.giver.state, sim.data.site(sim.robot.gripper_site).xpos.copy()))
    return events, frames


@pytest.fixture(scope="module")
def sawyer_run():
    sim = HandoverSimulation("sawyer", "default", seed=1)
    events, frames = _run(sim)
    return sim, events, frames


def test_robot_reaches_grasps_and_retreats_in_order(sawyer_run):
    sim, events, _ = sawyer_run
    assert sim.done
    assert [e.kind for e, _, _ in events] == ORDER
    times = [e.t for e, _, _ in events]
    assert times == sorted(times)
    started, ended = events[0][0], events[1][0]
    assert started.t >= sim.giver.plan.start_t  # only once the giver has started
    assert ended.t - started.t == pytest.approx(started.info["planned_duration"], abs=0.02)
    assert events[3][0].info["planned_duration"] > 0
    # At the end of the reach the gripper is at the handover location.
    np.testing.assert_allclose(events[1][2], sim.layout.handover_location, atol=0.03)


def test_grasp_waits_for_the_object_and_retreat_for_the_release(sawyer_run):
    sim, events, _ = sawyer_run
    grasped = events[2]
    assert grasped[1] in (GiverState.OFFER, GiverState.SHARE)
    retreat = events[3]
    assert sim.giver.released_at is not None and retreat[0].t >= sim.giver.released_at
    assert retreat[0].t - grasped[0].t >= sim.giver.plan.transfer_s - 0.01
    # The robot ends at home holding the object.
    arm = np.array([sim.joint_state()[j] for j in sim.robot.arm_joints])
    np.testing.assert_allclose(arm, sim.home, atol=0.03)
    obj = sim.data.mocap_pos[sim.scene.object_mocap]
    gripper = sim.data.site(sim.robot.gripper_site).xpos
    assert np.linalg.norm(obj - gripper) < 0.05


def test_tracking_reports_points_and_gripper_evidence(sawyer_run):
    sim, events, frames = sawyer_run
    t_grasp = events[2][0].t
    before = [f for f in frames if f.t < t_grasp - 1e-6]
    after = [f for f in frames if f.t >= t_grasp]
    assert not any(f.gripper_closed for f in before) and all(f.gripper_closed for f in after)
    assert [f.load_share for f in (before[-1], after[0], frames[-1])] == [0.0, 0.5, 1.0]
    f = frames[-1]
    np.testing.assert_allclose(f.receiver_hand, sim.data.site(sim.robot.gripper_site).xpos)
    np.testing.assert_allclose(f.giver_face, sim.scene.giver.face_point)


def test_controller_does_not_reach_before_the_giver_moves_nor_grasp_a_far_object():
    home, goal = np.zeros(3), np.array([0.5, -0.5, 1.0])
    ctl = HandoverController(home, goal, ControllerConfig())
    far = Sensed(giver_hand=np.array([1.0, 0.0, 1.0]), object_gap=0.5, hand_object_gap=0.0)
    for t in np.arange(0.0, 1.0, 0.01):
        ctl.update(t, home, far)
    assert ctl.state is ControllerState.WAITING and ctl.pop_events() == []
    moved = Sensed(giver_hand=np.array([0.9, 0.0, 1.0]), object_gap=0.5, hand_object_gap=0.0)
    ctl.update(1.0, home, moved)
    (event,) = ctl.pop_events()
    assert event.kind is EventKind.ROBOT_REACH_STARTED
    # Peak joint speed at the configured limit: duration = 1.875 * 1.0 rad / limit.
    limit = np.deg2rad(ControllerConfig().max_joint_speed_deg)
    assert event.info["planned_duration"] == pytest.approx(max(1.6, 1.875 / limit))
    for t in np.arange(1.0, 5.0, 0.01):
        cmd = ctl.update(t, home, moved)
    assert ctl.state is ControllerState.AT_HANDOVER and cmd.gripper == 0.0
    np.testing.assert_allclose(cmd.arm, goal)


def test_same_seed_same_handover_other_seed_other_timing():
    a, b, c = (HandoverSimulation("sawyer", "default", seed=s) for s in (4, 4, 5))
    for sim in (a, b, c):
        for _ in range(240):
            sim.step(1 / 120)
    np.testing.assert_array_equal(a.tracking().giver_hand, b.tracking().giver_hand)
    assert a.giver.plan == b.giver.plan != c.giver.plan


def test_tracking_noise_and_dropouts_are_optional():
    noisy = HandoverSimulation(
        "sawyer",
        "default",
        seed=0,
        tracking_noise=TrackingNoiseConfig(noise_m=0.01, dropout_rate=0.3),
    )
    frames = [noisy.tracking() for _ in range(200)]
    hands = np.array([f.giver_hand for f in frames])
    lost = np.isnan(hands).all(axis=1)
    assert 0.15 < lost.mean() < 0.45
    assert 0.005 < np.std(hands[~lost][:, 0]) < 0.02


def test_head_commands_are_clipped_and_bad_ones_rejected():
    sim = HandoverSimulation("sawyer", "default", seed=0)
    sim.apply_head({"head_pan": 100.0})
    act = sim.model.actuator("head_pan")
    assert sim.data.ctrl[act.id] == pytest.approx(act.ctrlrange[1])
    with pytest.raises(ValueError, match="unknown head joint"):
        sim.apply_head({"right_j0": 0.0})
    with pytest.raises(ValueError, match="finite"):
        sim.apply_head({"head_pan": float("nan")})
    with pytest.raises(ValueError, match="finite"):
        sim.apply_eyes(float("inf"), 0.0)
    with pytest.raises(ValueError, match="positive"):
        sim.step(0.0)
    sim.apply_head({"head_pan": -0.3})
    for _ in range(120):
        sim.step(1 / 120)
    assert sim.joint_state()["head_pan"] == pytest.approx(-0.3, abs=0.02)


def test_jaco2_handover_completes_without_full_turns():
    sim = HandoverSimulation("jaco2", "default", seed=0)
    assert np.all(np.abs(sim.home - sim.robot.handover) <= np.pi + 1e-9)
    events, _ = _run(sim)
    assert sim.done and [e.kind for e, _, _ in events] == ORDER


def test_nearest_equivalent_only_shifts_joints_that_turn_more_than_once():
    ranges = np.array([[-2 * np.pi, 2 * np.pi], [-3.0, 3.0]])
    q = nearest_equivalent(np.array([np.radians(282.8), 2.9]), np.array([0.6, -2.9]), ranges)
    np.testing.assert_allclose(q, [np.radians(282.8 - 360), 2.9])


def test_arm_commands_take_the_arm_over_from_the_controller():
    sim = HandoverSimulation("sawyer", "default", seed=0)
    goal = dict(zip(sim.robot.arm_joints, sim.home, strict=True))
    goal["right_j0"] = sim.home[0] + 0.3
    sim.apply_arm(goal)
    for _ in range(int(3.5 * 120)):  # past the robot's reach start
        sim.step(1 / 120)
    assert sim.controller.state is not ControllerState.WAITING  # the controller still runs...
    # ...but the arm holds the commanded pose.
    assert sim.joint_state()["right_j0"] == pytest.approx(goal["right_j0"], abs=0.02)
    with pytest.raises(ValueError, match="unknown arm joint"):
        sim.apply_arm({"head_pan": 0.0})
