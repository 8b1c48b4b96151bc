"""Look-at inverse kinematics: point the head's line of sight at a 3D target.

Damped least squares on the pointing error with Pinocchio frame Jacobians, warm-started, within
joint limits (active set: a joint at a limit that the step pushes further is frozen for that
step). The pointing error is expressed as the eye angles that would close it, ``(yaw, pitch)``
of the target in the gaze frame, so what the head cannot do goes straight to the eyes.
Redundant heads (Jaco-2's two tilts and roll) are pulled toward their rest posture in the
null space of the pointing task.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from gazebot.core.kinematics.robot import GazePose, RobotModel
from gazebot.core.kinematics.robot_config import IKSettings

_LIMIT_EPS = 1e-9


@dataclass(frozen=True)
class IKConfig:
    """Solver settings.

    Attributes:
        damping: Levenberg damping lambda (rad^2) of the least-squares step.
        max_iterations: Iteration cap (a warm start typically needs 1-3; a cold one on the
            shipped robots fewer than 25).
        tolerance: Head pointing error (rad) at which the solve stops.
        max_step: Largest joint change per iteration (rad); keeps far targets stable.
        posture_gain: Null-space pull toward the rest posture per iteration (0..1).
        min_distance: Targets closer than this to the gaze origin (m) have no direction.
        max_distance: Targets farther than this from the base origin (m) are treated as invalid
            (a corrupted sample; squaring such coordinates would overflow).
        min_step: A step smaller than this (rad) means the head cannot do better.
        posture_off: Reducible pointing error (rad) below which the posture pull stops.
        tracking_tolerance: Looser stop (rad) for a target that moved slightly since the last
            solve (see :func:`solve_ik_raw`): the gaze controller uses it while following a
            moving target, where one Gauss-Newton step from the last solution usually meets it.
        goal_deadband: The gaze controller keeps its head goal while a tracked target (one
            that moved without a gaze shift) stays within this angle (rad), seen from the
            goal's gaze origin, of the target the goal was solved for (no saccade under way;
            never with fixed eyes): the eyes, which always aim from the head's current pose,
            take the difference as far as their range allows, so the gaze stays exact where
            they can reach the target and, where it is beyond their reach anyway, misses it by
            at most this angle more than with the goal re-solved.
            A quarter degree keeps the tracker's millimetre noise out of the neck and is below
            a pixel of the drawn eyes; it skips most per-tick solves. 0 re-solves every move.
            (:func:`solve_ik` itself does not use it.)
    """

    damping: float = 1e-4
    max_iterations: int = 25
    tolerance: float = 1e-5
    max_step: float = 0.5
    posture_gain: float = 0.1
    min_distance: float = 1e-3
    max_distance: float = 1e4
    min_step: float = 1e-9
    posture_off: float = 1e-3
    tracking_tolerance: float = 1e-4
    goal_deadband: float = math.radians(0.25)

    @classmethod
    def from_settings(cls, settings: IKSettings) -> IKConfig:
        """The solver settings of a robot YAML's ``ik:`` block (degrees to rad); fields it
        leaves out keep the defaults above."""
        given = settings.model_dump(exclude_none=True)
        values: dict[str, float | int] = {}
        for key, value in given.items():
            if key.endswith("_deg"):
                values[key.removesuffix("_deg")] = math.radians(value)
            else:
                values[key.removesuffix("_m")] = value
        return cls(**values)  # type: ignore[arg-type]


@dataclass(frozen=True)
class LookAtSolution:
    """Result of :func:`solve_ik` (rad).

    Attributes:
        joints: Head joint goals by name (finite, within limits).
        q: The same as a vector in ``robot.head_joints`` order.
        eye_yaw, eye_pitch: Eye angles that take the rest of the way (clipped to the eye range).
        residual: Pointing error of the head alone.
        total_residual: Pointing error after the eyes.
        iterations: Solver iterations used.
        converged: The solver reached the head's best pointing (on target, or no joint can
            turn closer); ``False`` only when the iteration cap stopped it.
        clamped: Head joints stopped at limits before reaching the target.
        eyes_saturated: The eyes hit their range.
        valid: The target was usable (finite, not at the gaze origin); if not, ``q`` is the
            warm start held unchanged, the eyes are centered and residuals are NaN.
        message: Why the head alone is off target or the target unusable (empty when on target).
        limited_joints: Head joints at a position limit.
    """

    joints: dict[str, float]
    q: np.ndarray
    eye_yaw: float
    eye_pitch: float
    residual: float
    total_residual: float
    iterations: int = 0
    converged: bool = False
    clamped: bool = False
    eyes_saturated: bool = False
    valid: bool = True
    message: str = ""
    limited_joints: tuple[str, ...] = field(default_factory=tuple)

    def to_json(self) -> dict:
        """The ``gazebot ik --json`` document (rad; residuals in degrees)."""
        return {
            "joints": dict(self.joints),
            "eyes": {"yaw": self.eye_yaw, "pitch": self.eye_pitch},
            "residual_deg": math.degrees(self.residual),
            "total_residual_deg": math.degrees(self.total_residual),
        }


def pointing_error(
    pose: GazePose, J: np.ndarray, target: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Pointing error ``e = (azimuth, elevation)`` of the target seen from the line of sight, and
    its exact Jacobian ``de/dq``.

    The angles are measured in a roll-free tangent frame of the line of sight ``x``: ``b1`` is
    horizontal (``up x x``, the robot's left when upright), ``b2 = x x b1``. A head roll about the
    line of sight changes neither ``x`` nor the target direction ``u``, so its column is zero and
    the null-space posture pull keeps the display upright; ``atan2`` keeps the error meaningful
    up to 180 deg.

    Args:
        pose: Gaze frame pose.
        J: Its LOCAL_WORLD_ALIGNED frame Jacobian (6 x n: linear, angular).
        target: Target point (base frame).

    Returns:
        ``e`` (2,) in rad and ``de/dq`` (2 x n).
    """
    e0, e1, d_az, d_el = _pointing_error(
        pose.rotation.tolist(), pose.position.tolist(), J.tolist(), target
    )
    return np.array([e0, e1]), np.array([d_az, d_el])


