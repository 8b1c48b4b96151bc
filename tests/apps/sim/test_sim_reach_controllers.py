"""The seed's controllers as the simulated robot's reach, and the robot's part in each study
(issue 12.2): robot-initiated handovers, retreat after grasping, the reach-start time."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.sim.scene_config import SceneConfig, load_scene
from gazebot.core.types import EventKind

pytest.importorskip("mujoco")


def _scene(name: str = "default", **controller) -> SceneConfig:
    data = load_scene(name).model_dump()
    data["controller"].update(controller)
    return SceneConfig.model_validate(data)


def _run(scene, robot="jaco2", until=9.0):
    from gazebot.apps.sim.simulation import HandoverSimulation

    sim = HandoverSimulation(robot=robot, scene=scene, seed=0)
    events, track = [], []
    gripper = sim.data.site(sim.robot.gripper_site)
    while sim.t < until and not sim.done:
        sim.step(1 / 30)
        events += sim.robot_events()
        obj = sim.data.mocap_pos[sim.scene.object_mocap]
        track.append((sim.t, gripper.xpos.copy(), float(np.linalg.norm(obj - gripper.xpos))))
    return sim, events, track


def _first(events, kind):
    return next((e.t for e in events if e.kind is kind), None)


def test_mce_reach_is_still_until_the_stall_time_and_there_by_the_reach_time():
    sim, events, track = _run(_scene(reach_controller="mce", reach_time_s=2.5, stall_time_s=0.5))
    t0 = sim.controller.handover_start
    assert t0 is not None and sim.done
    start = next(p for t, p, _ in track if t >= t0 - 1e-9)
    still = [np.linalg.norm(p - start) for t, p, _ in track if t0 <= t <= t0 + 0.5]
    assert max(still) < 0.005  # "Don't move until"
    assert _first(events, EventKind.ROBOT_REACH_STARTED) >= t0 + 0.5 - 1e-9
    assert _first(events, EventKind.ROBOT_REACH_ENDED) <= t0 + 2.5  # "Reach before"
    assert EventKind.ROBOT_REACH_INFEASIBLE not in {e.kind for e in events}


@pytest.mark.parametrize("controller", ["mce", "stl"])
def test_infeasible_reach_time_is_reported_once(controller):
    sim, events, _ = _run(_scene(reach_controller=controller, reach_time_s=0.2), until=4.0)
    bad = [e for e in events if e.kind is EventKind.ROBOT_REACH_INFEASIBLE]
    assert len(bad) == 1
    assert bad[0].info["reach_time"] == pytest.approx(0.2)


def test_robot_initiated_scene_robot_reaches_first():
    sim, events, _ = _run("robot-initiated")
    robot = _first(events, EventKind.ROBOT_REACH_STARTED)
    assert sim.done
    assert robot == pytest.approx(1.0, abs=0.05)
    assert sim.giver.reach_started_at > robot  # the giver responds after its reaction time
    assert sim.reach_start_time == pytest.approx(0.3, abs=0.05)


def test_retreat_after_grasp_starts_with_the_grasp():
    sim, events, _ = _run("retreat-after-grasp")
    assert sim.done
    assert _first(events, EventKind.ROBOT_RETREAT_STARTED) == pytest.approx(
        _first(events, EventKind.ROBOT_GRASPED)
    )
    # the default scene waits for the giver to let go
    _, ev2, _ = _run("default")
    assert _first(ev2, EventKind.ROBOT_RETREAT_STARTED) > _first(ev2, EventKind.ROBOT_GRASPED)


def test_arm_commands_stay_finite_and_within_limits_under_a_cartesian_reach():
    from gazebot.apps.sim.simulation import HandoverSimulation

    sim = HandoverSimulation(robot="sawyer", scene=_scene(reach_controller="pv"), seed=2)
    while sim.t < 6.0 and not sim.done:
        sim.step(1 / 30)
        ctrl = sim.data.ctrl[sim._arm_act]
        assert np.all(np.isfinite(ctrl))
        assert np.all(ctrl >= sim._arm_lo - 1e-9) and np.all(ctrl <= sim._arm_hi + 1e-9)
    assert sim.done


def test_feedback_banner_marks_the_frame():
    from gazebot.apps.sim.simulation import _feedback_banner

    frame = np.zeros((120, 320, 3), np.uint8)
    out = _feedback_banner(frame, "I will not be able to reach in the specified time limit")
    assert out.shape == frame.shape and out[:5].any() and not out[-20:].any()


@pytest.mark.parametrize("controller", ["joint", "mce"])
def test_robot_to_human_scene_the_person_takes_the_object(controller):
    from gazebot.apps.sim.receiver import ReceiverState
    from gazebot.apps.sim.simulation import HandoverSimulation

    sim = HandoverSimulation(
        robot="jaco2", scene=_scene("robot-to-human", reach_controller=controller), seed=0
    )
    gripper = sim.data.site(sim.robot.gripper_site)
    obj = sim.data.mocap_pos[sim.scene.object_mocap]
    assert np.linalg.norm(obj - gripper.xpos) < 1e-6  # starts in the robot's gripper
    shares, events = [], []
    while sim.t < 9.0 and not sim.done:
        sim.step(1 / 30)
        events += sim.robot_events()
        shares.append(sim.tracking().load_share)
    assert sim.done and sim.giver.state is ReceiverState.DONE
    kinds = [e.kind for e in events]
    assert kinds.index(EventKind.ROBOT_RELEASED) < kinds.index(EventKind.ROBOT_RETREAT_STARTED)
    # the taker's (the person's) share: nothing, then with the robot, then alone
    first_half = shares.index(0.5)
    assert set(shares[:first_half]) == {0.0} and shares[-1] == 1.0
    # the object ends in the person's hand, back at rest
    assert np.linalg.norm(obj - (sim.giver.hand + sim.layout.object_offset)) < 0.06
    assert np.linalg.norm(sim.giver.hand - sim.layout.rest_hand) < 1e-6
    assert sim.reach_start_time == pytest.approx(0.3, abs=0.05)  # robot first, then the person


def _monitored(scene, force_sensor: bool = True):
    from gazebot.apps.sim.simulation import HandoverSimulation
    from gazebot.apps.sim.stl_monitor import HandoverMonitor, robot_timing

    sim = HandoverSimulation(robot="jaco2", scene=scene, seed=0)
    cfg = robot_timing(sim)
    cfg = cfg.model_copy(update={"stl": cfg.stl.model_copy(update={"force_sensor": force_sensor})})
    monitor = HandoverMonitor(config=cfg)
    while sim.t < 8.0 and not sim.done:
        sim.step(1 / 30)
        monitor.sample(sim)
    return monitor.robustness()


def test_stl_monitor_over_a_run_positive_when_met_negative_when_missed():
    met = _monitored(_scene(reach_controller="mce", reach_time_s=2.5, stall_time_s=0.5))
    assert met["reach"] > 0 and met["transfer"] > 0 and met["retreat"] > 0
    # Table 4.1 without a force sensor: object states from distances and grips, same verdicts
    met = _monitored(
        _scene(reach_controller="mce", reach_time_s=2.5, stall_time_s=0.5), force_sensor=False
    )
    assert met["reach"] > 0 and met["transfer"] > 0 and met["retreat"] > 0
    missed = _monitored(_scene(reach_controller="mce", reach_time_s=0.3))
    assert missed["reach"] < 0
    # a retreat deadline shorter than the retreat move is missed too
    late = _scene(reach_controller="mce", reach_time_s=2.5, retreat_min_duration_s=3.0)
    assert _monitored(late)["retreat"] < 0
