"""The gaze engine: composes phases -> behavior -> gaze target -> kinematics, one tick at a time.

The engine owns no transport and no simulator; a robot stack calls :meth:`GazeEngine.step` with each
tracking frame and sends the returned :class:`~gazebot.types.GazeCommand` wherever it likes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gazebot.behaviors import BehaviorMachine, BehaviorSpec, load_behavior
from gazebot.config import ConfigError
from gazebot.kinematics import GazeController, GazeShiftConfig, RobotConfig, RobotModel
from gazebot.phases import PhaseConfig, load_phase_config, make_detector
from gazebot.types import (
    Event,
    GazeCommand,
    GazeContext,
    Phase,
    TrackingFrame,
    is_valid_point,
)

# Targets the engine fills from tracking each tick; all others come from the robot config.
_TRACKED_TARGETS = frozenset({"face", "hand", "object", "receiver_hand"})


@dataclass
class _PointMemory:
    """Last valid position of each tracked point, so a dropout does not move the gaze target."""

    last: dict[str, np.ndarray] = field(default_factory=dict)

    def update(self, name: str, value: np.ndarray, fallback: np.ndarray) -> np.ndarray:
        if is_valid_point(value):
            self.last[name] = value
            return value
        return self.last.get(name, fallback)


class GazeEngine:
    """Turns tracking frames into head joint goals and eye angles.

    Args:
        robot: The robot's kinematic model (head joints, limits, gaze frame, eye range).
        behavior: The gaze behavior to run.
        phases: Phase detection thresholds.
        shifts: Gaze shift timing (neck and eye durations); ``None`` for the defaults.
        seed: Seed for behaviors that draw random timings (reproducible runs).
    """

    def __init__(
        self,
        robot: RobotModel,
        behavior: BehaviorSpec,
        phases: PhaseConfig | None = None,
        shifts: GazeShiftConfig | None = None,
        seed: int = 0,
    ) -> None:
        missing = behavior.targets() - set(robot.points) - _TRACKED_TARGETS
        if missing:
            raise ConfigError(
                f"behavior '{behavior.name}'",
                "targets",
                f"points the robot '{robot.name}' defines ({', '.join(sorted(robot.points))}) "
                f"or tracked ones ({', '.join(sorted(_TRACKED_TARGETS))})",
                sorted(missing),
            )
        self.robot = robot
        self.behavior_spec = behavior
        self.detector = make_detector(phases or PhaseConfig())
        self.behavior = BehaviorMachine(behavior, seed=seed)
        self.gaze = GazeController(robot, shifts)
        self._memory = _PointMemory()
        self._pending: list[Event] = []
        self._last_t = -math.inf
        self._fixed_points = {k: np.asarray(v, float) for k, v in robot.points.items()}

    @classmethod
    def from_config(
        cls,
        robot: str | Path | RobotConfig = "sawyer",
        behavior: str | Path = "face-hand-face",
        phases: str | Path | PhaseConfig | None = None,
        shifts: GazeShiftConfig | None = None,
        seed: int = 0,
    ) -> GazeEngine:
        """Build an engine from names or YAML paths.

        Args:
            robot: Robot name (``sawyer``, ``jaco2``), a robot YAML file or a loaded config.
            behavior: Behavior name (see ``gazebot behaviors list``) or a behavior YAML file.
            phases: Phase config YAML file or object; ``None`` for ``configs/phases.yaml``.
        """
        model = RobotModel.load(robot)
        spec = load_behavior(behavior)
        phase_cfg = phases if isinstance(phases, PhaseConfig) else load_phase_config(phases)
        return cls(model, spec, phase_cfg, shifts, seed)

    @property
    def phase(self) -> Phase:
        return self.detector.phase

    def notify(self, event: Event) -> None:
        """Queue a robot event (e.g. ``robot_reach_started`` with ``planned_duration``) for the
        next :meth:`step`."""
        self._pending.append(event)

    def _points(self, frame: TrackingFrame) -> dict[str, np.ndarray]:
        fixed = self._fixed_points
        face = self._memory.update("face", frame.giver_face, fixed["face"])
        hand = self._memory.update("hand", frame.giver_hand, fixed["handover_location"])
        receiver = self._memory.update("receiver_hand", frame.receiver_hand, fixed["rest"])
        points = dict(fixed)
        points.update(face=face, hand=hand, object=hand, receiver_hand=receiver)
        return points

    def step(self, frame: TrackingFrame, arm: Mapping[str, float] | None = None) -> GazeCommand:
        """Advance one tick with ``frame`` and return the command for the head and the eyes.

        ``arm`` is the robot's measured arm joint positions (rad) by name; pass it when the arm
        carries the head (Sawyer's head sits on ``right_j0``) so the head goals compensate.

        Out-of-order frames are handed to the phase detector (which ignores them) and answered
        with the previous command's goals, so the output never jumps back in time.
        """
        # Every event this sample reveals (a gripper closing can reveal a reach and a transfer).
        events = self.detector.update_all(frame)
        events.extend(self._pending)
        self._pending.clear()
        for event in events:
            self.behavior.handle(event)

        if math.isfinite(frame.t):
            t = self._last_t = max(frame.t, self._last_t)
        else:  # a frame without a usable time: answer at the last known time
            t = self._last_t if math.isfinite(self._last_t) else 0.0
        ctx = GazeContext(
            t=t,
            phase=self.detector.phase,
            phase_start=self.detector.phase_start,
            expected_phase_end=self.detector.expected_phase_end,
            points=self._points(frame),
        )
        target = self.behavior.target(ctx)
        state = self.gaze.update(t, target.point, arm=arm)
        return GazeCommand(
            t=t,
            phase=ctx.phase,
            target=target.kind,
            target_point=target.point,
            head=state.head,
            eye_yaw=state.eye_yaw,
            eye_pitch=state.eye_pitch,
            residual=state.residual,
            events=tuple(events),
        )

    @property
    def tracking(self) -> str:
        """The behavior's tracking state after the last step: ``ok``; ``hold`` while tracking is
        lost and the behavior holds the gaze (its ``tracking_lost.hold_s``); ``lost`` once it
        looks at its ``tracking_lost`` target."""
        return self.behavior.tracking

    def look_at(
        self,
        t: float,
        point: np.ndarray,
        target: str = "face",
        arm: Mapping[str, float] | None = None,
    ) -> GazeCommand:
        """Point the head and eyes at a fixed ``point`` (base frame, m), bypassing the behavior.

        A fallback for a robot stack, e.g. the last face position while tracking is lost; the
        gaze shift timing and limits still apply. The phase is left as it is.
        """
        if math.isfinite(t):
            t = self._last_t = max(t, self._last_t)
        else:
            t = self._last_t if math.isfinite(self._last_t) else 0.0
        state = self.gaze.update(t, point, arm=arm)
        return GazeCommand(
            t=t,
            phase=self.detector.phase,
            target=target,
            target_point=np.asarray(point, float),
            head=state.head,
            eye_yaw=state.eye_yaw,
            eye_pitch=state.eye_pitch,
            residual=state.residual,
        )

    def resync(self, events: list[Event]) -> None:
        """Catch up with a handover already under way (e.g. after an engine restart): replay the
        phase and robot events published before the restart, oldest first."""
        for event in sorted(events, key=lambda e: e.t):
            self.detector.resync(event)
            self.behavior.handle(event)

    def reset(self, head: Mapping[str, float] | None = None) -> None:
        """Forget the current handover (e.g. after a restart) and optionally the head pose."""
        self.detector = make_detector(self.detector.config)
        self.behavior = BehaviorMachine(self.behavior_spec, seed=self.behavior.seed)
        self.gaze.reset(head)
        self._memory = _PointMemory()
        self._pending.clear()
        self._last_t = -math.inf
