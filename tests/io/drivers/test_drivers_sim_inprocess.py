"""The in-process simulated driver: engine node and simulation in lockstep, no bus."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.io.drivers.engine_node import EngineNode
from gazebot.io.drivers.sim_driver import SimRobotDriver
from gazebot.io.ros2.values import ArmCommand, JointGoal


def run_handover(seed: int):
    from gazebot.apps.sim import HandoverSimulation
    from gazebot.core.engine import GazeEngine
    from gazebot.core.runtime import GazeLoop

    with HandoverSimulation("sawyer", "default", seed=seed) as sim:
        driver = SimRobotDriver(sim)
        sent: list[JointGoal] = []
        send = driver.send_head
        driver.send_head = lambda msg: (sent.append(msg), send(msg))[1]
        node = EngineNode(GazeLoop(GazeEngine.from_config("sawyer", "face-hand-face", seed=seed)),
                          driver)
        node.start()
        # until both the simulation and the engine (from the tracking) have seen the end
        while sim.t < 20 and not (
            sim.done and any(m.kind == "handover_done" for m in driver.events)
        ):
            node.tick()
        pan = float(sim.data.qpos[sim.model.joint("head_pan").qposadr[0]])
        return sim.done, sent, driver, pan


def test_in_process_handover_is_deterministic_and_turns_the_head():
    done, sent, driver, pan = run_handover(seed=3)
    assert done and driver.head_commands == len(sent) > 100
    phases = [m.kind for m in driver.events if m.category == "phase"]
    assert phases == ["reach_started", "transfer_started", "retreat_started", "handover_done"]
    assert any(m.source == "sim" and m.kind == "robot_grasped" for m in driver.events)
    assert pan == pytest.approx(sent[-1].positions["head_pan"], abs=0.05)
    _, sent2, _, _ = run_handover(seed=3)
    assert [m.positions for m in sent2] == [m.positions for m in sent]


def test_arm_commands_in_process_apply_named_poses_and_reject_the_impossible():
    from gazebot.apps.sim import HandoverSimulation

    with HandoverSimulation("jaco2", "default", seed=0) as sim:
        driver = SimRobotDriver(sim)
        driver.send_arm(ArmCommand(pose="handover"))
        acts = [sim.model.actuator(j).id for j in sim.robot.arm_joints]
        lo, hi = sim.model.jnt_range[[sim.model.joint(j).id for j in sim.robot.arm_joints]].T
        limited = sim.model.jnt_limited[[sim.model.joint(j).id for j in sim.robot.arm_joints]]
        goal = np.where(limited, np.clip(sim.robot.handover, lo, hi), sim.robot.handover)
        np.testing.assert_allclose(sim.data.ctrl[acts], goal, atol=1e-9)
        driver.send_arm(ArmCommand(positions={"bogus": 0.0}))
        assert driver.rejected == {"arm": 1}
        assert np.allclose(sim.data.ctrl[acts], goal)
