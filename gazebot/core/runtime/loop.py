"""The one runtime loop: tracking and robot state in, safe head, eye and blink commands out.

Every consumer drives the robot's head and eyes through :class:`GazeLoop`: the in-process
handover recording (``gazebot demo``, ``gazebot render video``, ``gazebot study render``), the
engine node on the bus (``gazebot run``, ``gazebot sim --with-engine``) and the in-process
simulated driver. What it adds to :meth:`gazebot.core.engine.GazeEngine.step`:

* **Blinks**: one :class:`~gazebot.core.runtime.blink.BlinkModel`, fed with the command's
  ``gaze_shift`` (the size of a gaze shift starting this tick, computed once by the gaze
  controller).
* **Vergence distance**: from the same ``gaze`` frame origin to the target point (``None`` when
  the target is unknown or at the display itself). The ``gaze`` frame is placed at the measured
  head joints when the tick's ``joints`` has them all (where the display really is), else at
  the commanded head pose.
* **Tracking loss**: a tick without a sample (``frame=None``, the transport heard nothing) is a
  missing sample for the phase detector, which bridges short gaps and reports ``tracking_lost``
  after ``max_gap_hold``; the behavior then applies its own ``tracking_lost`` policy (hold for
  ``hold_s``, then look at its target, by default the last known face). There is no other
  fallback: the behavior's timings are the only ones.
* **Safety**: the gaze controller is the one place that clips the head goals into the joint
  limits and the eyes into their range; the loop checks: a command with any non-finite value, a
  head goal outside the limits (or for a joint the robot lacks) or eyes outside their range is
  never returned (the tick returns ``None`` and counts it in :attr:`GazeLoop.unsafe`); the blink
  is kept in 0..1. An engine that raises is answered the same way (counted in
  :attr:`GazeLoop.faults`): the loop never dies on input.

The loop's output is the engine's :class:`~gazebot.core.types.GazeCommand` with the lids, the
vergence distance and ``answers_sample`` filled in (one command type from the engine to the
wire).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Protocol

import numpy as np

from gazebot.core.defaults import DEFAULT_BEHAVIOR, DEFAULT_ROBOT
from gazebot.core.runtime.blink import BlinkModel
from gazebot.core.types import (
    Event,
    GazeCommand,
    Phase,
    TrackingFrame,
    TrackingState,
    is_valid_point,
)

if TYPE_CHECKING:
    from pathlib import Path

    from gazebot.core.kinematics import RobotConfig
    from gazebot.core.phases import PhaseConfig

#: The loop's command is the engine's (kept as a name for the drivers that import it).
LoopCommand = GazeCommand

__all__ = ["EngineLike", "GazeLoop", "LoopCommand", "RobotLike", "TrackingState"]


class EyesLike(Protocol):
    """What the loop uses of the eyes (:class:`gazebot.core.kinematics.eyes.DisplayEyes`)."""

    def clip(self, yaw: float, pitch: float) -> tuple[float, float, bool]:
        """Clip yaw and pitch (rad) to the eye range; the flag: whether anything was clipped."""


class RobotLike(Protocol):
    """What the loop reads of the robot (:class:`gazebot.core.kinematics.RobotModel`)."""

    @property
    def head_joints(self) -> Sequence[str]:
        """Head joint names, in the order of every head vector."""

    @property
    def lower(self) -> np.ndarray:
        """Lower head joint limits (rad)."""

    @property
    def upper(self) -> np.ndarray:
        """Upper head joint limits (rad)."""

    @property
    def rest(self) -> np.ndarray:
        """The head's rest position (rad)."""

    @property
    def eyes(self) -> EyesLike:
        """The display eyes, which clip eye angles to their range."""

    def gaze_frame_lists(self, q_head: Sequence[float]) -> list[list[float]]:
        """Gaze frame pose for head vector ``q_head``: three rows ``[R_i0, R_i1, R_i2, p_i]``."""