def _pointing_error(
    R: list[list[float]], p: list[float], rows: list[list[float]], target
) -> tuple[float, float, list[float], list[float]]:
    """Core of :func:`pointing_error` on plain lists (rotation rows, extra columns ignored;
    origin; Jacobian rows)."""
    # Scalar arithmetic on purpose: for 3-vectors and n <= 4 columns it is several times faster
    # than numpy's per-call overhead, and this runs in every IK iteration.
    px, py, pz = p
    tx, ty, tz = float(target[0]) - px, float(target[1]) - py, float(target[2]) - pz
    dist = math.sqrt(tx * tx + ty * ty + tz * tz)
    ux, uy, uz = tx / dist, ty / dist, tz / dist
    xx, xy, xz = R[0][0], R[1][0], R[2][0]
    wn = math.hypot(xx, xy)  # |up x x|
    horizontal = wn > 1e-6
    if horizontal:
        b1x, b1y, b1z = -xy / wn, xx / wn, 0.0
        roll = xz / wn
    else:  # looking straight up or down: fall back on the display's left axis
        b1x, b1y, b1z = R[0][1], R[1][1], R[2][1]
        roll = 0.0
    b2x, b2y, b2z = xy * b1z - xz * b1y, xz * b1x - xx * b1z, xx * b1y - xy * b1x
    # The target direction in the tangent frame F = (x, b1, b2).
    a = ux * xx + uy * xy + uz * xz
    b = ux * b1x + uy * b1y + uz * b1z
    c = ux * b2x + uy * b2y + uz * b2z
    rho2 = a * a + b * b
    if rho2 < 1e-18:  # max(rho2, 1e-18) without the call
        rho2 = 1e-18
    rho = math.sqrt(rho2)
    n2 = rho2 + c * c
    d_az: list[float] = []
    d_el: list[float] = []
    for vx, vy, vz, wx, wy, wz in zip(*rows, strict=True):  # columns
        # Origin velocity v and angular velocity w in F. F turns with w about b1 and b2 (that
        # moves the line of sight); about x it turns so that b1 stays horizontal (o0 = o2 xz /
        # |up x x|), or with the head when b1 is the display's axis.
        v0 = vx * xx + vy * xy + vz * xz
        v1 = vx * b1x + vy * b1y + vz * b1z
        v2 = vx * b2x + vy * b2y + vz * b2z
        o1 = wx * b1x + wy * b1y + wz * b1z
        o2 = wx * b2x + wy * b2y + wz * b2z
        o0 = o2 * roll if horizontal else wx * xx + wy * xy + wz * xz
        # d(u in F) = F^T du - o x (u in F), with du = (u (u.v) - v) / dist
        uv = a * v0 + b * v1 + c * v2
        da = (a * uv - v0) / dist - (o1 * c - o2 * b)
        db = (b * uv - v1) / dist - (o2 * a - o0 * c)
        dc = (c * uv - v2) / dist - (o0 * b - o1 * a)
        d_rho = (a * da + b * db) / rho
        d_az.append((a * db - b * da) / rho2)
        d_el.append((rho * dc - c * d_rho) / n2)
    return math.atan2(b, a), math.atan2(c, rho), d_az, d_el


