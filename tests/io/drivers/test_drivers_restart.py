"""An engine restarted in the middle of a handover, or after one, resynchronises from the event
history and the joint state without inventing events (issue 21): the simulator in process,
the second engine on the same driver, as ``gazebot run`` restarted against ``gazebot sim``."""

from __future__ import annotations

import pytest

from gazebot.io.drivers.engine_node import EngineNode
from gazebot.io.drivers.sim_driver import SimRobotDriver


def restart_at(cut: float, then: float, seed: int = 3) -> tuple[list, list]:
    """Phase events ``(kind, source)`` of a first engine run until sim time ``cut`` and of a
    second one started then, run for ``then`` more simulated seconds."""
    from gazebot.apps.sim import HandoverSimulation
    from gazebot.core.engine import GazeEngine
    from gazebot.core.runtime import GazeLoop

    def engine_node(driver: SimRobotDriver) -> EngineNode:
        loop = GazeLoop(GazeEngine.from_config("sawyer", "face-hand-face", seed=seed))
        return EngineNode(loop, driver)

    with HandoverSimulation("sawyer", "default", seed=seed) as sim:
        driver = SimRobotDriver(sim)
        first = engine_node(driver)
        first.start()
        while sim.t < cut:
            first.tick()
        n = len(driver.events)
        driver.node = "engine2"  # the restarted engine: a new node on the same robot
        second = engine_node(driver)
        assert second.start() > 0  # it found the handover in the history
        while sim.t < cut + then:
            second.tick()

    def phases(msgs):
        return [(m.kind, m.info.get("source")) for m in msgs if m.category == "phase"]

    return phases(driver.events[:n]), phases(driver.events[n:])


def test_engine_restarted_mid_reach_neither_aborts_nor_starts_a_new_handover():
    before, after = restart_at(2.5, 3.0)
    assert [k for k, _ in before] == ["reach_started"]
    # the reach goes on: the robot grasps, the giver retreats, done; nothing else
    assert [k for k, _ in after] == ["transfer_started", "retreat_started", "handover_done"]
    assert ("handover_done", "aborted") not in after


def test_engine_restarted_after_a_finished_handover_does_not_re_emit_its_phases():
    before, after = restart_at(5.0, 2.0)
    assert [k for k, _ in before] == [
        "reach_started", "transfer_started", "retreat_started", "handover_done"]
    # the robot still holds the object (gripper closed, load on the robot): no new handover
    assert after == []


@pytest.mark.parametrize("cut", [1.5, 3.6])
def test_engine_restarted_at_other_points_emits_only_the_phases_still_to_come(cut):
    before, after = restart_at(cut, 6.0 - cut)
    all_phases = ["reach_started", "transfer_started", "retreat_started", "handover_done"]
    seen = [k for k, _ in before]
    assert [k for k, _ in after] == all_phases[len(seen):]
