"""``RobotModel``: the head's kinematics (Pinocchio, from the robot's MJCF) plus its YAML facts.

The Pinocchio model keeps the head joints and the arm joints that carry the head (Sawyer's
``head_pan`` sits on ``right_l0``, so ``right_j0`` turns the head too); every other joint is
locked. Carrying arm joints are passive: the look-at solver never moves them, but
:meth:`RobotModel.set_arm` updates their values when the arm moves.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from gazebot.core.config import ConfigError
from gazebot.core.defaults import DEFAULT_ROBOT
from gazebot.core.kinematics.eyes import DisplayEyes
from gazebot.core.kinematics.robot_config import RobotConfig, load_robot_config, resolve_mjcf


def _radians(degrees: Sequence[float]) -> tuple[float, float]:
    """A ``(min, max)`` range in degrees, in rad."""
    lo, hi = degrees
    return math.radians(lo), math.radians(hi)


@dataclass(frozen=True)
class GazePose:
    """Pose of the ``gaze`` frame in the base frame: origin and rotation (columns = x, y, z)."""

    position: np.ndarray
    rotation: np.ndarray

    @property
    def line_of_sight(self) -> np.ndarray:
        """Unit +x axis of the gaze frame."""
        return self.rotation[:, 0]

    def to_local(self, point: np.ndarray | Sequence[float]) -> np.ndarray:
        """``point`` (base frame) expressed in the gaze frame."""
        return self.rotation.T @ (np.asarray(point, dtype=float) - self.position)


class RobotModel:
    """A robot's head kinematics and configuration.

    Build with :meth:`load`. Angles are rad, lengths m, points in the base frame.

    Attributes:
        name: Robot name (``sawyer``, ``jaco2``).
        config: The validated robot YAML.
        mjcf_path: The MJCF file the model was built from.
        model: Pinocchio model: head joints + carrying arm joints (others locked).
        data: Pinocchio data for ``model`` (used by the solvers; not thread-safe).
        head_joints: Head joint names, in the order of every head vector.
        lower, upper: Head joint position limits (rad), from the MJCF.
        velocity_limits: Head joint velocity limits (rad/s), from the YAML.
        rest: Head rest posture (rad).
        eye_yaw_range, eye_pitch_range: Eye ranges (rad) as ``(min, max)``.
        eye_velocity_limit: Eye speed limit (rad/s).
        eyes: The display eyes (range and speed) as a :class:`DisplayEyes`; in ``head-only``
            mode their range is zero (fixed eyes).
        gaze_mode: ``head-and-eyes``, ``head-only`` or ``eyes-only`` (from the YAML).
        head_moves: Whether the look-at solver may turn the head (``False`` in ``eyes-only``
            mode or without head joints: the head holds still).
        gaze_frame_id: Pinocchio frame id of the ``gaze`` site.
        points: Default points (face, handover_location, rest, ...) as (3,) arrays.
        arm_joints: Arm joint names; ``arm_home``/``arm_handover``: poses (rad) by joint.
    """

    def __init__(self, config: RobotConfig, mjcf_path: Path) -> None:
        self.name = config.name
        self.config = config
        self.mjcf_path = Path(mjcf_path)
        try:
            full = pin.buildModelFromMJCF(str(self.mjcf_path))
        except (RuntimeError, ValueError) as exc:  # Pinocchio's parser errors
            raise ConfigError(
                self.mjcf_path, "<mjcf>", "a robot MJCF Pinocchio can load", str(exc)
            ) from exc
        self.full_model = full
        self.head_joints = list(config.head_joints)
        self.arm_joints = list(config.arm_joints)
        self.arm_home = {j: math.radians(v) for j, v in config.arm_home_deg.items()}
        self.arm_handover = {j: math.radians(v) for j, v in config.arm_handover_deg.items()}

        for name in self.head_joints + self.arm_joints:
            self._check_revolute(full, name)
        if not full.existFrame(config.gaze_site, pin.FrameType.OP_FRAME):
            raise ConfigError(self.mjcf_path, "gaze_site", f"a site named {config.gaze_site!r}")

        # Keep the head joints and the arm joints that carry the gaze frame; lock the rest.
        gaze_full = full.frames[full.getFrameId(config.gaze_site, pin.FrameType.OP_FRAME)]
        support = [full.names[j] for j in full.supports[gaze_full.parentJoint] if j > 0]
        keep = set(self.head_joints) | set(support)
        self.passive_joints = [n for n in support if n not in self.head_joints]
        q_ref = pin.neutral(full)
        for name, value in self.arm_home.items():
            q_ref[full.joints[full.getJointId(name)].idx_q] = value
        lock = [j for j in range(1, full.njoints) if full.names[j] not in keep]
        self.model = pin.buildReducedModel(full, lock, q_ref) if lock else full
        self.data = self.model.createData()
        self.gaze_frame_id = self.model.getFrameId(config.gaze_site, pin.FrameType.OP_FRAME)

        idx = {
            self.model.names[j]: self.model.joints[j].idx_q for j in range(1, self.model.njoints)
        }
        self.head_idx = np.array([idx[n] for n in self.head_joints], dtype=int)
        self.passive_idx = np.array([idx[n] for n in self.passive_joints], dtype=int)
        self.lower = np.array(self.model.lowerPositionLimit[self.head_idx], dtype=float)
        self.upper = np.array(self.model.upperPositionLimit[self.head_idx], dtype=float)
        self.velocity_limits = np.radians(
            [config.head_velocity_limits_deg_s[n] for n in self.head_joints]
        )
        rest = np.radians([config.head_rest_deg.get(n, 0.0) for n in self.head_joints])
        self.rest = np.clip(rest, self.lower, self.upper)
        for arr in (self.lower, self.upper, self.rest, self.velocity_limits):
            arr.flags.writeable = False
        self.gaze_mode = config.gaze_mode
        self.head_moves = bool(self.head_joints) and self.gaze_mode != "eyes-only"
        fixed_eyes = self.gaze_mode == "head-only"
        self.eye_yaw_range = (0.0, 0.0) if fixed_eyes else _radians(config.eyes.yaw_range_deg)
        self.eye_pitch_range = (
            (0.0, 0.0) if fixed_eyes else _radians(config.eyes.pitch_range_deg)
        )
        self.eye_velocity_limit = math.radians(config.eyes.velocity_limit_deg_s)
        self.eyes = DisplayEyes(self.eye_yaw_range, self.eye_pitch_range, self.eye_velocity_limit)
        self.points = {k: np.asarray(v, dtype=float) for k, v in config.points.items()}
        # Full reduced-model configuration: passive joints at the arm's home pose.
        self._q = pin.neutral(self.model)
        for name, i in zip(self.passive_joints, self.passive_idx, strict=True):
            self._q[i] = self.arm_home.get(name, 0.0)
        self._q[self.head_idx] = self.rest
        # A scratch configuration (its head entries are overwritten by every list-based
        # kinematics call) and a counter of arm moves, the key of kept poses.
        self._q_work = self._q.copy()
        self._arm_revision = 0
        # (head vector, arm revision) whose forward kinematics :attr:`data` holds, or None.
        self._kinematics_of: tuple[tuple[float, ...], int] | None = None
        # The last gaze frame :meth:`gaze_frame_lists` computed and its key: the gaze controller
        # computes the frame at the head command and the runtime loop asks for the same one
        # (the vergence distance) in the same tick.
        self._last_frame: tuple[tuple[tuple[float, ...], int], list[list[float]]] | None = None

    @classmethod
    def load(cls, name_or_yaml: str | Path | RobotConfig = DEFAULT_ROBOT) -> RobotModel:
        """Load a robot by name (``configs/robots/<name>.yaml``), YAML path or config.

        Raises:
            FileNotFoundError: unknown robot or missing file.
            ConfigError: malformed YAML or an MJCF that does not match it.
        """
        if isinstance(name_or_yaml, RobotConfig):
            return cls(name_or_yaml, resolve_mjcf(name_or_yaml, None))
        config, path = load_robot_config(name_or_yaml)
        return cls(config, resolve_mjcf(config, path))

    def _check_revolute(self, full: pin.Model, name: str) -> None:
        if not full.existJointName(name):
            raise ConfigError(self.mjcf_path, "joints", f"a joint named {name!r} in the MJCF")
        joint = full.joints[full.getJointId(name)]
        if joint.nq != 1 or joint.nv != 1:
            raise ConfigError(self.mjcf_path, name, "a 1-DOF hinge joint")

    # --- head vectors --------------------------------------------------------------------------
    @property
    def n_head(self) -> int:
        """Number of head joints."""
        return len(self.head_joints)

    def head_dict(self, q: np.ndarray) -> dict[str, float]:
        """Head vector -> ``{joint: rad}``."""
        return {n: float(v) for n, v in zip(self.head_joints, q, strict=True)}

    def head_vector(self, head: Mapping[str, float] | np.ndarray | None) -> np.ndarray:
        """A clamped head vector from ``{joint: rad}`` (missing joints at rest), a vector, or
        ``None`` (the rest posture).

        Raises:
            ValueError: unknown joint names, wrong length or non-finite values.
        """
        if head is None:
            return self.rest.copy()
        if isinstance(head, Mapping):
            unknown = set(head) - set(self.head_joints)
            if unknown:
                raise ValueError(
                    f"unknown head joints {sorted(unknown)} (known {self.head_joints})"
                )
            q = np.array(
                [float(head.get(n, r)) for n, r in zip(self.head_joints, self.rest, strict=True)]
            )
        else:
            q = np.asarray(head, dtype=float).reshape(-1)
            if q.shape != (self.n_head,):
                raise ValueError(f"expected {self.n_head} head joint values, got {q.shape}")
        if not np.all(np.isfinite(q)):
            raise ValueError(f"head joint values must be finite, got {q}")
        return self.clamp(q)

    def clamp(self, q: np.ndarray) -> np.ndarray:
        """Clip a head vector into the joint limits."""
        return np.clip(q, self.lower, self.upper)

    # --- arm ----------------------------------------------------------------------------------
    def set_arm(self, joints: Mapping[str, float]) -> bool:
        """Update the arm joints that carry the head (others are ignored; non-finite skipped).

        Returns whether the head's carrying joints moved (then gaze goals need a new solve).
        """
        moved = False
        for name, i in zip(self.passive_joints, self.passive_idx, strict=True):
            value = joints.get(name)
            if value is not None and math.isfinite(value) and float(value) != self._q[i]:
                self._q[i] = float(value)
                self._q_work[i] = float(value)
                moved = True
        if moved:
            self._arm_revision += 1
        return moved

    @property
    def arm_revision(self) -> int:
        """Counts the :meth:`set_arm` calls that moved the head's carrying joints (a cache key
        for gaze poses)."""
        return self._arm_revision

    def configuration(self, q_head: np.ndarray) -> np.ndarray:
        """The Pinocchio configuration of :attr:`model` for head vector ``q_head``."""
        q = self._q.copy()
        q[self.head_idx] = q_head
        return q

    # --- kinematics ---------------------------------------------------------------------------
    def gaze_pose(self, q_head: np.ndarray) -> GazePose:
        """Pose of the gaze frame for head vector ``q_head``."""
        self._kinematics_of = None
        pin.forwardKinematics(self.model, self.data, self.configuration(q_head))
        M = pin.updateFramePlacement(self.model, self.data, self.gaze_frame_id)
        return GazePose(M.translation.copy(), M.rotation.copy())

    def gaze_frame_lists(self, q_head: Sequence[float]) -> list[list[float]]:
        """Gaze frame pose for head vector ``q_head`` as plain lists: three rows ``[R_i0, R_i1,
        R_i2, p_i]`` (rotation columns = x, y, z; origin ``p``).

        The last frame is kept and returned again for the same head vector and arm pose (the
        same list: callers must not change it): the gaze controller computes the frame at the
        head command and the runtime loop asks for it again in the same tick.

        Raises:
            ValueError: ``q_head`` has not one value per head joint.
        """
        key = (tuple(q_head), self._arm_revision)
        last = self._last_frame
        if last is not None and last[0] == key:
            return last[1]
        q = self._q_work
        if len(key[0]) != self.n_head:
            raise ValueError(f"expected {self.n_head} head joint values, got {len(key[0])}")
        q[self.head_idx] = key[0]
        pin.forwardKinematics(self.model, self.data, q)
        M = pin.updateFramePlacement(self.model, self.data, self.gaze_frame_id)
        self._kinematics_of = key
        rows = M.homogeneous[:3].tolist()
        self._last_frame = (key, rows)
        return rows

    def gaze_jacobian_rows(self, q_head: Sequence[float]) -> list[list[float]]:
        """The 6 rows (linear, angular; LOCAL_WORLD_ALIGNED) of the gaze frame Jacobian over the
        head joints at ``q_head``.

        When :attr:`data` already holds the forward kinematics of ``q_head`` (the last call was
        :meth:`gaze_frame_lists` at the same head vector and arm pose) they are reused; any other
        call order recomputes them, so results never depend on which call came before.
        """
        if self._kinematics_of == (tuple(q_head), self._arm_revision):
            pin.computeJointJacobians(self.model, self.data)
        else:
            q = self._q_work
            q[self.head_idx] = q_head
            pin.computeJointJacobians(self.model, self.data, q)
            self._kinematics_of = (tuple(q_head), self._arm_revision)
        J = pin.getFrameJacobian(self.model, self.data, self.gaze_frame_id, pin.LOCAL_WORLD_ALIGNED)
        return J[:, self.head_idx].tolist()

    def gaze_jacobian(self, q_head: np.ndarray) -> tuple[GazePose, np.ndarray]:
        """Gaze pose and its frame Jacobian (6 x n_head) in LOCAL_WORLD_ALIGNED: linear velocity
        of the gaze origin then angular velocity, both in base-frame axes."""
        q = self.configuration(q_head)
        self._kinematics_of = None
        # computeJointJacobians runs the forward kinematics too (data.oMi), so the frame placement
        # and its Jacobian come from the same configuration.
        pin.computeJointJacobians(self.model, self.data, q)
        M = pin.updateFramePlacement(self.model, self.data, self.gaze_frame_id)
        J = pin.getFrameJacobian(self.model, self.data, self.gaze_frame_id, pin.LOCAL_WORLD_ALIGNED)
        return GazePose(M.translation.copy(), M.rotation.copy()), J[:, self.head_idx]