def _invalid(robot: RobotModel, q: np.ndarray, message: str) -> LookAtSolution:
    nan = math.nan
    return LookAtSolution(
        joints=robot.head_dict(q),
        q=q,
        eye_yaw=0.0,
        eye_pitch=0.0,
        residual=nan,
        total_residual=nan,
        valid=False,
        message=message,
    )


class RawSolution(NamedTuple):
    """Result of :func:`solve_ik_raw` in plain floats (rad).

    Attributes:
        q: Head joint goals (``robot.head_joints`` order).
        valid: ``False`` when the target reached the gaze origin (then ``q`` is where the solver
            stopped and the other fields are NaN / 0).
        local: The target in the gaze frame at ``q``.
        residual: Pointing error of the head alone.
        iterations: Solver iterations used.
        converged: On target, or no joint can turn closer (``False``: the iteration cap).
        stalled: No joint can turn closer.
        reached: Within the tolerance.
        frame: Gaze frame rows at ``q`` (see :meth:`RobotModel.gaze_frame_lists`).
        rows: Gaze Jacobian rows at ``q`` if the solver computed them, else ``None``.
    """

    q: list[float]
    valid: bool
    local: tuple[float, float, float]
    residual: float
    iterations: int
    converged: bool
    stalled: bool
    reached: bool
    frame: list[list[float]] | None = None
    rows: list[list[float]] | None = None


