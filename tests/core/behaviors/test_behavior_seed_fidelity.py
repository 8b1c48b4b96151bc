"""The seed's behaviors run through the real GazeEngine on one handover (seed 6.3.2, 6.4.2, 6.4.3):
each is its own behavior (no two give the same target timeline) and shifts when the seed says."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import pytest

from gazebot.core.behaviors import seed_behaviors
from gazebot.core.engine import GazeEngine
from gazebot.core.types import Event, EventKind, TrackingFrame

#: The seed's gaze behaviors (chapter 6): the built-ins whose YAML says ``source: seed``.
SEED_BEHAVIORS = seed_behaviors()
RATE = 120.0
FACE = np.array([1.15, 0.0, 1.62])
HAND_REST = np.array([1.0, -0.22, 0.92])
HAND_OFFER = np.array([0.72, 0.0, 1.02])
GRIP_HOME = np.array([0.45, 0.16, 1.04])
GRIP_OFFER = np.array([0.64, 0.0, 1.02])


def _mj(s: float) -> float:
    s = min(max(s, 0.0), 1.0)
    return s**3 * (10.0 - 15.0 * s + 6.0 * s * s)


def _move(t: float, t0: float, dur: float, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a + _mj((t - t0) / dur) * (b - a)


@dataclass(frozen=True)
class Handover:
    """Times (s) of one handover; the robot retreats after the giver's release (seed 6.3)."""

    robot_reach: float
    giver_reach: float
    robot_reach_s: float = 1.2
    giver_reach_s: float = 0.9
    hold_s: float = 0.7
    retreat_s: float = 1.1
    end: float = 6.0

    @property
    def robot_reach_end(self) -> float:
        return self.robot_reach + self.robot_reach_s

    @property
    def contact(self) -> float:
        return max(self.robot_reach_end, self.giver_reach + self.giver_reach_s)

    @property
    def grasp(self) -> float:
        return self.contact + 0.2

    @property
    def release(self) -> float:
        return self.contact + self.hold_s

    @property
    def robot_retreat(self) -> float:
        return self.release + 0.2

    def robot_events(self) -> list[Event]:
        def ev(kind: EventKind, t: float, **info: float) -> Event:
            return Event(kind, t, t, info)

        return [
            ev(
                EventKind.ROBOT_REACH_STARTED, self.robot_reach, planned_duration=self.robot_reach_s
            ),
            ev(EventKind.ROBOT_REACH_ENDED, self.robot_reach_end),
            ev(EventKind.ROBOT_GRASPED, self.grasp),
            ev(EventKind.ROBOT_RETREAT_STARTED, self.robot_retreat, planned_duration=1.2),
            ev(EventKind.ROBOT_RETREAT_ENDED, self.robot_retreat + 1.2),
        ]

    def frame(self, t: float) -> TrackingFrame:
        if t < self.release:
            hand = _move(t, self.giver_reach, self.giver_reach_s, HAND_REST, HAND_OFFER)
        else:
            hand = _move(t, self.release, self.retreat_s, HAND_OFFER, HAND_REST)
        if t < self.robot_retreat:
            grip = _move(t, self.robot_reach, self.robot_reach_s, GRIP_HOME, GRIP_OFFER)
        else:
            grip = _move(t, self.robot_retreat, 1.2, GRIP_OFFER, GRIP_HOME)
        closed = self.grasp <= t < self.robot_retreat + 1.2
        return TrackingFrame.make(t, hand, grip, FACE, gripper_closed=closed)


ROBOT_FIRST = Handover(
    robot_reach=1.0, giver_reach=1.45
)  # seed 6.3: the robot starts, the giver responds
GIVER_FIRST = Handover(
    robot_reach=1.15, giver_reach=1.0
)  # seed 6.4.3: the robot reacts to the giver


def run(name: str, handover: Handover) -> tuple[np.ndarray, list[str], list[dict[str, float]]]:
    """Tick times, target kinds and commands of behavior ``name`` on ``handover``."""
    engine = GazeEngine.from_config(robot="sawyer", behavior=name)
    pending = handover.robot_events()
    times, targets, eyes = [], [], []
    for k in range(int(handover.end * RATE)):
        t = k / RATE
        while pending and pending[0].t <= t:
            engine.notify(pending.pop(0))
        cmd = engine.step(handover.frame(t))
        times.append(t)
        targets.append(cmd.target)
        eyes.append({"yaw": cmd.eye_yaw, "pitch": cmd.eye_pitch, **cmd.head})
    return np.array(times), targets, eyes


@pytest.fixture(
    scope="module", params=[ROBOT_FIRST, GIVER_FIRST], ids=["robot-first", "giver-first"]
)
def timelines(request) -> tuple[Handover, dict[str, tuple[np.ndarray, list[str]]]]:
    handover = request.param
    return handover, {name: run(name, handover)[:2] for name in SEED_BEHAVIORS}


def test_no_two_seed_behaviors_give_the_same_target_timeline(timelines):
    _, runs = timelines
    same = [
        (a, b) for a, b in itertools.combinations(SEED_BEHAVIORS, 2) if runs[a][1] == runs[b][1]
    ]
    assert same == []


@pytest.mark.parametrize("name", ["face", "hand"])
def test_face_and_hand_hold_their_target_on_every_tick(timelines, name):
    # Seed 6.3.2: "Continuously look at the giver's face" / "... hand": the whole video.
    _, runs = timelines
    assert set(runs[name][1]) == {name}


def test_short_face_hand_is_on_the_hand_within_50_ms_of_the_first_reach_start(timelines):
    # Seed 6.3.2: "The transition began as soon as the reach phase started."
    handover, runs = timelines
    t, targets = runs["short-face-hand"]
    first = min(handover.robot_reach, handover.giver_reach)
    assert {targets[i] for i in np.flatnonzero(t < first)} == {"face"}
    if handover.robot_reach <= handover.giver_reach:
        known = first  # the robot knows its own reach at once
    else:
        known = handover.robot_reach  # the giver's start is known once the robot reacts to it
    on_hand = [targets[i] for i in np.flatnonzero((t >= known + 0.05) & (t < handover.release))]
    assert on_hand and set(on_hand) == {"hand"}
    if known == first:
        shift = t[targets.index("hand")]
        assert first <= shift <= first + 0.05


def test_long_face_hand_waits_for_the_end_of_the_robot_reach(timelines):
    # Seed 6.3.2: "The transition began as soon as the robot's reach phase ended."
    handover, runs = timelines
    t, targets = runs["long-face-hand"]
    shift = t[targets.index("hand")]
    assert handover.robot_reach_end <= shift <= handover.robot_reach_end + 1.5 / RATE
    assert {targets[i] for i in np.flatnonzero(t < handover.robot_reach_end)} == {"face"}


def test_as_studied_behaviors_key_on_the_robots_own_events(timelines):
    # Seed 6.4.3: face / hand / face by the end of the robot's reach (it then waits for its
    # proximity sensor to grasp) and its retreat; hand-face turns to the face "After the robot
    # started to retreat".
    handover, runs = timelines
    t, fhf = runs["face-hand-face-as-studied"]
    hand = t[np.array(fhf) == "hand"]
    end = handover.robot_reach_end
    assert end <= hand.min() <= end + 1.5 / RATE
    assert hand.max() < handover.robot_retreat
    t, hf = runs["hand-face-as-studied"]
    face = t[np.array(hf) == "face"]
    assert handover.robot_retreat <= face.min() <= handover.robot_retreat + 1.5 / RATE
