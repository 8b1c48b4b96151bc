"""``GazeController``: timed neck and eye commands that keep the robot's gaze on a target.

Each :meth:`GazeController.update` solves the look-at IK for the target, warm-started from the
last solution (whose gaze frame and Jacobian are reused). While the target moves without a gaze
shift, the solve stops at the looser ``IKConfig.tracking_tolerance`` (usually after one
Gauss-Newton step: the per-tick cost of following a hand or face); once it stops moving, the
goal is refined to the full tolerance. Then:

* a target direction change above ``saccade_threshold_deg`` starts a **gaze shift**: the neck
  re-plans a minimum-jerk move to the new goal with ``neck_duration_s`` and the eyes saccade
  with ``eye_duration_s`` (both stretched to respect velocity limits);
* smaller changes are **tracked**: the neck re-plans from its current position, velocity and
  acceleration (no jumps), the eyes follow the target directly (smooth pursuit); while the
  target stays within ``IKConfig.goal_deadband`` (seen from the goal's gaze origin) of the one
  the head goal was solved for, the goal is kept (no solve, no re-plan) and the eyes take the
  difference as far as their range allows (until the target stops: then the goal is refined
  as above);
* the eyes always aim from the neck's *current* pose, so once the saccade lands they
  counter-rotate while the neck catches up and the gaze stays on the target (the iCub gaze
  controller's behaviour), and they take whatever the head cannot do (Sawyer has only pan).

Every command is clipped to joint and eye ranges and rate-limited to the velocity limits, so no
plan, re-plan or odd time step can make it jump. NaN targets hold the last valid target; time
going backwards holds the pose and re-anchors the clock.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from gazebot.core.kinematics.eyes import angle_between
from gazebot.core.kinematics.look_at import (
    GazeFrame,
    HeadSolution,
    IKConfig,
    Vector3,
    solve_head,
)
from gazebot.core.kinematics.robot import RobotModel
from gazebot.core.kinematics.shifts import GazeShiftConfig, MinJerkTrajectory, min_jerk_duration
from gazebot.core.minimum_jerk import minimum_jerk

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
            blink model. target_valid: The target given to this update was a finite point.
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


class GazeStep(NamedTuple):
    """The commands of one :meth:`GazeController.step` (rad).

    Attributes:
        head: Head joint positions in ``robot.head_joints`` order (finite, within limits).
        eye_yaw, eye_pitch: Eye angles on the display.
        residual: Angle between the gaze (head + eyes) and the target.
        shift_amplitude: Angle of a gaze shift started at this step (0 if none).
    """

    head: list[float]
    eye_yaw: float
    eye_pitch: float
    residual: float
    shift_amplitude: float


class GazeController:
    """Neck and eye commands for a stream of gaze targets.

    Args:
        robot: The robot model.
        shifts: Gaze shift timing; ``None`` uses the robot YAML's ``shifts``.
        ik: Look-at solver settings; ``None`` uses the robot YAML's ``ik``.
    """

    def __init__(
        self,
        robot: RobotModel,
        shifts: GazeShiftConfig | None = None,
        ik: IKConfig | None = None,
    ) -> None:
        self.robot = robot
        self.shifts = shifts if shifts is not None else robot.config.shifts
        self.ik = ik if ik is not None else IKConfig.from_settings(robot.config.ik)
        self._names = tuple(robot.head_joints)
        # Per head joint: velocity limit and position limits.
        self._limits = list(
            zip(
                robot.velocity_limits.tolist(), robot.lower.tolist(), robot.upper.tolist(),
                strict=True,
            )
        )
        # The head goal deadband needs eyes that can take the difference (not head-only).
        eyes = robot.eyes
        movable = eyes.yaw_range[0] < eyes.yaw_range[1] or eyes.pitch_range[0] < eyes.pitch_range[1]
        self._deadband = self.ik.goal_deadband if movable else 0.0
        # A target farther than this on any axis is a corrupted sample (finite even if
        # max_distance is not).
        self._max_abs = min(self.ik.max_distance, sys.float_info.max)
        self.reset()

    # --- state --------------------------------------------------------------------------------
    def reset(self, head: Mapping[str, float] | None = None) -> None:
        """Forget targets and motion; put the head at ``head`` (missing joints at rest).

        Raises:
            ValueError: unknown joint names or non-finite values.
        """
        q = self.robot.head_vector(head).tolist()
        n = len(q)
        # Head vectors are lists that are replaced, never changed in place.
        self._q: list[float] = q
        self._vel: list[float] = [0.0] * n
        self._goal: list[float] = list(q)
        self._traj: MinJerkTrajectory | None = None
        self._eyes: tuple[float, float] = (0.0, 0.0)
        self._saccade: tuple[float, float, tuple[float, float]] | None = None
        self._clock = 0.0
        self._t: float | None = None
        self._target: tuple[float, float, float] | None = None
        self._goal_final = False
        self._residual = 0.0
        # Gaze pose at the head command: (head vector, arm revision, pose).
        self._frame: tuple[list[float], int, GazeFrame] | None = None
        # The last IK solution (its q is ``_goal``) and the arm revision it was solved for: its
        # gaze frame and Jacobian seed the next warm start.
        self._solution: tuple[HeadSolution, int] | None = None
        # The goal's gaze origin and the unit direction from it to the target the goal was
        # solved for (the deadband's reference), or None.
        self._solved_for: tuple[GazeFrame, Vector3] | None = None
        # The last update's target was a finite point; the eyes were at their range.
        self._target_valid = True
        self._eyes_saturated = False

    @property
    def head(self) -> dict[str, float]:
        """Current head command by joint."""
        return dict(zip(self._names, self._q, strict=True))

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
        shift = self.step(t, target_point, arm).shift_amplitude
        valid, eyes_saturated = self._target_valid, self._eyes_saturated
        names = self._names
        state = HeadEyeState(
            head=dict(zip(names, self._q, strict=True)),
            eye_yaw=float(self._eyes[0]),
            eye_pitch=float(self._eyes[1]),
            residual=float(self._residual),
            t=float(self._t if self._t is not None else 0.0),
            head_goal=dict(zip(names, self._goal, strict=True)),
            head_velocity=dict(zip(names, self._vel, strict=True)),
            shift_amplitude=shift,
            target_valid=valid,
            eyes_saturated=eyes_saturated,
        )
        return state

    def step(
        self,
        t: float,
        target_point: np.ndarray | None,
        arm: Mapping[str, float] | None = None,
    ) -> GazeStep:
        """:meth:`update` as a :class:`GazeStep`: the same floats without the
        :class:`HeadEyeState` and its joint dicts (the engine's tick reads only these)."""
        dt = self._advance(t)
        arm_moved = self.robot.set_arm(arm) if arm is not None else False
        target = self._usable_target(target_point)
        shift = 0.0
        if target is not None and not (
            target == self._target and not arm_moved and self._goal_final
        ):
            # Plans start where the last command left off (previous tick) and are evaluated now.
            shift = self._retarget(target, self._clock - dt)
        if dt > 0.0:
            if self._traj is not None:
                self._follow(self._traj.position(self._clock).tolist(), dt)
            else:
                self._vel = [0.0] * len(self._q)
        self._target_valid = target is not None
        self._eyes_saturated = self._aim_eyes(dt) if self._target is not None else False
        return GazeStep(self._q, self._eyes[0], self._eyes[1], self._residual, shift)

    def _usable_target(self, point: object) -> tuple[float, float, float] | None:
        """``point`` as floats, or ``None`` when it is missing, not finite or absurdly far (a
        corrupted sample is held like a missing one).

        Raises:
            ValueError: it is not a 3D point.
        """
        if point is None:
            return None
        x, y, z = _vector(point).tolist()
        if not all(abs(v) <= self._max_abs for v in (x, y, z)):  # NaN fails the comparison
            return None
        return (x, y, z)

    def _follow(self, pos: list[float], dt: float) -> None:
        """Move the head command toward the plan's position ``pos`` within the velocity and
        joint limits (a non-finite result keeps the last command)."""
        q = []
        for p, last, (vlim, lo, hi) in zip(pos, self._q, self._limits, strict=True):
            step = vlim * dt
            q.append(min(max(min(max(p, last - step), last + step), lo), hi))
        if all(map(math.isfinite, q)):
            self._vel = [(a - last) / dt for a, last in zip(q, self._q, strict=True)]
            self._q = q

    def _aim_eyes(self, dt: float) -> bool:
        """Aim the eyes at the target from the head command (saccade profile, speed limit,
        range); returns whether they are at their range."""
        local = self._gaze_frame().to_local(self._target)  # type: ignore[arg-type]
        if not math.hypot(*local) >= self.ik.min_distance:
            return False  # too close for a direction (or not a number): the eyes stay
        eyes = self.robot.eyes
        yaw, pitch, saturated = eyes.look(local)
        if self._saccade is not None:
            t0, duration, (yaw0, pitch0) = self._saccade
            s = minimum_jerk((self._clock - t0) / duration)
            yaw, pitch = yaw0 + s * (yaw - yaw0), pitch0 + s * (pitch - pitch0)
            if s >= 1.0:
                self._saccade = None
        reach = self.robot.eye_velocity_limit * dt
        last_yaw, last_pitch = self._eyes
        yaw = min(max(yaw, last_yaw - reach), last_yaw + reach)
        pitch = min(max(pitch, last_pitch - reach), last_pitch + reach)
        yaw, pitch, _ = eyes.clip(yaw, pitch)
        self._eyes = (yaw, pitch)
        self._residual = eyes.residual(yaw, pitch, local)
        return saturated

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

    def _gaze_frame(self) -> GazeFrame:
        """Gaze frame at the head command (kept: the eyes of one tick and the re-plan of the
        next both need it)."""
        revision = self.robot.arm_revision
        kept = self._frame
        if kept is not None and kept[1] == revision and kept[0] == self._q:
            return kept[2]
        frame = GazeFrame.of_rows(self.robot.gaze_frame_lists(self._q))
        self._frame = (self._q, revision, frame)
        return frame

    def _in_deadband(self, target: tuple[float, float, float]) -> bool:
        """The target is within ``ik.goal_deadband`` of the one the head goal was solved for,
        seen from the goal's gaze origin, with no saccade under way. The eyes take the
        difference as far as their range allows: where the target is beyond their reach
        anyway, the gaze misses by at most the deadband's angle more than with the goal
        re-solved. (``_solved_for`` is None without a deadband, as in ``head-only`` mode.)"""
        if self._solved_for is None or self._saccade is not None:
            return False
        solved, direction = self._solved_for
        return angle_between(direction, solved.offset(target)) <= self._deadband

    def _retarget(self, target: tuple[float, float, float], t_start: float) -> float:
        """Solve IK for a new target and (re)plan neck and eyes from the state at ``t_start``
        (the previous tick); returns the shift amplitude (rad, 0 when tracking)."""
        # The shift's size: from the gaze origin, between the new target and the old one (or
        # the line of sight).
        frame = self._gaze_frame()
        revision = self.robot.arm_revision
        seen = frame.offset(target)
        old = self._target
        if old is None:
            amplitude = angle_between(seen, frame.x)
            new_shift = True
        else:
            amplitude = angle_between(seen, frame.offset(old))
            new_shift = amplitude > self.shifts.saccade_threshold

        # A target that moved without a gaze shift is followed at the tracking tolerance; a new
        # or unchanged one (e.g. after the arm moved, or to finish a tracked goal) in full.
        tracking = not new_shift and target != old
        warm = None
        last = self._solution
        if last is not None and last[1] == revision:
            if tracking and self._in_deadband(target):
                # The head goal stays; the eyes, aimed from the head's pose, take the rest. It
                # is solved in full once the target stands still.
                self._target = target
                self._goal_final = False
                return 0.0
            warm = last[0].kinematics
        sol = solve_head(
            self.robot, target, self._goal, self.ik, warm, jacobian=True, tracking=tracking
        )
        if not sol.valid:
            return 0.0  # at the gaze origin: no direction to look
        self._solution = (sol, revision)
        self._target = target
        if self._deadband > 0.0 and sol.kinematics is not None:
            solved = GazeFrame.of_rows(sol.kinematics.frame)
            seen = solved.offset(target)
            norm = math.hypot(*seen)  # > 0: the solve was valid
            self._solved_for = (solved, (seen[0] / norm, seen[1] / norm, seen[2] / norm))
        # A solve stopped by the iteration cap or at the tracking tolerance is refined on the
        # next tick even if nothing moved.
        self._goal_final = sol.converged
        self._plan_neck(sol.q, new_shift, t_start)
        self._goal = sol.q
        if new_shift:
            self._plan_saccade(target, t_start)
            return float(amplitude)
        return 0.0

    def _plan_neck(self, goal: list[float], new_shift: bool, t_start: float) -> None:
        """Re-plan the neck toward ``goal`` from the current command, its velocity and the
        plan's acceleration at ``t_start``: a new shift takes at least ``neck_duration_s``, a
        tracked move keeps the plan's end or ``tracking_duration_s``, both stretched to the
        velocity limits. An unchanged goal keeps the plan."""
        cfg = self.shifts
        traj = self._traj
        q = np.array(self._q)
        move = np.subtract(goal, q)
        if new_shift:
            nominal = cfg.neck_duration_s
        else:
            remaining = traj.end_time - t_start if traj is not None else 0.0
            nominal = max(remaining, cfg.tracking_duration_s)
        goal_change = np.max(np.abs(np.subtract(goal, self._goal)), initial=0.0)
        if not (new_shift or goal_change > _REPLAN_EPS or traj is None):
            return
        moving = np.max(np.abs(move), initial=0.0) > _REPLAN_EPS or any(self._vel)
        if not moving:
            return
        duration = min_jerk_duration(move, nominal, self.robot.velocity_limits, cfg.velocity_margin)
        acc = traj.evaluate(t_start)[2] if traj is not None else None
        self._traj = MinJerkTrajectory(t_start, duration, self._q, goal, self._vel, acc)

    def _plan_saccade(self, target: tuple[float, float, float], t_start: float) -> None:
        """Start an eye saccade at ``t_start`` from where the eyes are toward the target (its
        end is re-aimed every tick); it takes at least ``eye_duration_s``."""
        yaw, pitch, _ = self.robot.eyes.look(self._gaze_frame().to_local(target))
        amplitude = math.hypot(yaw - self._eyes[0], pitch - self._eyes[1])
        duration = min_jerk_duration(
            amplitude,
            self.shifts.eye_duration_s,
            self.robot.eye_velocity_limit,
            self.shifts.velocity_margin,
        )
        self._saccade = (t_start, duration, self._eyes)


def _vector(point: object) -> np.ndarray:
    """``point`` as a float64 (3,) array.

    Raises:
        ValueError: it is not a 3D point.
    """
    p = np.asarray(point, dtype=float).reshape(-1)
    if p.shape != (3,):
        raise ValueError(f"target_point must be a 3D point, got shape {p.shape}")
    return p
