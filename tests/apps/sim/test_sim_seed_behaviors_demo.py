"""Issue 12 at the demo level: the seed's behaviors on one simulated ``robot-initiated`` handover
(the recording ``gazebot demo`` makes, without the video) give pairwise different target
timelines and shift when the seed's words say (6.3.2, 6.4.3).

Every behavior's own :class:`~gazebot.core.runtime.GazeLoop` sees the same frames and robot events
tick for tick; the gaze does not move the giver or the arm, so this is the handover each
``gazebot demo --behavior B --scene robot-initiated`` records. The phase detector, which costs
most of a tick, runs once and its answers are handed to every loop (it only reads frames).
"""

from __future__ import annotations

import itertools

import pytest
from shared_detector import Replay, SharedDetector

from gazebot.core.behaviors import seed_behaviors
from gazebot.core.types import EventKind

pytest.importorskip("mujoco")

#: The seed's gaze behaviors (chapter 6): the built-ins whose YAML says ``source: seed``.
SEED_BEHAVIORS = seed_behaviors()
SHIFT_TOL_S = 0.05  # the "within 50 ms"


class _AllBehaviors:
    """A ``record_handover`` loop that ticks one GazeLoop per behavior and commands the robot
    with the first; keeps every behavior's (t, target) per tick."""

    def __init__(self, robot, names, seed: int = 0) -> None:
        from gazebot.core.runtime import GazeLoop

        self.loops = {n: GazeLoop.from_config(robot=robot, behavior=n, seed=seed) for n in names}
        first, *rest = self.loops.values()
        shared = SharedDetector(first.engine.detector)
        first.engine.detector = shared
        for loop in rest:
            loop.engine.detector = Replay(shared)
        self.targets: dict[str, list[tuple[float, str]]] = {n: [] for n in names}

    def notify(self, events) -> None:
        for loop in self.loops.values():
            loop.notify(events)

    def tick(self, frame, *, t=None, joints=None):
        cmds = {n: loop.tick(frame, t=t, joints=joints) for n, loop in self.loops.items()}
        for name, cmd in cmds.items():
            assert cmd is not None, f"{name}: unsafe command at t={t:.3f}"
            self.targets[name].append((cmd.t, cmd.target))
        return next(iter(cmds.values()))


def _record(scene: str):
    """One handover of ``scene`` recorded with all seed behaviors; returns (targets by
    behavior, robot events, the giver's reach start, the reach-start time)."""
    from gazebot.apps.sim.record import record_handover
    from gazebot.apps.sim.robot import load_sim_robot

    loop = _AllBehaviors(load_sim_robot("sawyer").spec, SEED_BEHAVIORS)
    seen = {}
    rec = record_handover(
        robot="sawyer",
        behavior=SEED_BEHAVIORS[0],
        scene=scene,
        out_path=None,
        progress=False,
        loop=loop,
        on_tick=lambda sim, _tick: seen.setdefault("sim", sim),
    )
    assert rec.completed and rec.video is None
    giver_start = seen["sim"].giver.reach_started_at
    return loop.targets, rec.robot_events, giver_start, rec.ticks[-1].reach_start_time


@pytest.fixture(scope="module")
def handover():
    """The seed's 6.3 handover: the robot starts its reach, the giver responds."""
    return _record("robot-initiated")


def _first(events, kind) -> float:
    return next(e.t for e in events if e.kind is kind)


def _shift_times(targets: list[tuple[float, str]], to: str) -> list[float]:
    return [t for (_, a), (t, b) in itertools.pairwise(targets) if a != b and b == to]


def test_robot_initiated_scene_the_robot_reaches_before_the_giver(handover):
    _, events, giver_start, reach_start_time = handover
    robot_start = _first(events, EventKind.ROBOT_REACH_STARTED)
    assert giver_start is not None
    assert robot_start < giver_start
    assert reach_start_time == pytest.approx(giver_start - robot_start)  # seed 6.4, > 0


def test_no_two_seed_behaviors_give_the_same_target_timeline(handover):
    targets = handover[0]
    lengths = {len(v) for v in targets.values()}
    assert len(lengths) == 1 and lengths.pop() > 100
    for a, b in itertools.combinations(SEED_BEHAVIORS, 2):
        assert [k for _, k in targets[a]] != [k for _, k in targets[b]], (a, b)


@pytest.mark.parametrize("name", ["face", "hand"])
def test_face_and_hand_hold_their_target_on_every_tick(handover, name):
    assert {k for _, k in handover[0][name]} == {name}


def test_short_face_hand_is_on_the_hand_within_50_ms_of_the_first_reach_start(handover):
    targets, events, giver_start, _ = handover
    first_reach = min(_first(events, EventKind.ROBOT_REACH_STARTED), giver_start)
    timeline = targets["short-face-hand"]
    # The hand is kept through the transfer and the retreat; the face comes back once the
    # handover is done (the phase detector may see that before the recording ends).
    retreat = _first(events, EventKind.ROBOT_RETREAT_STARTED)
    assert all(k == "face" for t, k in timeline if t < first_reach - 1e-9)
    assert all(k == "hand" for t, k in timeline if first_reach + SHIFT_TOL_S <= t < retreat)


def test_long_face_hand_turns_to_the_hand_when_the_robot_reach_ends(handover):
    targets, events, _, _ = handover
    reach_end = _first(events, EventKind.ROBOT_REACH_ENDED)
    retreat = _first(events, EventKind.ROBOT_RETREAT_STARTED)
    timeline = targets["long-face-hand"]
    # "as soon as the robot's reach phase ended" (6.3.2): not before, and not much after (the
    # face comes back once the handover is done, which the detector may see before the end)
    assert all(k == "face" for t, k in timeline if t < reach_end - 1e-9)
    assert all(k == "hand" for t, k in timeline if reach_end + SHIFT_TOL_S <= t < retreat)


def _check_as_studied(targets, events) -> None:
    reach_end = _first(events, EventKind.ROBOT_REACH_ENDED)
    retreat = _first(events, EventKind.ROBOT_RETREAT_STARTED)
    fhf = targets["face-hand-face-as-studied"]
    assert _shift_times(fhf, "hand") == [pytest.approx(reach_end, abs=SHIFT_TOL_S)]
    assert _shift_times(fhf, "face") == [pytest.approx(retreat, abs=SHIFT_TOL_S)]
    hf = targets["hand-face-as-studied"]
    assert hf[0][1] == "hand"
    assert _shift_times(hf, "face") == [pytest.approx(retreat, abs=SHIFT_TOL_S)]


def test_as_studied_behaviors_shift_on_the_robots_reach_end_and_retreat(handover):
    _check_as_studied(*handover[:2])


def test_as_studied_behaviors_differ_when_the_robot_retreats_right_after_grasping():
    # Seed 6.4.3: "The robot retreated to its home position after grasping the object": the
    # grasp and the retreat start coincide, and Face-Hand-Face still shows the hand in between.
    targets, events, _, _ = _record("retreat-after-grasp")
    grasp = _first(events, EventKind.ROBOT_GRASPED)
    assert _first(events, EventKind.ROBOT_RETREAT_STARTED) == pytest.approx(grasp)
    for a, b in itertools.combinations(SEED_BEHAVIORS, 2):
        assert [k for _, k in targets[a]] != [k for _, k in targets[b]], (a, b)
    _check_as_studied(targets, events)
