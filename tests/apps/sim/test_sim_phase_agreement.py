"""Issue 19's done-when: over every seed behavior x scene x robot-first/giver-first, no tick's
target comes from a phase's rule while the command reports another phase.

Each (scene, initiator) is one simulated handover; every seed behavior's own
:class:`~gazebot.core.runtime.GazeLoop` sees the same frames and robot events tick for tick (the
gaze moves neither the giver nor the arm). The behavior records the rule that picked its gaze state
when it picked it (:attr:`~gazebot.core.behaviors.BehaviorMachine.origin`: a segment of a phase, the
``before``/``after`` target, with that rule's phase; a gaze carried unchanged into a later phase
says so). Every tick with tracking ok must agree with it
(:meth:`~gazebot.core.behaviors.GazeOrigin.disagreement`): the target is the one the rule picked, a
phase's own rule is the reported phase's, a carried gaze was carried into the reported phase.
That the check catches a stale origin is pinned in ``tests/core/behaviors/test_behavior_origin.py``.
"""

from __future__ import annotations

import pytest
from shared_detector import Replay, SharedDetector

from gazebot.apps.sim.scene_config import Initiator, load_scene, scene_names
from gazebot.core.behaviors import GazeOrigin, seed_behaviors
from gazebot.core.types import Phase

pytest.importorskip("mujoco")

#: The seed's gaze behaviors (chapter 6): the built-ins whose YAML says ``source: seed``.
SEED_BEHAVIORS = seed_behaviors()


class _AllBehaviors:
    """A ``record_handover`` loop ticking one GazeLoop per seed behavior; records, per tick and
    behavior, (t, reported phase, target, the behavior's gaze origin, its tracking state, and
    why they disagree, ``None`` if they agree)."""

    def __init__(self, robot) -> None:
        from gazebot.core.runtime import GazeLoop

        self.loops = {n: GazeLoop.from_config(robot=robot, behavior=n) for n in SEED_BEHAVIORS}
        first, *rest = self.loops.values()
        shared = SharedDetector(first.engine.detector)
        first.engine.detector = shared
        for loop in rest:
            loop.engine.detector = Replay(shared)
        self.ticks: dict[str, list[tuple[float, Phase, str, GazeOrigin, str, str | None]]] = {
            n: [] for n in SEED_BEHAVIORS
        }

    def notify(self, events) -> None:
        for loop in self.loops.values():
            loop.notify(events)

    def tick(self, frame, *, t=None, joints=None):
        out = None
        for name, loop in self.loops.items():
            cmd = loop.tick(frame, t=t, joints=joints)
            assert cmd is not None, f"{name}: unsafe command"
            behavior = loop.engine.behavior
            why = behavior.origin_disagreement(cmd.phase, cmd.target)
            self.ticks[name].append((cmd.t, cmd.phase, cmd.target, behavior.origin,
                                     behavior.tracking, why))
            out = out or cmd
        return out


# Scenes that replay a recorded giver have no initiator to choose: they are not cases here.
CASES = [("sawyer", scene, initiator) for scene in scene_names()
         if load_scene(scene).giver_motion is None
         for initiator in (Initiator.ROBOT, Initiator.GIVER)]
# Jaco-2 (a head that pans and tilts, other timings): one scene, both initiators.
CASES += [("jaco2", "default", Initiator.ROBOT), ("jaco2", "default", Initiator.GIVER)]


@pytest.mark.slow
@pytest.mark.parametrize(("robot", "scene", "initiator"), CASES)
def test_no_target_comes_from_another_phase_than_the_one_reported(robot, scene, initiator):
    from gazebot.apps.sim.record import record_handover
    from gazebot.apps.sim.robot import load_sim_robot

    config = load_scene(scene)
    config = config.model_copy(update={"initiator": initiator})
    loop = _AllBehaviors(load_sim_robot(robot).spec)
    rec = record_handover(
        robot=robot, behavior=SEED_BEHAVIORS[0], scene=config, out_path=None,
        progress=False, loop=loop,
    )
    assert rec.completed
    for name, ticks in loop.ticks.items():
        phases = {tick[1] for tick in ticks}
        assert Phase.REACH in phases, f"{name}: the handover's reach was never reported"
        checked = [tick for tick in ticks if tick[4] == "ok"]
        assert len(checked) > len(ticks) // 2, f"{name}: tracking lost most of the time"
        rules = {(tick[3].phase, tick[3].rule) for tick in checked}
        assert any(rule.startswith("segment") for _, rule in rules) or name in ("face", "hand"), (
            f"{name}: no segment ever picked the gaze ({sorted(rules)})"
        )
        for t, _, _, origin, _, why in checked:
            assert why is None, f"{name} at t={t:.3f}: {why} ({origin})"
