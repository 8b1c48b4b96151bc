"""``GazeController``: timed neck and eye commands that keep the robot's gaze on a target.

Each :meth:`GazeController.update` solves the look-at IK for the target (warm-started), then:

* a target direction change above ``saccade_threshold_deg`` starts a **gaze shift**: the neck
  re-plans a minimum-jerk move to the new goal with ``neck_duration_s`` and the eyes saccade
  with ``eye_duration_s`` (both stretched to respect velocity limits);
* smaller changes are **tracked**: the neck re-plans from its current position, velocity and
  acceleration (no jumps), the eyes follow the target directly (smooth pursuit);
* the eyes always aim from the neck's *current* pose, so once the saccade lands they
  counter-rotate while the neck catches up and the gaze stays on the target (the iCub gaze
  controller's behaviour), and they take whatever the head cannot do (Sawyer has only pan).

Every command is clipped to joint and eye ranges and rate-limited to the velocity limits, so no
plan, re-plan or odd time step can make it jump. NaN targets hold the last valid target; time
going backwards holds the pose and re-anchors the clock.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from gazebot.kinematics.eyes import angle_between
from gazebot.kinematics.look_at import IKConfig, solve_ik
from gazebot.kinematics.robot import RobotModel
from gazebot.kinematics.shifts import (
    GazeShiftConfig,
    MinJerkTrajectory,
    min_jerk,
    min_jerk_duration,
)

# Goal changes below this (rad, any joint) do not re-plan the neck.
_REPLAN_EPS = 1e-6


@dataclass(frozen=True)
class HeadEyeState:
    """Commands for one tick (rad, rad/s).

    Attributes:
        head: Head joint positions by name (finite, within limits).
        eye_yaw, eye_pitch: Eye angles on the display (+yaw = robot's left, +pitch = down).
        residual: Angle between the gaze (head + eyes) and the target; 0 before any target.
        t: Time of the update (s).
        head_goal: Where the neck is heading (IK solution for the target).
        head_velocity: Commanded head joint velocities.
        shift_amplitude: Angle of a gaze shift started at this update (0 if none) — e.g. for a
            blink model.
        target_valid: The target given to this update was a finite point.
        eyes_saturated: The eyes are at their range.
    """

    head: dict[str, float]
    eye_yaw: float
    eye_pitch: float
    residual: float
    t: float = 0.0
    head_goal: dict[str, float] = field(default_factory=dict)
    head_velocity: dict[str, float] = field(default_factory=dict)
    shift_amplitude: float = 0.0
    target_valid: bool = True
    eyes_saturated: bool = False


class GazeController:
    """Neck and eye commands for a stream of gaze targets.

    Args:
        robot: The robot model.
        shifts: Gaze shift timing; ``None`` uses the robot YAML's ``shifts``.
        ik: Look-at solver settings.
    """

    def __init__(
        self,
        robot: RobotModel,
        shifts: GazeShiftConfig | None = None,
        ik: IKConfig | None = None,
    ) -> None:
        self.robot = robot
        self.shifts = shifts if shifts is not None else robot.config.shifts
        self.ik = ik or IKConfig(max_iterations=25)
        self.reset()

    # --- state --------------------------------------------------------------------------------
    def reset(self, head: Mapping[str, float] | None = None) -> None:
        """Forget targets and motion; put the head at ``head`` (missing joints at rest).

        Raises:
            ValueError: unknown joint names or non-finite values.
        """
        q = self.robot.head_vector(head)
        n = self.robot.n_head
        self._q = q
        self._vel = np.zeros(n)
        self._goal = q.copy()
        self._traj: MinJerkTrajectory | None = None
        self._eyes = np.zeros(2)
        self._saccade: tuple[float, float, np.ndarray] | None = None
        self._clock = 0.0
        self._t: float | None = None
        self._target: np.ndarray | None = None
        self._goal_final = False
        self._residual = 0.0

    @property
    def head(self) -> dict[str, float]:
        """Current head command by joint."""
        return self.robot.head_dict(self._q)

    def set_arm(self, joints: Mapping[str, float]) -> None:
        """Tell the model where the arm is (matters when the arm carries the head, as on Sawyer).

        The next :meth:`update` re-solves the head goal for the new arm pose.
        """
        if self.robot.set_arm(joints):
            self._goal_final = False

    # --- update -------------------------------------------------------------------------------
    def update(
        self,
        t: float,
        target_point: np.ndarray | None,
        arm: Mapping[str, float] | None = None,
    ) -> HeadEyeState:
        """Advance to time ``t`` (s) looking at ``target_point`` (base frame, m).

        Args:
            t: Time (s); going backwards (or NaN) holds the pose for this tick.
            target_point: 3D target; ``None`` or non-finite holds the last valid target.
            arm: Optional arm joint positions (rad) when the arm carries the head.

        Raises:
            ValueError: ``target_point`` is not a 3D point or ``t`` not a number (programming
                errors, unlike NaN values, which are held).
        """
        dt = self._advance(t)
        arm_moved = self.robot.set_arm(arm) if arm is not None else False
        target = self._parse(target_point)
        valid = target is not None
        shift = 0.0
        unchanged = (
            self._target is not None
            and np.array_equal(target, self._target)
            and not arm_moved
            and self._goal_final
        )
        if valid and not unchanged:
            # Plans start where the last command left off (previous tick) and are evaluated now.
            shift = self._retarget(target, self._clock - dt)

        q_prev = self._q
        if self._traj is not None and dt > 0.0:
            pos = self._traj.position(self._clock)
            step = self.robot.velocity_limits * dt
            q = self.robot.clamp(np.clip(pos, q_prev - step, q_prev + step))
            if np.all(np.isfinite(q)):
                self._vel = (q - q_prev) / dt
                self._q = q
        elif dt > 0.0:
            self._vel = np.zeros_like(self._vel)

        eyes_saturated = False
        if self._target is not None:
            pose = self.robot.gaze_pose(self._q)
            v = pose.to_local(self._target)
            if float(np.linalg.norm(v)) >= self.ik.min_distance:
                yaw, pitch, eyes_saturated = self.robot.eyes.look(v)
                goal = np.array([yaw, pitch])
                if self._saccade is not None:
                    t0, dur, start = self._saccade
                    s = min_jerk((self._clock - t0) / dur)
                    goal = start + s * (goal - start)
                    if s >= 1.0:
                        self._saccade = None
                limit = self.robot.eye_velocity_limit * dt
                eyes = np.clip(goal, self._eyes - limit, self._eyes + limit)
                self._eyes = np.array(self.robot.eyes.clip(float(eyes[0]), float(eyes[1]))[:2])
                self._residual = self.robot.eyes.residual(self._eyes[0], self._eyes[1], v)
        return HeadEyeState(
            head=self.robot.head_dict(self._q),
            eye_yaw=float(self._eyes[0]),
            eye_pitch=float(self._eyes[1]),
            residual=float(self._residual),
            t=float(self._t if self._t is not None else 0.0),
            head_goal=self.robot.head_dict(self._goal),
            head_velocity=self.robot.head_dict(self._vel),
            shift_amplitude=shift,
            target_valid=valid,
            eyes_saturated=eyes_saturated,
        )

    def _advance(self, t: float) -> float:
        """Step the internal clock; returns dt >= 0 (0 for the first call, NaN or backward time)."""
        try:
            t = float(t)
        except (TypeError, ValueError):
            raise ValueError(f"time must be a number of seconds, got {t!r}") from None
        if not math.isfinite(t):
            return 0.0
        dt = 0.0 if self._t is None else t - self._t
        self._t = t
        if dt <= 0.0:
            return 0.0
        self._clock += dt
        return dt

    @staticmethod
    def _parse(target_point: np.ndarray | None) -> np.ndarray | None:
        if target_point is None:
            return None
        p = np.asarray(target_point, dtype=float).reshape(-1)
        if p.shape != (3,):
            raise ValueError(f"target_point must be a 3D point, got shape {p.shape}")
        return p if bool(np.all(np.isfinite(p))) else None

    def _retarget(self, target: np.ndarray, t_start: float) -> float:
        """Solve IK for a new target and (re)plan neck and eyes from the state at ``t_start``
        (the previous tick); returns the shift amplitude (rad, 0 when tracking)."""
        sol = solve_ik(self.robot, target, q0=self._goal, config=self.ik)
        if not sol.valid:
            return 0.0
        cfg = self.shifts
        pose = self.robot.gaze_pose(self._q)
        if self._target is None:
            amplitude = angle_between(target - pose.position, pose.line_of_sight)
            new_shift = True
        else:
            amplitude = angle_between(target - pose.position, self._target - pose.position)
            new_shift = amplitude > cfg.saccade_threshold
        self._target = target
        goal = sol.q
        # A solve stopped by the iteration cap is refined on the next tick even if nothing moved.
        self._goal_final = sol.converged

        # Neck: continue from the current command, its velocity and the plan's acceleration.
        if self._traj is not None:
            _, _, acc = self._traj.evaluate(t_start)
        else:
            acc = np.zeros_like(self._q)
        vel = self._vel
        delta = goal - self._q
        if new_shift:
            duration = min_jerk_duration(
                delta, cfg.neck_duration_s, self.robot.velocity_limits, cfg.velocity_margin
            )
        else:
            remaining = self._traj.end_time - t_start if self._traj is not None else 0.0
            duration = max(
                remaining,
                cfg.tracking_duration_s,
                min_jerk_duration(delta, 0.0, self.robot.velocity_limits, cfg.velocity_margin),
            )
        if (
            new_shift
            or float(np.max(np.abs(goal - self._goal))) > _REPLAN_EPS
            or self._traj is None
        ):
            if float(np.max(np.abs(delta))) > _REPLAN_EPS or float(np.max(np.abs(vel))) > 0.0:
                self._traj = MinJerkTrajectory(t_start, duration, self._q, goal, vel, acc)
        self._goal = goal

        # Eyes: a saccade from where they are now toward the target (re-aimed every tick).
        if new_shift:
            v = pose.to_local(target)
            yaw, pitch, _ = self.robot.eyes.look(v)
            amp = float(np.hypot(yaw - self._eyes[0], pitch - self._eyes[1]))
            dur = min_jerk_duration(
                amp, cfg.eye_duration_s, self.robot.eye_velocity_limit, cfg.velocity_margin
            )
            self._saccade = (t_start, dur, self._eyes.copy())
            return float(amplitude)
        return 0.0
