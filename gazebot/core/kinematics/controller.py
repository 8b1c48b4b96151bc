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

import numpy as np

from gazebot.core.kinematics.eyes import angle_of, eye_angles_of, residual_of
from gazebot.core.kinematics.look_at import IKConfig, RawSolution, solve_ik_raw
from gazebot.core.kinematics.robot import RobotModel
from gazebot.core.kinematics.shifts import (
    MINJERK_PEAK,
    GazeShiftConfig,
    MinJerkTrajectory,
    min_jerk,
)
from gazebot.core.types import F64

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
        # The per-tick state is kept in plain floats: with 1-4 joints numpy's per-call overhead
        # would cost more than the arithmetic (this runs at the tracking rate).
        self._names = tuple(robot.head_joints)
        self._lower = robot.lower.tolist()
        self._upper = robot.upper.tolist()
        self._vlim = robot.velocity_limits.tolist()
        self._limits = tuple(zip(self._vlim, self._lower, self._upper, strict=True))
        # The head goal deadband needs eyes that can take the difference (not head-only).
        eyes = robot.eyes
        movable = eyes.yaw_range[0] < eyes.yaw_range[1] or eyes.pitch_range[0] < eyes.pitch_range[1]
        self._deadband = self.ik.goal_deadband if movable else 0.0
        # Per-tick constants read once (both configs are frozen): attribute chains and
        # properties cost more than the arithmetic they feed.
        self._eyes_model = eyes
        self._eye_vlim = robot.eye_velocity_limit
        self._min_distance = self.ik.min_distance
        # Finite even if max_distance is not (see update_raw).
        self._max_abs = min(self.ik.max_distance, sys.float_info.max)
        self._saccade_threshold = self.shifts.saccade_threshold
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
        # Gaze frame at the head command: (head vector, arm revision, frame rows).
        self._frame: tuple[list[float], int, list[list[float]]] | None = None
        # The last IK solution (its q is ``_goal``) and the arm revision it was solved for: its
        # gaze frame and Jacobian seed the next warm start.
        self._solution: tuple[RawSolution, int] | None = None
        # The goal's gaze origin and the unit direction from it to the target the goal was
        # solved for (the deadband's reference), or None.
        self._solved_for: tuple[float, float, float, float, float, float] | None = None
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
        shift = self.update_raw(t, target_point, arm)[4]
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

    def update_raw(
        self,
        t: float,
        target_point: np.ndarray | None,
        arm: Mapping[str, float] | None = None,
    ) -> tuple[list[float], float, float, float, float]:
        """:meth:`update` for the engine's tick: the head command (``robot.head_joints``
        order; a list the controller replaces, never changes), eye yaw, eye pitch, residual and
        shift amplitude, the same floats as the :class:`HeadEyeState` fields (building that
        value and its three dicts costs microseconds the engine does not need)."""
        last = self._t
        # The usual tick (a float time after the last one, a float64 3-vector) without the
        # general path's calls: _advance gives the same for it.
        if type(t) is float and last is not None and last < t < math.inf:
            dt = t - last  # > 0: the difference of two ordered floats
            self._t = t
            self._clock += dt
        else:
            dt = self._advance(t)
        arm_moved = self.robot.set_arm(arm) if arm is not None else False
        p = target_point
        if p is None:
            target = None
        else:
            # ``is`` first: NumPy's float64 dtype is one object (the usual point needs no call).
            if type(p) is not np.ndarray or p.dtype is not F64 or p.shape != (3,):
                p = _vector(p)
            x, y, z = p.tolist()
            # Finite and not absurdly far (a corrupted sample is held like a missing one); a
            # NaN fails every comparison, and the bound is finite even if max_distance is not.
            m = self._max_abs
            target = (x, y, z) if -m <= x <= m and -m <= y <= m and -m <= z <= m else None
        valid = target is not None
        shift = 0.0
        if valid and not (target == self._target and not arm_moved and self._goal_final):
            # Plans start where the last command left off (previous tick) and are evaluated now.
            shift = self._retarget(target, self._clock - dt)

        if dt > 0.0:
            if self._traj is not None:
                self._follow(self._traj.sample_position(self._clock), dt)
            else:
                self._vel = [0.0] * len(self._q)

        # (kept for update(): the engine's tick does not read them)
        self._target_valid = valid
        self._eyes_saturated = self._aim_eyes(dt) if self._target is not None else False
        yaw, pitch = self._eyes
        return self._q, yaw, pitch, self._residual, shift

    def _follow(self, pos: list[float], dt: float) -> None:
        """Move the head command toward the plan's position ``pos`` within the velocity and
        joint limits (a non-finite result keeps the last command)."""
        q_prev = self._q
        if pos == q_prev:
            # At rest on the plan's goal (within the limits): what the loop below gives.
            self._vel = [0.0] * len(q_prev)
            return
        q = []
        vel = []
        finite = True
        for p, a, (v, lo, hi) in zip(pos, q_prev, self._limits, strict=True):
            # Rate limit, then joint limits (comparisons, not min/max calls: this is the
            # hot path; a NaN stays NaN and is caught below).
            step = v * dt
            x = p
            if x < a - step:
                x = a - step
            if x > a + step:
                x = a + step
            if x < lo:
                x = lo
            if x > hi:
                x = hi
            finite = finite and x - x == 0.0  # isfinite(x) without a call (inf - inf is NaN)
            q.append(x)
            vel.append((x - a) / dt)
        if finite:
            self._vel = vel
            self._q = q

    def _aim_eyes(self, dt: float) -> bool:
        """Aim the eyes at the target from the head command (saccade profile, speed limit,
        range); returns whether they are at their range."""
        x, y, z = self._to_local(self._target)  # type: ignore[arg-type]
        if not math.sqrt(x * x + y * y + z * z) >= self._min_distance:
            return False  # too close for a direction (or not a number): the eyes stay
        eyes = self._eyes_model
        yaw, pitch = eye_angles_of(x, y, z)
        yaw, pitch, saturated = eyes.clip(yaw, pitch)  # eyes.look((x, y, z))
        if self._saccade is not None:
            t0, dur, (y0, p0) = self._saccade
            s = min_jerk((self._clock - t0) / dur)
            yaw, pitch = y0 + s * (yaw - y0), p0 + s * (pitch - p0)
            if s >= 1.0:
                self._saccade = None
        limit = self._eye_vlim * dt
        e0, e1 = self._eyes
        # min(max(v, lo), hi) as comparisons (the same result, NaN included)
        lo, hi = e0 - limit, e0 + limit
        if yaw < lo:
            yaw = lo
        if yaw > hi:
            yaw = hi
        lo, hi = e1 - limit, e1 + limit
        if pitch < lo:
            pitch = lo
        if pitch > hi:
            pitch = hi
        yaw, pitch, _ = eyes.clip(yaw, pitch)
        self._eyes = (yaw, pitch)
        self._residual = residual_of(yaw, pitch, x, y, z)  # eyes.residual, floats already
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

    def _gaze_frame(self) -> list[list[float]]:
        """Gaze frame rows at the head command (cached: the eyes of one tick and the re-plan of
        the next both need it)."""
        revision = self.robot.arm_revision
        cached = self._frame
        if cached is not None and cached[1] == revision and cached[0] == self._q:
            return cached[2]
        frame = self.robot.gaze_frame_lists(self._q)
        self._frame = (self._q, revision, frame)
        return frame

    def _to_local(self, point: tuple[float, float, float]) -> tuple[float, float, float]:
        """``point`` (base frame) in the gaze frame at the head command."""
        (r00, r01, r02, px), (r10, r11, r12, py), (r20, r21, r22, pz) = self._gaze_frame()
        dx, dy, dz = point[0] - px, point[1] - py, point[2] - pz
        return (
            r00 * dx + r10 * dy + r20 * dz,
            r01 * dx + r11 * dy + r21 * dz,
            r02 * dx + r12 * dy + r22 * dz,
        )

    def _retarget(self, target: tuple[float, float, float], t_start: float) -> float:
        """Solve IK for a new target and (re)plan neck and eyes from the state at ``t_start``
        (the previous tick); returns the shift amplitude (rad, 0 when tracking)."""
        # The shift's size: from the gaze origin, between the new target and the old one (or
        # the line of sight); floats unpacked once (this runs every tick the target moves).
        (r00, _, _, ox), (r10, _, _, oy), (r20, _, _, oz) = self._gaze_frame()
        nx, ny, nz = target[0] - ox, target[1] - oy, target[2] - oz
        old = self._target
        if old is None:
            amplitude = angle_of(nx, ny, nz, r00, r10, r20)
            new_shift = True
        else:
            amplitude = angle_of(nx, ny, nz, old[0] - ox, old[1] - oy, old[2] - oz)
            new_shift = amplitude > self._saccade_threshold

        revision = self._frame[1]  # type: ignore[index] # (the _gaze_frame call above set it)
        # A target that moved without a gaze shift is followed at the tracking tolerance; a new
        # or unchanged one (e.g. after the arm moved, or to finish a tracked goal) in full.
        tracking = not new_shift and target != old
        last = self._solution
        if last is not None and last[1] == revision and last[0].q is self._goal:
            # The goal deadband: the target is within ``ik.goal_deadband`` of the one the goal
            # was solved for, seen from the goal's gaze origin, with no saccade under way. The
            # eyes take the difference as far as their range allows: where the target is
            # beyond their reach anyway, the gaze misses by at most the deadband's angle more
            # than with the goal re-solved. (``_solved_for`` is None without a deadband, as in
            # ``head-only`` mode.)
            ref = self._solved_for
            if (
                tracking
                and ref is not None
                and self._saccade is None
                and angle_of(
                    ref[3], ref[4], ref[5], target[0] - ref[0], target[1] - ref[1],
                    target[2] - ref[2],
                )
                <= self._deadband
            ):
                # The head goal stays; the eyes, aimed from the head's pose, take the rest. It
                # is solved in full once the target stands still.
                self._target = target
                self._goal_final = False
                return 0.0
            warm_frame, warm_rows = last[0].frame, last[0].rows  # the warm start's kinematics
        else:
            warm_frame = warm_rows = None
        sol = solve_ik_raw(
            self.robot,
            target,
            self._goal,
            self.ik,
            warm_frame,
            warm_rows,
            jacobian=True,
            tracking=tracking,
        )
        if not sol.valid:
            return 0.0  # at the gaze origin: no direction to look
        self._solution = (sol, revision)
        self._target = target
        if self._deadband > 0.0:
            (_, _, _, ox), (_, _, _, oy), (_, _, _, oz) = sol.frame
            dx, dy, dz = target[0] - ox, target[1] - oy, target[2] - oz
            d = math.sqrt(dx * dx + dy * dy + dz * dz)  # > 0: the solve was valid
            self._solved_for = (ox, oy, oz, dx / d, dy / d, dz / d)
        goal = sol.q
        # A solve stopped by the iteration cap or at the tracking tolerance is refined on the
        # next tick even if nothing moved.
        self._goal_final = sol.converged

        # Neck: continue from the current command, its velocity and the plan's acceleration.
        cfg = self.shifts
        traj = self._traj
        q = self._q
        acc = traj.sample(t_start)[2] if traj is not None else (0.0,) * len(q)
        vel = self._vel
        margin = cfg.velocity_margin
        # One pass over the joints: the shortest rest-to-rest minimum-jerk duration within
        # margin * the velocity limits, and the largest move, goal change and speed.
        need = move = goal_change = speed = 0.0
        for g, a, old_g, v, vlim in zip(goal, q, self._goal, vel, self._vlim, strict=True):
            d = abs(g - a)
            if d > move:
                move = d
            d = MINJERK_PEAK * d / (vlim * margin)
            if d > need:
                need = d
            d = abs(g - old_g)
            if d > goal_change:
                goal_change = d
            d = abs(v)
            if d > speed:
                speed = d
        if new_shift:
            duration = max(cfg.neck_duration_s, need)
        else:
            remaining = traj.end_time - t_start if traj is not None else 0.0
            duration = max(remaining, cfg.tracking_duration_s, need)
        if new_shift or goal_change > _REPLAN_EPS or traj is None:
            if move > _REPLAN_EPS or speed > 0.0:
                self._traj = MinJerkTrajectory.of_floats(t_start, duration, q, goal, vel, acc)
        self._goal = goal

        # Eyes: a saccade from where they are now toward the target (re-aimed every tick).
        if new_shift:
            yaw, pitch, _ = self.robot.eyes.look(self._to_local(target))
            amp = math.hypot(yaw - self._eyes[0], pitch - self._eyes[1])
            dur = max(
                cfg.eye_duration_s,
                MINJERK_PEAK * amp / (self.robot.eye_velocity_limit * margin),
            )
            self._saccade = (t_start, dur, self._eyes)
            return float(amplitude)
        return 0.0


def _vector(point: object) -> np.ndarray:
    """``point`` as a float64 (3,) array.

    Raises:
        ValueError: it is not a 3D point.
    """
    p = np.asarray(point, dtype=float)
    if p.shape != (3,):
        p = p.reshape(-1)
        if p.shape != (3,):
            raise ValueError(f"target_point must be a 3D point, got shape {p.shape}")
    return p