def solve_ik_raw(
    robot: RobotModel,
    target: tuple[float, float, float],
    qs: list[float],
    cfg: IKConfig,
    frame: list[list[float]] | None = None,
    rows: list[list[float]] | None = None,
    jacobian: bool = False,
    tracking: bool = False,
) -> RawSolution:
    """The look-at iterations of :func:`solve_ik` on plain floats, for hot paths (the gaze
    controller calls this every tick).

    Args:
        robot: The robot model.
        target: Finite 3D point (base frame).
        qs: Warm start: finite head vector within limits.
        cfg: Solver settings.
        frame, rows: The gaze frame (and Jacobian rows) at ``qs`` when known, e.g. from the
            :class:`RawSolution` that produced ``qs`` (the same arm pose): saves recomputing them.
        jacobian: Also return the Jacobian rows at the solution (to warm-start the next solve).
        tracking: After the first step, stop as soon as the head points within
            ``cfg.tracking_tolerance`` of the target, or its joints can reduce the error by no
            more than that; such a solution reports ``converged`` only if it also meets
            ``cfg.tolerance``. (The first step is always taken, so the goal follows every
            move of the target, as with a full solve.)
    """
    lower, upper, rest = robot.head_bounds
    n = len(qs)
    lam = cfg.damping
    tol = cfg.tolerance
    cos_tol = math.cos(tol)
    loose = cfg.tracking_tolerance if tracking else 0.0
    cos_loose = math.cos(loose) if tracking else 2.0
    gain = cfg.posture_gain
    posture_off = cfg.posture_off
    tx, ty, tz = target
    qs = list(qs)
    iterations = 0
    converged = False
    stalled = False
    nudged = False
    stepped = False  # the looser tracking stop applies only after a step
    # Only the pose is needed to test convergence; the Jacobian is computed for the steps (a
    # warm start on a slowly moving target converges in one step: one Jacobian, two poses).
    if frame is None:
        frame = robot.gaze_frame_lists(qs)
        rows = None
    # A head that holds still (eyes-only gaze mode, or no head joints) takes no step: the eyes do
    # all the pointing from where it is.
    max_iterations = cfg.max_iterations if n and robot.head_moves else 0
    if not max_iterations:
        converged = stalled = True
    # Plain-Python floats on purpose: with n <= 4 joints numpy's per-call overhead would dominate.
    for iterations in range(1, max_iterations + 1):  # noqa: B007 (reported afterwards)
        (r00, _, _, px), (r10, _, _, py), (r20, _, _, pz) = frame
        dx, dy, dz = tx - px, ty - py, tz - pz
        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
        if dist < cfg.min_distance:
            nan = math.nan
            return RawSolution(qs, False, (nan, nan, nan), nan, iterations, False, False, False)
        cos = (r00 * dx + r10 * dy + r20 * dz) / dist
        if cos >= cos_tol:
            converged = True
            break
        if stepped and cos >= cos_loose:
            break
        if rows is None:
            rows = robot.gaze_jacobian_rows(qs)
        e0, e1, r0, r1 = _pointing_error(frame, (px, py, pz), rows, target)
        if not nudged and e0 * e0 + e1 * e1 > 2.0:
            g2 = sum((a * e0 + b * e1) ** 2 for a, b in zip(r0, r1, strict=True))
            if g2 < 1e-20:
                # Looking straight away from the target (a saddle of the error): nudge the first
                # joint that can move so the gradient picks a side.
                for j in range(n):
                    if upper[j] - lower[j] > 1e-6:
                        qs[j] = qs[j] + 0.1 if qs[j] + 0.1 <= upper[j] else qs[j] - 0.1
                        nudged = True
                        break
                if nudged:
                    frame, rows = robot.gaze_frame_lists(qs), None
                    continue
        # The active set below only matters when some joint is at a limit.
        at_limit = False
        for q, lo, hi in zip(qs, lower, upper, strict=True):
            if q <= lo + _LIMIT_EPS or q >= hi - _LIMIT_EPS:
                at_limit = True
                break
        free = range(n)
        dq = [0.0] * n
        reducible = 0.0
        for _ in range(n):
            a11 = a12 = a22 = 0.0
            for j in free:
                v, w = r0[j], r1[j]
                a11 += v * v
                a12 += v * w
                a22 += w * w
            a11 += lam
            a22 += lam
            det = a11 * a22 - a12 * a12
            i11, i12, i22 = a22 / det, -a12 / det, a11 / det
            # damped pseudo-inverse columns (pinv = Jf^T (Jf Jf^T + lam I)^-1)
            p0 = [0.0] * n
            p1 = [0.0] * n
            dq = [0.0] * n
            j0 = j1 = 0.0
            for j in free:
                v, w = r0[j], r1[j]
                a, b = v * i11 + w * i12, v * i12 + w * i22
                p0[j] = a
                p1[j] = b
                s_ = -(a * e0 + b * e1)
                dq[j] = s_
                j0 += v * s_
                j1 += w * s_
            reducible = math.hypot(j0, j1)
            # The posture pull only shapes the big first steps; near the best pointing it would
            # keep trading redundant joints and slow the final convergence.
            if reducible > posture_off and gain > 0.0:
                y = [0.0] * n
                y0 = y1 = 0.0
                for j in free:
                    yj = gain * (rest[j] - qs[j])
                    y[j] = yj
                    y0 += r0[j] * yj
                    y1 += r1[j] * yj
                # null-space projection: y - pinv (Jf y)
                for j in free:
                    dq[j] = dq[j] + y[j] - (p0[j] * y0 + p1[j] * y1)
            if not at_limit:
                break
            blocked = [
                j
                for j in free
                if (qs[j] <= lower[j] + _LIMIT_EPS and dq[j] < 0.0)
                or (qs[j] >= upper[j] - _LIMIT_EPS and dq[j] > 0.0)
            ]
            if not blocked:
                break
            free = [j for j in free if j not in blocked]
            if not free:
                dq = [0.0] * n
                reducible = 0.0
                break
        if reducible <= tol:
            stalled = True  # the joints can no longer turn the gaze closer: the eyes take the rest
            break
        if stepped and reducible <= loose:
            break
        biggest = max(map(abs, dq))
        scale = cfg.max_step / biggest if biggest > cfg.max_step else 1.0
        q_new = []
        moved = 0.0
        for a, b, lo, hi in zip(qs, dq, lower, upper, strict=True):
            x = a + scale * b
            if x < lo:
                x = lo
            if x > hi:
                x = hi
            q_new.append(x)
            d = abs(x - a)
            if d > moved:
                moved = d
        if moved < cfg.min_step:
            stalled = True
            break
        qs = q_new
        stepped = True
        frame, rows = robot.gaze_frame_lists(qs), None

    (r00, r01, r02, px), (r10, r11, r12, py), (r20, r21, r22, pz) = frame
    dx, dy, dz = tx - px, ty - py, tz - pz
    if not max_iterations and math.sqrt(dx * dx + dy * dy + dz * dz) < cfg.min_distance:
        nan = math.nan
        return RawSolution(qs, False, (nan, nan, nan), nan, 0, False, False, False)
    local = (
        r00 * dx + r10 * dy + r20 * dz,
        r01 * dx + r11 * dy + r21 * dz,
        r02 * dx + r12 * dy + r22 * dz,
    )
    # angle_between((1, 0, 0), local) with its zero terms dropped (the same floats).
    residual = math.atan2(math.sqrt(local[2] * local[2] + local[1] * local[1]), local[0])
    reached = residual <= tol
    if jacobian and rows is None:
        rows = robot.gaze_jacobian_rows(qs)
    return RawSolution(
        qs,
        True,
        local,
        residual,
        iterations,
        converged or stalled or reached,
        stalled,
        reached,
        frame,
        rows,
    )


