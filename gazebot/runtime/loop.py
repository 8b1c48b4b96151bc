"""The one runtime loop: tracking and robot state in, safe head, eye and blink commands out.

Every consumer drives the robot's head and eyes through :class:`GazeLoop`: the in-process
handover recording (``gazebot demo``, ``gazebot render video``, ``gazebot study render``), the
engine node on the bus (``gazebot run``, ``gazebot sim --with-engine``) and the in-process
simulated driver. What it adds to :meth:`gazebot.engine.GazeEngine.step`:

* **Blinks**: one :class:`~gazebot.render.blink.BlinkModel`, fed with how far the gaze direction
  (from the head's ``gaze`` frame to the target point) turned since the previous tick.
* **Vergence distance**: from the same ``gaze`` frame origin to the target point (``None`` when
  the target is unknown or at the display itself). The ``gaze`` frame is placed at the measured
  head joints when the tick's ``joints`` has them all (where the display really is), else at
  the commanded head pose.
* **Tracking loss**: a tick without a sample (``frame=None``, the transport heard nothing) is a
  missing sample for the phase detector, which bridges short gaps and reports ``tracking_lost``
  after ``max_gap_hold``; the behavior then applies its own ``tracking_lost`` policy (hold for
  ``hold_s``, then look at its target, by default the last known face). There is no other
  fallback: the behavior's timings are the only ones.
* **Safety**: a head goal outside the joint limits is clipped into them, eye angles into the
  eye range, the blink into 0..1; a command with any non-finite value is never returned (the
  tick returns ``None`` and counts it in :attr:`GazeLoop.unsafe`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from gazebot.render.blink import BlinkModel
from gazebot.types import Event, GazeCommand, Phase, TrackingFrame, is_valid_point

TrackingState = Literal["waiting", "ok", "hold", "lost"]


@dataclass(frozen=True)
class LoopCommand:
    """One tick's command for the head, the eyes and the lids (SI units, robot base frame).

    Attributes:
        t: Robot time (s) of the tick.
        phase: Handover phase.
        target: Gaze target kind (``face``, ``hand``, ...).
        target_point: The point looked at (m).
        head: Head joint goals (rad), finite and within the joint limits.
        eye_yaw: Eye yaw (rad, + = robot's left), within the eye range.
        eye_pitch: Eye pitch (rad, + = down), within the eye range.
        blink: Lid closure, 0 open .. 1 closed.
        distance: Distance (m) from the ``gaze`` frame to the target, for vergence; ``None``
            when unknown.
        tracking: ``ok``, ``hold`` (tracking lost, the behavior holds the gaze) or ``lost``
            (the behavior looks at its ``tracking_lost`` target).
        answers_sample: Whether the tick answered a tracking sample (``False``: silence).
        residual: Angle between the line of sight and the target (rad).
        events: Events that fired during the tick.
    """

    t: float
    phase: Phase
    target: str
    target_point: np.ndarray
    head: dict[str, float]
    eye_yaw: float
    eye_pitch: float
    blink: float
    distance: float | None
    tracking: TrackingState
    answers_sample: bool
    residual: float = 0.0
    events: tuple[Event, ...] = ()


def _direction_change(prev: tuple[float, float, float] | None,
                      cur: tuple[float, float, float] | None) -> float:
    """Angle (rad) between two gaze directions; 0 when either is unknown or degenerate."""
    if prev is None or cur is None:
        return 0.0
    # Plain floats: this runs every tick, where numpy's per-call overhead would dominate.
    a = math.sqrt(prev[0] * prev[0] + prev[1] * prev[1] + prev[2] * prev[2])
    b = math.sqrt(cur[0] * cur[0] + cur[1] * cur[1] + cur[2] * cur[2])
    if a < 1e-9 or b < 1e-9:
        return 0.0
    c = (prev[0] * cur[0] + prev[1] * cur[1] + prev[2] * cur[2]) / (a * b)
    return math.acos(min(max(c, -1.0), 1.0))


class GazeLoop:
    """Turns tracking samples (or their absence) into :class:`LoopCommand` s.

    Args:
        engine: A :class:`gazebot.engine.GazeEngine` (``step``, ``notify``, ``reset``, ``resync``,
            ``tracking``, and ``robot`` with ``head_joints``, ``lower``, ``upper``,
            ``rest``, ``eyes.clip`` and ``gaze_frame_lists``).
        blink: The blink model; ``None`` for ``BlinkModel(seed)``.
        seed: Seed of the default blink model.
    """

    def __init__(self, engine: Any, blink: BlinkModel | None = None, seed: int = 0) -> None:
        self.engine = engine
        self.blinks = blink if blink is not None else BlinkModel(seed)
        self.unsafe = 0  # commands refused for non-finite values
        self.clipped = 0  # commands brought into the joint or eye limits
        self.ticks = 0
        self._prev_dir: tuple[float, float, float] | None = None
        self._t = -math.inf
        robot = engine.robot
        self._limits = [(str(n), float(lo), float(hi))
                        for n, lo, hi in zip(robot.head_joints, robot.lower, robot.upper,
                                             strict=True)]
        self._rest = [float(r) for r in robot.rest]

    @classmethod
    def from_config(
        cls,
        robot: Any = "sawyer",
        behavior: Any = "face-hand-face",
        phases: Any = None,
        seed: int = 0,
    ) -> GazeLoop:
        """A loop around ``GazeEngine.from_config(robot, behavior, phases, seed=seed)`` with
        ``BlinkModel(seed)``."""
        from gazebot.engine import GazeEngine

        return cls(GazeEngine.from_config(robot, behavior, phases, seed=seed), seed=seed)

    @property
    def robot(self) -> Any:
        return self.engine.robot

    @property
    def phase(self) -> Phase:
        return self.engine.phase

    def notify(self, events: Sequence[Event]) -> None:
        """Hand robot events (e.g. ``robot_reach_started``) to the engine's next tick."""
        for event in events:
            self.engine.notify(event)

    def reset(self, head: Mapping[str, float] | None = None) -> None:
        """Forget the handover, the head pose (``head``: the measured one) and the blink line."""
        self.engine.reset(head)
        self.blinks.reset()
        self._prev_dir = None
        self._t = -math.inf

    def resync(self, events: list[Event]) -> None:
        """Catch up with a handover under way (see :meth:`GazeEngine.resync`)."""
        self.engine.resync(events)

    def tick(
        self,
        t: float,
        frame: TrackingFrame | None = None,
        joints: Mapping[str, float] | None = None,
    ) -> LoopCommand | None:
        """Advance to robot time ``t`` (s) with ``frame`` (``None``: no sample arrived).

        ``joints`` is the robot's measured joint positions (rad) by name: the arm joints that
        carry the head (Sawyer's ``right_j0``) and the head joints. Returns the command, or
        ``None`` when the engine produced a non-finite one (never sent).
        """
        answers = frame is not None
        if frame is None:
            # Silence is a missing sample: the detector bridges it, then reports tracking_lost.
            frame = TrackingFrame(t=float(t))
        cmd = self.engine.step(frame, arm=joints)
        self.ticks += 1
        return self._finish(cmd, answers, joints)

    def _finish(
        self, cmd: GazeCommand, answers: bool, joints: Mapping[str, float] | None
    ) -> LoopCommand | None:
        if not (cmd.is_finite() and math.isfinite(cmd.t)):
            self.unsafe += 1
            return None
        robot = self.robot
        head, clipped = self._safe_head(cmd.head)
        yaw, pitch, eyes_clipped = robot.eyes.clip(cmd.eye_yaw, cmd.eye_pitch)
        if clipped or eyes_clipped:
            self.clipped += 1
        rows = robot.gaze_frame_lists(self._display_pose(head, joints))
        direction = None
        distance = None
        if is_valid_point(cmd.target_point):
            x, y, z = cmd.target_point.tolist()
            direction = (x - rows[0][3], y - rows[1][3], z - rows[2][3])
            d = math.sqrt(direction[0] ** 2 + direction[1] ** 2 + direction[2] ** 2)
            # A target at the display itself has no defined vergence: unknown.
            distance = d if d > 1e-3 else None
        # Blink times never go back (the engine's t never does either).
        t = self._t = max(cmd.t, self._t)
        shift = _direction_change(self._prev_dir, direction)
        if direction is not None:
            self._prev_dir = direction
        blink = min(max(float(self.blinks.update(t, shift)), 0.0), 1.0)
        return LoopCommand(
            t=cmd.t,
            phase=cmd.phase,
            target=cmd.target,
            target_point=np.asarray(cmd.target_point, float),
            head=head,
            eye_yaw=float(yaw),
            eye_pitch=float(pitch),
            blink=blink,
            distance=distance,
            tracking=self.engine.tracking,
            answers_sample=answers,
            residual=float(cmd.residual),
            events=cmd.events,
        )

    def _display_pose(
        self, head: dict[str, float], joints: Mapping[str, float] | None
    ) -> list[float]:
        """Head vector where the display is: the measured head joints when all are known and
        finite, else the commanded (safe) ones."""
        if joints:
            measured = [joints.get(n, math.nan) for n, _, _ in self._limits]
            if all(math.isfinite(v) for v in measured):
                return [min(max(v, lo), hi)
                        for v, (_, lo, hi) in zip(measured, self._limits, strict=True)]
        return [head.get(n, r) for (n, _, _), r in zip(self._limits, self._rest, strict=True)]

    def _safe_head(self, head: Mapping[str, float]) -> tuple[dict[str, float], bool]:
        """``head`` clipped into the joint limits, and whether anything was clipped."""
        unknown = set(head).difference(n for n, _, _ in self._limits)
        if unknown:
            raise ValueError(f"engine commanded unknown head joints {sorted(unknown)}")
        out: dict[str, float] = {}
        clipped = False
        for name, lo, hi in self._limits:
            if name not in head:
                continue
            q = float(head[name])
            x = min(max(q, lo), hi)
            clipped = clipped or x != q
            out[name] = x
        return out, clipped
