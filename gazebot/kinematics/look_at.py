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

import numpy as np

from gazebot.kinematics.eyes import angle_between
from gazebot.kinematics.robot import GazePose, RobotModel

_LIMIT_EPS = 1e-9


@dataclass(frozen=True)
class IKConfig:
    """Solver settings.

    Attributes:
        damping: Levenberg damping lambda (rad^2) of the least-squares step.
        max_iterations: Iteration cap (a warm start typically needs 1-3).
        tolerance: Head pointing error (rad) at which the solve stops.
        max_step: Largest joint change per iteration (rad); keeps far targets stable.
        posture_gain: Null-space pull toward the rest posture per iteration (0..1).
        min_distance: Targets closer than this to the gaze origin (m) have no direction.
        min_step: A step smaller than this (rad) means the head cannot do better.
        posture_off: Reducible pointing error (rad) below which the posture pull stops.
    """

    damping: float = 1e-4
    max_iterations: int = 50
    tolerance: float = 1e-5
    max_step: float = 0.5
    posture_gain: float = 0.1
    min_distance: float = 1e-3
    min_step: float = 1e-9
    posture_off: float = 1e-3


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
    """Core of :func:`pointing_error` on plain lists (rotation rows, origin, Jacobian rows)."""
    # Scalar arithmetic on purpose: for 3-vectors and n <= 4 columns it is several times faster
    # than numpy's per-call overhead, and this runs in every IK iteration.
    px, py, pz = p
    tx, ty, tz = float(target[0]) - px, float(target[1]) - py, float(target[2]) - pz
    dist = math.sqrt(tx * tx + ty * ty + tz * tz)
    ux, uy, uz = tx / dist, ty / dist, tz / dist
    xx, xy, xz = R[0][0], R[1][0], R[2][0]
    wn = math.hypot(xx, xy)  # |up x x|
    if wn > 1e-6:
        b1x, b1y, b1z = -xy / wn, xx / wn, 0.0
    else:  # looking straight up or down: fall back on the display's left axis
        b1x, b1y, b1z = R[0][1], R[1][1], R[2][1]
    b2x, b2y, b2z = xy * b1z - xz * b1y, xz * b1x - xx * b1z, xx * b1y - xy * b1x
    a = ux * xx + uy * xy + uz * xz
    b = ux * b1x + uy * b1y + uz * b1z
    c = ux * b2x + uy * b2y + uz * b2z
    rho2 = max(a * a + b * b, 1e-18)
    rho = math.sqrt(rho2)
    n2 = rho2 + c * c
    d_az: list[float] = []
    d_el: list[float] = []
    for j in range(len(rows[0])):
        vx, vy, vz = rows[0][j], rows[1][j], rows[2][j]
        wx, wy, wz = rows[3][j], rows[4][j], rows[5][j]
        # line of sight: dx = w x x ; target direction: du = -(v - u (u.v)) / dist
        dxx, dxy, dxz = wy * xz - wz * xy, wz * xx - wx * xz, wx * xy - wy * xx
        uv = ux * vx + uy * vy + uz * vz
        dux, duy, duz = (ux * uv - vx) / dist, (uy * uv - vy) / dist, (uz * uv - vz) / dist
        if wn > 1e-6:  # b1 = (up x x) / |up x x|
            dwx, dwy = -dxy, dxx
            bdw = b1x * dwx + b1y * dwy
            db1x, db1y, db1z = (dwx - b1x * bdw) / wn, (dwy - b1y * bdw) / wn, -b1z * bdw / wn
        else:  # b1 turns with the head
            db1x, db1y, db1z = wy * b1z - wz * b1y, wz * b1x - wx * b1z, wx * b1y - wy * b1x
        # b2 = x x b1 -> db2 = dx x b1 + x x db1
        db2x = (dxy * b1z - dxz * b1y) + (xy * db1z - xz * db1y)
        db2y = (dxz * b1x - dxx * b1z) + (xz * db1x - xx * db1z)
        db2z = (dxx * b1y - dxy * b1x) + (xx * db1y - xy * db1x)
        da = xx * dux + xy * duy + xz * duz + ux * dxx + uy * dxy + uz * dxz
        db = b1x * dux + b1y * duy + b1z * duz + ux * db1x + uy * db1y + uz * db1z
        dc = b2x * dux + b2y * duy + b2z * duz + ux * db2x + uy * db2y + uz * db2z
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
        config: Solver settings (defaults: :class:`IKConfig`).

    Returns:
        A :class:`LookAtSolution`; never raises for unreachable targets (joints clamp to limits,
        the eyes take what they can, residuals report the rest). A non-finite target or one at
        the gaze origin returns the warm start unchanged with ``valid=False``.

    Raises:
        ValueError: ``target`` is not a 3-vector, or ``q0`` names unknown joints.
    """
    cfg = config or IKConfig()
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

    lower, upper = robot.lower.tolist(), robot.upper.tolist()
    rest = robot.rest.tolist()
    n = robot.n_head
    lam = cfg.damping
    tol = cfg.tolerance
    tx, ty, tz = (float(v) for v in t)
    qs = q.tolist()
    iterations = 0
    converged = False
    stalled = False
    nudged = False
    # Plain-Python floats on purpose: with n <= 4 joints numpy's per-call overhead would dominate.
    for iterations in range(1, cfg.max_iterations + 1):  # noqa: B007 (reported afterwards)
        R, p, rows = robot.gaze_jacobian_lists(qs)
        dx, dy, dz = tx - p[0], ty - p[1], tz - p[2]
        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
        if dist < cfg.min_distance:
            return _invalid(
                robot, np.array(qs), "target is at the gaze origin: no direction to look"
            )
        cos = (R[0][0] * dx + R[1][0] * dy + R[2][0] * dz) / dist
        if cos >= math.cos(tol):
            converged = True
            break
        e0, e1, r0, r1 = _pointing_error(R, p, rows, t)
        g2 = sum((a * e0 + b * e1) ** 2 for a, b in zip(r0, r1, strict=True))
        if not nudged and g2 < 1e-20 and e0 * e0 + e1 * e1 > 2.0:
            # Looking straight away from the target (a saddle of the error): nudge the first
            # joint that can move so the gradient picks a side.
            for j in range(n):
                if upper[j] - lower[j] > 1e-6:
                    qs[j] = qs[j] + 0.1 if qs[j] + 0.1 <= upper[j] else qs[j] - 0.1
                    nudged = True
                    break
            if nudged:
                continue
        free = list(range(n))
        dq = [0.0] * n
        reducible = 0.0
        for _ in range(n):
            f0 = [r0[j] for j in free]
            f1 = [r1[j] for j in free]
            a11 = sum(v * v for v in f0) + lam
            a12 = sum(v * w for v, w in zip(f0, f1, strict=True))
            a22 = sum(w * w for w in f1) + lam
            det = a11 * a22 - a12 * a12
            i11, i12, i22 = a22 / det, -a12 / det, a11 / det
            # damped pseudo-inverse columns (pinv = Jf^T (Jf Jf^T + lam I)^-1)
            p0 = [v * i11 + w * i12 for v, w in zip(f0, f1, strict=True)]
            p1 = [v * i12 + w * i22 for v, w in zip(f0, f1, strict=True)]
            step = [-(a * e0 + b * e1) for a, b in zip(p0, p1, strict=True)]
            j0 = sum(v * s_ for v, s_ in zip(f0, step, strict=True))
            j1 = sum(w * s_ for w, s_ in zip(f1, step, strict=True))
            reducible = math.hypot(j0, j1)
            # The posture pull only shapes the big first steps; near the best pointing it would
            # keep trading redundant joints and slow the final convergence.
            if reducible > cfg.posture_off and cfg.posture_gain > 0.0:
                y = [cfg.posture_gain * (rest[j] - qs[j]) for j in free]
                y0 = sum(v * w for v, w in zip(f0, y, strict=True))
                y1 = sum(v * w for v, w in zip(f1, y, strict=True))
                # null-space projection: y - pinv (Jf y)
                step = [
                    s_ + yy - (a * y0 + b * y1)
                    for s_, yy, a, b in zip(step, y, p0, p1, strict=True)
                ]
            dq = [0.0] * n
            for j, s_ in zip(free, step, strict=True):
                dq[j] = s_
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
        biggest = max(abs(v) for v in dq)
        scale = cfg.max_step / biggest if biggest > cfg.max_step else 1.0
        q_new = [
            min(max(a + scale * b, lo), hi)
            for a, b, lo, hi in zip(qs, dq, lower, upper, strict=True)
        ]
        if max(abs(a - b) for a, b in zip(q_new, qs, strict=True)) < cfg.min_step:
            stalled = True
            break
        qs = q_new

    q = np.array(qs)
    lower, upper = robot.lower, robot.upper
    pose = robot.gaze_pose(q)
    v = pose.to_local(t)
    residual = angle_between(np.array([1.0, 0.0, 0.0]), v)
    reached = residual <= cfg.tolerance
    converged = converged or stalled or reached
    yaw, pitch, saturated = robot.eyes.look(v)
    total = robot.eyes.residual(yaw, pitch, v)
    at_limit = (q <= lower + 1e-7) | (q >= upper - 1e-7)
    limited = tuple(nm for nm, a in zip(robot.head_joints, at_limit, strict=True) if a)
    clamped = (not reached) and bool(limited)
    message = ""
    if clamped:
        message = f"head joint limit reached ({', '.join(limited)}); the eyes take the rest"
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
        iterations=iterations,
        converged=converged,
        clamped=clamped,
        eyes_saturated=saturated,
        valid=True,
        message=message,
        limited_joints=limited,
    )