class EngineLike(Protocol):
    """What the loop drives (:class:`gazebot.core.engine.GazeEngine`)."""

    @property
    def robot(self) -> RobotLike:
        """The robot model."""

    @property
    def phase(self) -> Phase:
        """The current handover phase."""

    def step(
        self, frame: TrackingFrame, arm: Mapping[str, float] | None = None
    ) -> GazeCommand:
        """Advance one tick with ``frame`` (``arm``: measured arm joints, rad) and return the
        command."""

    def notify(self, events: Event | Iterable[Event]) -> None:
        """Queue one robot event or several for the next step."""

    def reset(self, head: Mapping[str, float] | None = None) -> None:
        """Forget the current handover and optionally the head pose."""

    def resync(self, events: Iterable[Event]) -> None:
        """Catch up with a handover under way from the events published before a restart."""


class GazeLoop:
    """Turns tracking samples (or their absence) into safe :class:`GazeCommand` s.

    Args:
        engine: The engine (a :class:`gazebot.core.engine.GazeEngine`, or anything
            :class:`EngineLike`).
        blink: The blink model; ``None`` for ``BlinkModel(seed)``.
        seed: Seed of the default blink model.
    """

    def __init__(self, engine: EngineLike, blink: BlinkModel | None = None, seed: int = 0) -> None:
        self.engine = engine
        self.blinks = blink if blink is not None else BlinkModel(seed)
        self.unsafe = 0  # commands refused: non-finite, or outside the joint or eye limits
        self.faults = 0  # ticks the engine raised on (answered with None)
        self.ticks = 0
        self._t = -math.inf
        # The last gaze frame and its key (head pose, arm revision): a head at rest needs no
        # forward kinematics.
        self._frame: tuple[tuple[tuple[float, ...], object], list[list[float]]] | None = None
        robot = engine.robot  # (the engine's robot never changes)
        # Each head joint's name, limits and rest value.
        self._joints = [
            (str(n), float(lo), float(hi), float(r))
            for n, lo, hi, r in zip(robot.head_joints, robot.lower, robot.upper, robot.rest,
                                    strict=True)
        ]

    @classmethod
    def from_config(
        cls,
        robot: str | Path | RobotConfig = DEFAULT_ROBOT,
        behavior: str | Path = DEFAULT_BEHAVIOR,
        phases: str | Path | PhaseConfig | None = None,
        seed: int = 0,
    ) -> GazeLoop:
        """A loop around ``GazeEngine.from_config(robot, behavior, phases, seed=seed)`` with
        ``BlinkModel(seed)``."""
        from gazebot.core.engine import GazeEngine

        return cls(GazeEngine.from_config(robot, behavior, phases, seed=seed), seed=seed)

    @property
    def robot(self) -> RobotLike:
        """The engine's robot model."""
        return self.engine.robot

    @property
    def phase(self) -> Phase:
        """The engine's current handover phase."""
        return self.engine.phase

    def notify(self, events: Event | Iterable[Event]) -> None:
        """Hand one robot event or several (e.g. ``robot_reach_started``) to the engine's next
        tick."""
        self.engine.notify(events)

    def reset(self, head: Mapping[str, float] | None = None) -> None:
        """Forget the handover, the head pose (``head``: the measured one) and the blink line."""
        self.engine.reset(head)
        self.blinks.reset()
        self._t = -math.inf

    def resync(self, events: Iterable[Event]) -> None:
        """Catch up with a handover under way (see :meth:`GazeEngine.resync`)."""
        self.engine.resync(events)

    def tick(
        self,
        frame: TrackingFrame | None,
        *,
        t: float | None = None,
        joints: Mapping[str, float] | None = None,
    ) -> GazeCommand | None:
        """Advance with ``frame``, or, with ``None`` (no sample arrived), to robot time ``t``.

        ``t`` is the tick's robot time (s): required without a frame; with a frame it may be
        given only if it agrees with ``frame.t``. ``joints`` is the robot's measured joint
        positions (rad) by name: the arm joints that carry the head (Sawyer's ``right_j0``) and
        the head joints. Returns the command, or ``None`` when the engine produced an unsafe one
        (non-finite, or outside the joint or eye limits) or raised (never sent).

        Raises:
            ValueError: no frame and no ``t``, or a ``t`` that disagrees with ``frame.t``
                (a caller's mistake, not bad input).
        """
        answers = frame is not None
        if frame is None:
            if t is None:
                raise ValueError("tick(None) needs the robot time t")
            # Silence is a missing sample: the detector bridges it, then reports tracking_lost.
            frame = TrackingFrame(t=float(t))
        elif t is not None:
            ft = frame.t
            if math.isfinite(t) and math.isfinite(ft) and abs(float(t) - float(ft)) > 1e-9:
                raise ValueError(f"tick: t={t} disagrees with the frame's t={ft}")
        self.ticks += 1
        try:
            cmd = self.engine.step(frame, joints)
        except Exception:  # noqa: BLE001 - a node never dies on input; the tick sends nothing
            self.faults += 1
            return None
        return self._finish(cmd, answers, joints)

    def _finish(
        self, cmd: GazeCommand, answers: bool, joints: Mapping[str, float] | None
    ) -> GazeCommand | None:
        """The safe command with lids, vergence distance and ``answers_sample`` filled in, or
        ``None`` (counted in :attr:`unsafe`)."""
        pose = self._safe_head(cmd)
        if pose is None:
            self.unsafe += 1
            return None
        if joints:
            # The display is where the measured head is, when all its joints are known.
            pose = self._measured_pose(joints) or pose
        distance = self._vergence_distance(cmd.target_point, pose)
        # Blink times never go back (the engine's t never does either).
        t = self._t = max(cmd.t, self._t)
        blink = min(max(float(self.blinks.update(t, cmd.gaze_shift)), 0.0), 1.0)
        return cmd.replaced(blink=blink, distance=distance, answers_sample=answers)

    def _safe_head(self, cmd: GazeCommand) -> list[float] | None:
        """The commanded head vector (rest for a joint the command lacks), or ``None`` if the
        command is unsafe: a non-finite value (what :meth:`GazeCommand.is_finite` checks, and
        the gaze shift), a head goal outside its joint's limits or for a joint the robot lacks,
        or eyes outside their range. (A check, not a clip: the gaze controller clips.)"""
        if not all(map(math.isfinite, (cmd.t, cmd.blink, cmd.gaze_shift))):
            return None
        head = cmd.head
        if not set(head) <= {name for name, _, _, _ in self._joints}:
            return None
        pose = []
        for name, lo, hi, rest in self._joints:
            value = head.get(name, rest)
            if not lo <= value <= hi:  # NaN fails too
                return None
            pose.append(value)
        if self.engine.robot.eyes.clip(cmd.eye_yaw, cmd.eye_pitch)[2]:  # NaN is clipped too
            return None
        return pose

    def _vergence_distance(self, point: np.ndarray | None, pose: list[float]) -> float | None:
        """Distance (m) from the ``gaze`` frame origin at head ``pose`` to ``point``; ``None``
        without a finite point, or for one at the display itself."""
        if not is_valid_point(point):
            return None
        rows = self._gaze_frame(pose)
        origin = (rows[0][3], rows[1][3], rows[2][3])
        distance = math.dist(np.asarray(point, dtype=float).tolist(), origin)
        # A target at the display itself (or beyond any float) has no defined vergence.
        return distance if 1e-3 < distance < math.inf else None

    def _gaze_frame(self, pose: list[float]) -> list[list[float]]:
        """The ``gaze`` frame at head ``pose``; the last one again while neither the pose nor
        the arm carrying the head moved."""
        key = (tuple(pose), getattr(self.engine.robot, "arm_revision", None))
        if self._frame is None or self._frame[0] != key:
            self._frame = (key, self.engine.robot.gaze_frame_lists(pose))
        return self._frame[1]

    def _measured_pose(self, joints: Mapping[str, float]) -> list[float] | None:
        """The measured head vector clipped into the limits, or ``None`` unless every head
        joint is in ``joints`` and finite."""
        measured = [joints.get(n, math.nan) for n, _, _, _ in self._joints]
        if all(isinstance(v, (int, float)) and math.isfinite(v) for v in measured):
            return [min(max(v, lo), hi)
                    for v, (_, lo, hi, _) in zip(measured, self._joints, strict=True)]
        return None
