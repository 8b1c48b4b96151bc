"""The engine's full command stream on a fixed set of scenarios, flattened for comparison.

``tests/core/test_engine_stream_reference.py`` compares what the current code gives against the
stream in ``tests/core/data/engine_stream.npz``, so a speed-up that changes any command by more than
float round-off fails. It was first recorded from the code before the issue-19 speed-ups and
re-recorded only for changes of the engine's output made on purpose (each one reviewed against
the stream it replaced):

1. the gaze controller's head goal deadband (``ik: goal_deadband_deg``);
2. that deadband extended to ticks with the eyes at their range;
3. issue 20's analysis grid (the detector decides on a fixed ``online_period`` grid), end
   predictions that read no speed from the smoothing's edge and the retreat's landing dated
   from the whole speed profile (recorded on main merged with them).

A speed-up that should change nothing is checked against the stream as it stands.
Regenerate (only after an intended change of the engine's output, and say so in the commit):

    PYTHONPATH=. .venv/bin/python -m tests.core.engine_stream
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gazebot import Event, EventKind, GazeEngine, TrackingFrame
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.core.runtime import GazeLoop
from gazebot.core.types import GazeCommand

REFERENCE = Path(__file__).resolve().parent / "data" / "engine_stream.npz"
ROBOTS = ("sawyer", "jaco2")


@dataclass
class Stream:
    """One run's commands: ``floats`` (ticks x columns, NaN where absent), ``labels`` (one line
    of the non-numeric fields per tick), ``event_floats`` and ``event_labels`` (one row per
    event, its tick index first)."""

    floats: np.ndarray
    labels: np.ndarray
    event_floats: np.ndarray
    event_labels: np.ndarray


_EVENT_FLOATS = 4  # t, detected_at and up to two numeric info values


def _frames(seed: int, damaged: bool) -> list[TrackingFrame | None]:
    """A 120 Hz synthetic handover; ``damaged``: NaN points, swapped (out-of-order) and NaN
    times, a point beyond the workspace, silent ticks (``None``) and a tracking loss long
    enough for the behavior's ``tracking_lost`` policy."""
    rec = generate(seed=seed, options=SyntheticOptions(rate=120.0, posture="standing"))
    frames: list[TrackingFrame | None] = list(rec.trajectory.frames())
    if not damaged:
        return frames
    rng = np.random.default_rng(seed)
    n = len(frames)
    for k in rng.choice(n, n // 25, replace=False):
        f = frames[k]
        frames[k] = TrackingFrame.make(f.t, giver_hand=None, receiver_hand=f.receiver_hand,
                                       giver_face=f.giver_face)
    for k in rng.choice(n - 2, 5, replace=False):
        frames[k], frames[k + 1] = frames[k + 1], frames[k]
    for k in rng.choice(n, 2, replace=False):
        f = frames[k]
        frames[k] = TrackingFrame.make(math.nan, f.giver_hand, f.receiver_hand, f.giver_face)
    k = int(rng.integers(0, n))
    f = frames[k]
    frames[k] = TrackingFrame.make(f.t, [50.0, 0.0, 1.0], f.receiver_hand, f.giver_face)
    for k in rng.choice(n, 6, replace=False):
        frames[k] = None
    lost = n // 2
    for k in range(lost, min(n, lost + 150)):  # 1.25 s without hands or face
        f = frames[k]
        if f is not None:
            frames[k] = TrackingFrame.make(f.t)
    return frames


def _ticks(loop: GazeLoop, robot: str, seed: int, damaged: bool, events: bool
           ) -> Iterator[GazeCommand | None]:
    """Run one handover through ``loop``; ``events``: the robot reaches first (at 0.5 s),
    grasps and retreats, and (Sawyer) its arm joint carrying the head moves."""
    loop.reset()
    last_t = 0.0
    for i, frame in enumerate(_frames(seed, damaged)):
        t = last_t + 1 / 120 if frame is None else frame.t
        if math.isfinite(t):
            last_t = t
        if events and i == 60:
            loop.notify(Event(EventKind.ROBOT_REACH_STARTED, 0.5, 0.5,
                              {"planned_duration": 1.0}))
        if events and i == 200:
            loop.notify([Event(EventKind.ROBOT_REACH_ENDED, last_t, last_t),
                         Event(EventKind.ROBOT_GRASPED, last_t, last_t)])
        if events and i == 300:
            loop.notify(Event(EventKind.ROBOT_RETREAT_STARTED, last_t, last_t,
                              {"planned_duration": 0.8}))
        joints = None
        if events and robot == "sawyer":
            joints = {"right_j0": 0.2 * math.sin(i / 90)}
        yield loop.tick(frame, t=None if frame is not None else last_t, joints=joints)


def _flatten(cmds: list[GazeCommand | None], joints: list[str]) -> Stream:
    rows, labels, ev_rows, ev_labels = [], [], [], []
    for i, c in enumerate(cmds):
        if c is None:
            rows.append([math.nan] * (10 + len(joints)))
            labels.append("None")
            continue
        rows.append([
            c.t, *c.target_point.tolist(), *(c.head.get(j, math.nan) for j in joints),
            c.eye_yaw, c.eye_pitch, c.residual, c.gaze_shift, c.blink,
            math.nan if c.distance is None else c.distance,
        ])
        labels.append(" ".join([c.phase.value, c.phase_source, c.target, c.tracking, c.status,
                                str(c.answers_sample), ",".join(sorted(c.head))]))
        for e in c.events:
            nums = [v for _, v in sorted(e.info.items()) if isinstance(v, float)]
            text = [f"{k}={v}" for k, v in sorted(e.info.items()) if not isinstance(v, float)]
            assert len(nums) <= _EVENT_FLOATS - 2, e
            ev_rows.append([i, e.t, e.detected_at,
                            *nums, *[math.nan] * (_EVENT_FLOATS - 2 - len(nums))])
            ev_labels.append(" ".join([e.kind.value, *text]))
    return Stream(np.array(rows, float), np.array(labels),
                  np.array(ev_rows, float).reshape(-1, 1 + _EVENT_FLOATS),
                  np.array(ev_labels, dtype=str))


def scenarios() -> list[str]:
    """Names of every recorded run: robot, behavior, recording seed, damaged, robot events."""
    runs = (
        ("face-hand-face", 3, False, False),  # the benchmark's handover
        ("face-hand-face", 8, True, True),
        ("face-hand-face-as-studied", 5, True, False),
        ("human-receiver", 8, True, True),
    )
    return [f"{robot}|{behavior}|{seed}|{int(damaged)}|{int(events)}"
            for robot in ROBOTS for behavior, seed, damaged, events in runs]


def run(name: str) -> Stream:
    """The command stream of scenario ``name`` (see :func:`scenarios`)."""
    robot, behavior, seed, damaged, events = name.split("|")
    loop = GazeLoop(GazeEngine.from_config(robot=robot, behavior=behavior, seed=1), seed=1)
    joints = list(loop.robot.head_joints)
    # Two runs on one loop: the second after reset() must not depend on the first.
    for _ in _ticks(loop, robot, int(seed), bool(int(damaged)), bool(int(events))):
        pass
    cmds = list(_ticks(loop, robot, int(seed), bool(int(damaged)), bool(int(events))))
    return _flatten(cmds, joints)


def record(path: Path = REFERENCE) -> None:
    """Write every scenario's stream to ``path``."""
    arrays = {}
    for i, name in enumerate(scenarios()):
        s = run(name)
        arrays.update({f"{i}_name": np.array(name), f"{i}_floats": s.floats,
                       f"{i}_labels": s.labels, f"{i}_event_floats": s.event_floats,
                       f"{i}_event_labels": s.event_labels})
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, **arrays)


if __name__ == "__main__":
    record()
    print(f"wrote {REFERENCE} ({REFERENCE.stat().st_size // 1024} KiB)")