def solve_ik(
    robot: RobotModel,
    target: np.ndarray,
    q0: np.ndarray | dict[str, float] | None = None,
    config: IKConfig | None = None,
) -> LookAtSolution:
    """Head joint goals that point the line of sight at ``target`` (base frame, m).

    Args:
        robot: The robot model.
        target: 3D point in the base frame.
        q0: Warm start (head vector or ``{joint: rad}``); ``None`` starts from the rest posture.
            A non-finite warm start falls back to rest.
        config: Solver settings (default: the robot YAML's ``ik:``).

    Returns:
        A :class:`LookAtSolution`; never raises for unreachable targets (joints clamp to limits,
        the eyes take what they can, residuals report the rest). A non-finite target or one at
        the gaze origin returns the warm start unchanged with ``valid=False``.

    Raises:
        ValueError: ``target`` is not a 3-vector, or ``q0`` names unknown joints.
    """
    cfg = config or IKConfig.from_settings(robot.config.ik)
    t = np.asarray(target, dtype=float).reshape(-1)
    if t.shape != (3,):
        raise ValueError(f"target must be a 3D point, got shape {t.shape}")
    try:
        q = robot.head_vector(q0)
    except ValueError:
        if isinstance(q0, dict) and set(q0) - set(robot.head_joints):
            raise
        q = robot.rest.copy()
    if not np.all(np.isfinite(t)):
        return _invalid(robot, q, "target is not finite: holding the previous head pose")
    if float(np.max(np.abs(t))) > cfg.max_distance:
        return _invalid(
            robot, q, f"target is farther than {cfg.max_distance:g} m: holding the previous pose"
        )

    out = solve_ik_raw(robot, tuple(t.tolist()), q.tolist(), cfg)
    if not out.valid:
        message = "target is at the gaze origin: no direction to look"
        return _invalid(robot, np.array(out.q), message)
    q = np.array(out.q)
    residual, reached, stalled, converged = out.residual, out.reached, out.stalled, out.converged
    v = out.local
    yaw, pitch, saturated = robot.eyes.look(v)
    total = robot.eyes.residual(yaw, pitch, v)
    at_limit = (q <= robot.lower + 1e-7) | (q >= robot.upper - 1e-7)
    limited = tuple(nm for nm, a in zip(robot.head_joints, at_limit, strict=True) if a)
    clamped = (not reached) and bool(limited)
    message = ""
    if clamped:
        message = f"head joint limit reached ({', '.join(limited)}); the eyes take the rest"
    elif not reached and not robot.head_moves:
        why = "no head joints" if not robot.head_joints else f"gaze mode {robot.gaze_mode}"
        message = f"the head holds still ({why}); the eyes take the rest"
    elif not reached and stalled:
        message = "the head cannot turn closer (missing degrees of freedom); the eyes take the rest"
    elif not converged:
        message = "head did not converge within the iteration cap"
    if saturated and total > cfg.tolerance:
        message += ("; " if message else "") + "eyes at their range"
    return LookAtSolution(
        joints=robot.head_dict(q),
        q=q,
        eye_yaw=yaw,
        eye_pitch=pitch,
        residual=residual,
        total_residual=total,
        iterations=out.iterations,
        converged=converged,
        clamped=clamped,
        eyes_saturated=saturated,
        valid=True,
        message=message,
        limited_joints=limited,
    )
