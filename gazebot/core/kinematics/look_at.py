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
from collections.abc import Sequence
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
            solve (see :func:`solve_head`): the gaze controller uses it while following a
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

    The angles are measured in a roll-free tangent frame ``F = (x, b1, b2)`` of the line of sight
    ``x``: ``b1`` is horizontal (``up x x``, the robot's left when upright), ``b2 = x x b1``. A
    head roll about the line of sight changes neither ``x`` nor the target direction ``u``, so
    its column is zero and the null-space posture pull keeps the display upright; ``atan2``
    keeps the error meaningful up to 180 deg.

    Args:
        pose: Gaze frame pose.
        J: Its LOCAL_WORLD_ALIGNED frame Jacobian (6 x n: linear, angular).
        target: Target point (base frame).

    Returns:
        ``e`` (2,) in rad and ``de/dq`` (2 x n).
    """
    x0, x1, x2 = x = pose.rotation[:, 0].tolist()
    offset = np.asarray(target, dtype=float) - pose.position
    dist = math.sqrt(offset @ offset)
    horizontal_norm = math.hypot(x0, x1)  # |up x x|
    horizontal = horizontal_norm > 1e-6
    if horizontal:
        b1 = [-x1 / horizontal_norm, x0 / horizontal_norm, 0.0]
    else:  # looking straight up or down: fall back on the display's left axis
        b1 = pose.rotation[:, 1].tolist()
    b2 = [x1 * b1[2] - x2 * b1[1], x2 * b1[0] - x0 * b1[2], x0 * b1[1] - x1 * b1[0]]  # x cross b1
    F = np.array([x, b1, b2])  # rows: the tangent frame's axes
    u = F @ (offset / dist)  # the target direction in F
    a, b, c = u.tolist()
    rho2 = max(a * a + b * b, 1e-18)
    rho = math.sqrt(rho2)
    n2 = rho2 + c * c
    # Per joint (columns): the gaze origin's velocity V and the angular velocity W of F, both
    # in F. F turns with the head about b1 and b2 (that moves the line of sight); about x it
    # turns so that b1 stays horizontal (W0 = W2 x_z / |up x x|), or with the head when b1 is
    # the display's axis.
    V = F @ J[:3]
    W = F @ J[3:]
    if horizontal:
        W[0] = W[2] * (x2 / horizontal_norm)
    # d(u in F)/dq = F^T du - W x u, with du = (u (u . v) - v) / dist; u x W = [u]x W.
    u_cross = np.array([[0.0, -c, b], [c, 0.0, -a], [-b, a, 0.0]])
    du = (np.outer(u, u @ V) - V) / dist + u_cross @ W
    # The gradient of (atan2(b, a), atan2(c, rho)) with respect to u = (a, b, c).
    angles_by_u = np.array(
        [[-b / rho2, a / rho2, 0.0], [-a * c / (rho * n2), -b * c / (rho * n2), rho / n2]]
    )
    error = np.array([math.atan2(b, a), math.atan2(c, rho)])
    return error, angles_by_u @ du


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


Vector3 = tuple[float, float, float]


class GazeFrame(NamedTuple):
    """The gaze frame in the base frame, as floats: its origin and its x (line of sight), y
    and z axes."""

    origin: Vector3
    x: Vector3
    y: Vector3
    z: Vector3

    @classmethod
    def of_rows(cls, rows: list[list[float]]) -> GazeFrame:
        """From :meth:`RobotModel.gaze_frame_lists` rows ``[R_i0, R_i1, R_i2, p_i]``."""
        (r00, r01, r02, px), (r10, r11, r12, py), (r20, r21, r22, pz) = rows
        return cls((px, py, pz), (r00, r10, r20), (r01, r11, r21), (r02, r12, r22))

    def offset(self, point: Sequence[float]) -> Vector3:
        """``point - origin`` (base frame axes)."""
        ox, oy, oz = self.origin
        return (point[0] - ox, point[1] - oy, point[2] - oz)

    def to_local(self, point: Sequence[float]) -> Vector3:
        """``point`` (base frame) in the gaze frame."""
        d = self.offset(point)
        return (_dot(self.x, d), _dot(self.y, d), _dot(self.z, d))


def _dot(a: Vector3, b: Vector3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@dataclass(frozen=True)
class HeadKinematics:
    """The gaze frame (and, once computed, its Jacobian) at one head vector and arm pose.

    Attributes:
        frame: Gaze frame rows ``[R_i0, R_i1, R_i2, p_i]`` (see
            :meth:`RobotModel.gaze_frame_lists`).
        jacobian: The gaze frame Jacobian (6 x n; linear, angular) or ``None``.
    """

    frame: list[list[float]]
    jacobian: np.ndarray | None = None

    @property
    def pose(self) -> GazePose:
        """The frame as a :class:`GazePose`."""
        rows = np.array(self.frame)
        return GazePose(rows[:, 3], rows[:, :3])


class HeadSolution(NamedTuple):
    """Result of :func:`solve_head` (rad).

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
        kinematics: Gaze frame (and Jacobian, if computed) at ``q``: the next solve's warm start.
    """

    q: list[float]
    valid: bool
    local: tuple[float, float, float]
    residual: float
    iterations: int
    converged: bool
    stalled: bool
    reached: bool
    kinematics: HeadKinematics | None = None


def _unusable(q: list[float], iterations: int) -> HeadSolution:
    """The :class:`HeadSolution` of a target at the gaze origin."""
    nan = math.nan
    return HeadSolution(q, False, (nan, nan, nan), nan, iterations, False, False, False)


def _distance_and_cos(frame: GazeFrame, target: Vector3) -> tuple[float, float]:
    """The target's distance from the gaze origin and the cosine of its angle to the line of
    sight (NaN at the origin)."""
    offset = frame.offset(target)
    dist = math.hypot(*offset)
    return dist, _dot(frame.x, offset) / dist if dist > 0.0 else math.nan


def _nudge_off_saddle(q: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
    """Turn the first joint that can move by 0.1 rad (up, or down at its upper limit): looking
    straight away from the target is a saddle of the error, where the gradient picks no side.
    Returns whether a joint moved (``q`` is changed in place)."""
    movable = np.flatnonzero(upper - lower > 1e-6)
    if movable.size == 0:
        return False
    j = movable[0]
    q[j] = q[j] + 0.1 if q[j] + 0.1 <= upper[j] else q[j] - 0.1
    return True


def _damped_step(
    error: np.ndarray,
    de_dq: np.ndarray,
    q: np.ndarray,
    bounds: tuple[np.ndarray, np.ndarray, np.ndarray],
    cfg: IKConfig,
) -> tuple[np.ndarray, float]:
    """The damped least-squares step ``dq`` toward the target, with the rest posture pulled in
    the null space of the pointing task, and how much of the error the joints can reduce
    (``|de/dq dq|`` of the pointing part, rad).

    Active set: a joint at a limit that the step pushes further is frozen (its column dropped)
    and the step recomputed with the others.
    """
    lower, upper, rest = bounds
    at_lower = q <= lower + _LIMIT_EPS
    at_upper = q >= upper - _LIMIT_EPS
    any_at_limit = bool(at_lower.any() or at_upper.any())
    free = np.ones(q.shape, dtype=bool)
    while free.any():
        J = de_dq * free  # frozen joints' columns are zero
        pinv = J.T @ _inverse_2x2(J @ J.T, cfg.damping)  # J^T (J J^T + damping I)^-1
        dq = -(pinv @ error)
        reducible = math.hypot(*(J @ dq).tolist())
        # The posture pull only shapes the big first steps; near the best pointing it would
        # keep trading redundant joints and slow the final convergence.
        if reducible > cfg.posture_off and cfg.posture_gain > 0.0:
            pull = cfg.posture_gain * (rest - q) * free
            dq += pull - pinv @ (J @ pull)  # its null-space projection
        if not any_at_limit:
            return dq, reducible
        blocked = free & ((at_lower & (dq < 0.0)) | (at_upper & (dq > 0.0)))
        if not blocked.any():
            return dq, reducible
        free &= ~blocked
    return np.zeros_like(q), 0.0


def _inverse_2x2(A: np.ndarray, damping: float) -> np.ndarray:
    """``(A + damping I)^-1`` of a symmetric 2 x 2 ``A`` in closed form."""
    (a11, a12), (_, a22) = A.tolist()
    a11 += damping
    a22 += damping
    det = a11 * a22 - a12 * a12
    return np.array([[a22, -a12], [-a12, a11]]) / det


def _take_step(
    q: np.ndarray, dq: np.ndarray, cfg: IKConfig, lower: np.ndarray, upper: np.ndarray
) -> tuple[np.ndarray, float]:
    """``q + dq`` with ``dq`` scaled down to at most ``cfg.max_step`` per joint, clipped to the
    joint limits, and the largest joint change it made."""
    biggest = float(abs(dq).max())
    scale = cfg.max_step / biggest if biggest > cfg.max_step else 1.0
    q_new = np.minimum(np.maximum(q + scale * dq, lower), upper)
    return q_new, float(abs(q_new - q).max())


def solve_head(
    robot: RobotModel,
    target: tuple[float, float, float],
    q0: Sequence[float],
    cfg: IKConfig,
    warm: HeadKinematics | None = None,
    jacobian: bool = False,
    tracking: bool = False,
) -> HeadSolution:
    """The look-at iterations of :func:`solve_ik` (the gaze controller calls this every tick the
    target moves): Gauss-Newton steps (:func:`_damped_step`) from ``q0`` until the head points
    within ``cfg.tolerance``, no joint can turn it closer, or ``cfg.max_iterations``.

    Args:
        robot: The robot model.
        target: Finite 3D point (base frame).
        q0: Warm start: finite head vector within limits.
        cfg: Solver settings.
        warm: The gaze frame (and Jacobian) at ``q0`` when known, e.g. the
            :attr:`HeadSolution.kinematics` of the solve that produced ``q0`` (the same arm
            pose): saves recomputing them.
        jacobian: Also return the Jacobian at the solution (to warm-start the next solve).
        tracking: After the first step, stop as soon as the head points within
            ``cfg.tracking_tolerance`` of the target, or its joints can reduce the error by no
            more than that; such a solution reports ``converged`` only if it also meets
            ``cfg.tolerance``. (The first step is always taken, so the goal follows every
            move of the target, as with a full solve.)
    """
    lower, upper, _ = bounds = (robot.lower, robot.upper, robot.rest)
    aim = np.array(target, dtype=float)
    q = np.array(q0, dtype=float)
    loose = cfg.tracking_tolerance if tracking else 0.0
    cos_tolerance = math.cos(cfg.tolerance)
    cos_loose = math.cos(loose) if tracking else 2.0  # 2: never
    kin = warm if warm is not None else _kinematics_at(robot, q)
    iterations = 0
    converged = stalled = nudged = False
    stepped = False  # the looser tracking stop applies only after a step
    # A head that holds still (eyes-only gaze mode, or no head joints) takes no step: the eyes do
    # all the pointing from where it is.
    max_iterations = cfg.max_iterations if q.size and robot.head_moves else 0
    if not max_iterations:
        converged = stalled = True
    for iterations in range(1, max_iterations + 1):  # noqa: B007 (reported afterwards)
        dist, cos = _distance_and_cos(GazeFrame.of_rows(kin.frame), target)
        if dist < cfg.min_distance:
            return _unusable(q.tolist(), iterations)
        if cos >= cos_tolerance:
            converged = True
            break
        if stepped and cos >= cos_loose:
            break
        kin = _with_jacobian(robot, kin, q)
        error, de_dq = pointing_error(kin.pose, kin.jacobian, aim)  # type: ignore[arg-type]
        if not nudged and _at_saddle(error, de_dq):
            nudged = _nudge_off_saddle(q, lower, upper)
            if nudged:
                kin = _kinematics_at(robot, q)
                continue
        dq, reducible = _damped_step(error, de_dq, q, bounds, cfg)
        if reducible <= cfg.tolerance:
            stalled = True  # the joints can no longer turn the gaze closer: the eyes take the rest
            break
        if stepped and reducible <= loose:
            break
        q_new, moved = _take_step(q, dq, cfg, lower, upper)
        if moved < cfg.min_step:
            stalled = True
            break
        q, stepped = q_new, True
        kin = _kinematics_at(robot, q)

    frame = GazeFrame.of_rows(kin.frame)
    if not max_iterations and math.hypot(*frame.offset(target)) < cfg.min_distance:
        return _unusable(q.tolist(), 0)
    local = frame.to_local(target)
    residual = math.atan2(math.hypot(local[1], local[2]), local[0])  # from the line of sight
    reached = residual <= cfg.tolerance
    return HeadSolution(
        q=q.tolist(),
        valid=True,
        local=local,
        residual=residual,
        iterations=iterations,
        converged=converged or stalled or reached,
        stalled=stalled,
        reached=reached,
        kinematics=_with_jacobian(robot, kin, q) if jacobian else kin,
    )


def _kinematics_at(robot: RobotModel, q: np.ndarray) -> HeadKinematics:
    """The gaze frame at head vector ``q`` (its Jacobian computed when first needed)."""
    return HeadKinematics(robot.gaze_frame_lists(q.tolist()))


def _with_jacobian(robot: RobotModel, kin: HeadKinematics, q: np.ndarray) -> HeadKinematics:
    """``kin`` (the kinematics at ``q``) with its Jacobian."""
    if kin.jacobian is not None:
        return kin
    return HeadKinematics(kin.frame, np.array(robot.gaze_jacobian_rows(q.tolist())))


def _at_saddle(error: np.ndarray, de_dq: np.ndarray) -> bool:
    """Looking about straight away from the target (an error beyond ~80 deg) where the error's
    gradient vanishes: a saddle, where a Gauss-Newton step picks no side."""
    return bool(error @ error > 2.0 and np.sum((error @ de_dq) ** 2) < 1e-20)


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

    out = solve_head(robot, tuple(t.tolist()), q.tolist(), cfg)
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
