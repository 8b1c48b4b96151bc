"""The engine's command is a complete GazeCommand, and
the loop's one-pass safety check refuses exactly what ``GazeCommand.is_finite`` and the limits
refuse."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from gazebot import GazeEngine
from gazebot.core.runtime import GazeLoop
from gazebot.core.types import GazeCommand, Phase, TrackingFrame


def _frames(n: int = 60):
    for i in range(n):
        t = i / 120
        yield TrackingFrame.make(t, giver_hand=[1.0, 0.3 - 0.2 * t, 0.9],
                                 receiver_hand=[0.4, 0, 0.9], giver_face=[1.1, -0.3, 1.6])


def test_engine_commands_have_every_field_and_compare_like_constructed_ones():
    engine = GazeEngine.from_config("jaco2", "face-hand-face")
    names = [f.name for f in dataclasses.fields(GazeCommand)]
    for frame in _frames():
        cmd = engine.step(frame)
        assert list(vars(cmd)) == names  # field order too: what dataclass __init__ makes
        rebuilt = GazeCommand(**{n: getattr(cmd, n) for n in names})
        assert repr(rebuilt) == repr(cmd)
        with pytest.raises(dataclasses.FrozenInstanceError):
            cmd.t = 0.0  # type: ignore[misc]


class _Engine:
    def __init__(self, robot) -> None:
        self.robot = robot
        self.next: GazeCommand | None = None
        self.phase = Phase.IDLE

    def step(self, frame, arm=None):
        return self.next

    def reset(self, head=None) -> None:
        pass


@pytest.mark.parametrize("field", ["t", "eye_yaw", "eye_pitch", "blink", "gaze_shift", "head"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_the_loop_refuses_any_non_finite_value_is_finite_would(field, bad):
    robot = GazeEngine.from_config("sawyer", "face-hand-face").robot
    engine = _Engine(robot)
    loop = GazeLoop(engine)
    good = GazeCommand(t=1.0, phase=Phase.IDLE, target="face",
                       target_point=np.array([1.0, 0.0, 1.5]), head={"head_pan": 0.1},
                       eye_yaw=0.0, eye_pitch=0.0)
    engine.next = good
    assert loop.tick(TrackingFrame(t=1.0)) is not None
    value = {"head_pan": bad} if field == "head" else bad
    cmd = good.replaced(**{field: value})
    assert not (cmd.is_finite() and math.isfinite(cmd.gaze_shift))
    engine.next = cmd
    unsafe = loop.unsafe
    assert loop.tick(TrackingFrame(t=2.0)) is None
    assert loop.unsafe == unsafe + 1
