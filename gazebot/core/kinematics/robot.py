"""``RobotModel``: the head's kinematics (Pinocchio, from the robot's MJCF or URDF) plus its YAML
facts.

The Pinocchio model keeps the head joints and the arm joints that carry the head (Sawyer's
``head_pan`` sits on ``right_l0``, so ``right_j0`` turns the head too); every other joint (eye
joints included: they sit after the gaze frame) is locked at its ``arm_home_deg`` or zero
position (``pin.buildReducedModel``). Carrying arm joints are passive: the look-at solver never
moves them, but
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
from gazebot.core.kinematics.eye_joints import (
    EyeChain,
    eye_chains_of,
    eye_joint_positions,
    eye_ranges,
)
from gazebot.core.kinematics.eyes import DisplayEyes
from gazebot.core.kinematics.robot_config import (
    RobotConfig,
    load_robot_config,
    resolve_model_file,
)


def load_full_model(path: Path, kind: str) -> pin.Model:
    """The Pinocchio model of a robot's MJCF or URDF (fixed base).

    Raises:
        ConfigError: Pinocchio cannot parse the file.
    """
    if kind == "urdf":
        import xml.etree.ElementTree as ET

        try:
            root = ET.parse(path).getroot()
        except (ET.ParseError, OSError) as exc:
            raise ConfigError(path, "<urdf>", "a readable URDF (XML)", str(exc)) from exc
        return _build_urdf(root, path)
    try:
        return pin.buildModelFromMJCF(str(path))
    except (RuntimeError, ValueError) as exc:  # Pinocchio's parser errors
        raise ConfigError(path, "<mjcf>", "a robot MJCF Pinocchio can load", str(exc)) from exc


def load_urdf_text(text: str, source: str) -> pin.Model:
    """The Pinocchio model (fixed base) of a URDF given as text, e.g. the ``/robot_description``
    of a running stack; ``source`` names where it came from in errors. Meshes
    (``package://`` URIs) are not read: the kinematics needs none.

    Raises:
        ConfigError: the text is not XML or Pinocchio cannot parse it.
    """
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ConfigError(source, "<urdf>", "a readable URDF (XML)", str(exc)) from exc
    return _build_urdf(root, source)


def _build_urdf(root: object, source: str | Path) -> pin.Model:
    """Pinocchio's model of a parsed URDF (``xml.etree`` root), limit gaps marked."""
    import xml.etree.ElementTree as ET

    assert isinstance(root, ET.Element)
    if root.tag != "robot":
        raise ConfigError(source, "<urdf>", "a URDF (root element <robot>)", f"<{root.tag}>")
    try:
        return pin.buildModelFromXML(_with_limit_gaps_marked(root))
    except (RuntimeError, ValueError) as exc:  # Pinocchio's parser errors
        raise ConfigError(source, "<urdf>", "a robot URDF Pinocchio can load", str(exc)) from exc


def _with_limit_gaps_marked(root: object) -> str:
    """The URDF's text with what urdfdom refuses to parse marked as absent: a ``<limit>``
    without ``velocity`` gets ``velocity="0"`` and a revolute or prismatic joint without
    ``<limit>`` gets an empty one (lower = upper = 0), so the model loads and a head joint that
    lacks a limit is reported by name (with its YAML override, a velocity limit may be left out).

    Raises:
        ConfigError: the file is not readable XML.
    """
    import xml.etree.ElementTree as ET

    assert isinstance(root, ET.Element)
    for joint in root.iter("joint"):
        if joint.get("type") not in ("revolute", "prismatic"):
            continue
        limit = joint.find("limit")
        if limit is None:
            limit = ET.SubElement(joint, "limit", lower="0", upper="0", effort="0")
        limit.attrib.setdefault("velocity", "0")
        limit.attrib.setdefault("effort", "0")
    return ET.tostring(root, encoding="unicode")


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
        mjcf_path: The model file (MJCF or URDF) the model was built from.
        model_kind: ``"mjcf"`` or ``"urdf"``.
        full_model: The Pinocchio model of the whole file (with the gaze frame).
        model: Pinocchio model: head joints + carrying arm joints (others locked).
        data: Pinocchio data for ``model`` (used by the solvers; not thread-safe).
        head_joints: Head joint names, in the order of every head vector.
        lower, upper: Head joint position limits (rad), from the model.
        velocity_limits: Head joint velocity limits (rad/s): the YAML's overrides, else the
            model's. eye_joints: Eye joint names (empty for eyes drawn on a display or no eyes).
        eye_chains: One :class:`EyeChain` per eye whose eyes are joints.
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

    def __init__(self, config: RobotConfig, mjcf_path: Path, full: pin.Model | None = None) -> None:
        self.name = config.name
        self.config = config
        # The model file (MJCF or URDF; the attribute keeps its historical name), or where the
        # model came from when ``full`` is given (a topic).
        self.mjcf_path = Path(mjcf_path)
        self.model_kind = "mjcf" if config.mjcf is not None else "urdf"
        if full is None:
            full = load_full_model(self.mjcf_path, self.model_kind)
        self.head_joints = list(config.head_joints)
        self.arm_joints = list(config.arm_joints)
        self.eye_joints = list(config.eye_joints.names) if config.eye_joints is not None else []
        self.arm_home = {j: math.radians(v) for j, v in config.arm_home_deg.items()}
        self.arm_handover = {j: math.radians(v) for j, v in config.arm_handover_deg.items()}

        for name in self.head_joints + self.eye_joints:
            self._check_revolute(full, name)
        for name in self.arm_joints:
            self._check_revolute(full, name, field="arm_joints")
        gaze_type = self._add_gaze_frame(full, config)
        self.full_model = full

        # Keep the head joints and the arm joints that carry the gaze frame; lock the rest
        # (eye joints and joints outside the head's chain) at their configured or zero position.
        gaze_full = full.frames[full.getFrameId(config.gaze_site, gaze_type)]
        support = [full.names[j] for j in full.supports[gaze_full.parentJoint] if j > 0]
        moved_eyes = sorted(set(support) & set(self.eye_joints))
        if moved_eyes:
            raise ConfigError(
                self.mjcf_path, "eye_joints", "eye joints after the gaze frame's link (they "
                f"would move the gaze frame: {moved_eyes})",
            )
        # Joints that carry the head but are not head joints stay in the model as passive
        # joints (the arm's, moved by :meth:`set_arm`); multi-DOF ones are locked.
        self.passive_joints = [
            n for n in support
            if n not in self.head_joints and full.joints[full.getJointId(n)].nq == 1
        ]
        keep = set(self.head_joints) | set(self.passive_joints)
        q_ref = pin.neutral(full)
        for name, value in self.arm_home.items():
            q_ref[full.joints[full.getJointId(name)].idx_q] = value
        lock = [j for j in range(1, full.njoints) if full.names[j] not in keep]
        self.model = pin.buildReducedModel(full, lock, q_ref) if lock else full
        self.data = self.model.createData()
        self.gaze_frame_id = self.model.getFrameId(config.gaze_site, gaze_type)

        idx = {
            self.model.names[j]: self.model.joints[j].idx_q for j in range(1, self.model.njoints)
        }
        self.head_idx = np.array([idx[n] for n in self.head_joints], dtype=int)
        self.passive_idx = np.array([idx[n] for n in self.passive_joints], dtype=int)
        self.lower = np.array(self.model.lowerPositionLimit[self.head_idx], dtype=float)
        self.upper = np.array(self.model.upperPositionLimit[self.head_idx], dtype=float)
        self._check_position_limits(self.head_joints, self.lower, self.upper)
        self.velocity_limits = np.array(
            [self._velocity_limit(full, n) for n in self.head_joints], dtype=float
        )
        rest = np.radians([config.head_rest_deg.get(n, 0.0) for n in self.head_joints])
        self.rest = np.clip(rest, self.lower, self.upper)
        for arr in (self.lower, self.upper, self.rest, self.velocity_limits):
            arr.flags.writeable = False
        self.gaze_mode = config.gaze_mode
        self.head_moves = bool(self.head_joints) and self.gaze_mode != "eyes-only"
        fixed_eyes = self.gaze_mode == "head-only"
        self.eye_chains: tuple[EyeChain, ...] = ()
        if config.eye_joints is not None:
            self.eye_chains = eye_chains_of(
                full,
                config.eye_joints.yaw,
                config.eye_joints.pitch,
                full.getFrameId(config.gaze_site, gaze_type),
                self.mjcf_path,
            )
            yaw_range, pitch_range = eye_ranges(self.eye_chains, self.mjcf_path)
            eye_speed = min(self._velocity_limit(full, n) for n in self.eye_joints)
        elif config.eyes is not None:
            yaw_range = _radians(config.eyes.yaw_range_deg)
            pitch_range = _radians(config.eyes.pitch_range_deg)
            eye_speed = math.radians(config.eyes.velocity_limit_deg_s)
        else:  # no screen and no eye joints: the head alone points the gaze
            yaw_range, pitch_range, eye_speed = (0.0, 0.0), (0.0, 0.0), math.inf
        self.eye_yaw_range = (0.0, 0.0) if fixed_eyes else yaw_range
        self.eye_pitch_range = (0.0, 0.0) if fixed_eyes else pitch_range
        self.eye_velocity_limit = eye_speed
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
            return cls(name_or_yaml, resolve_model_file(name_or_yaml, None)[0])
        config, path = load_robot_config(name_or_yaml)
        return cls(config, resolve_model_file(config, path)[0])

    @classmethod
    def from_urdf_text(cls, config: RobotConfig, urdf: str,
                       source: str = "/robot_description") -> RobotModel:
        """A robot whose model is the URDF text ``urdf`` (the stack's ``/robot_description``,
        named ``source`` in errors) and whose YAML ``config`` gives what a URDF does not say
        (head joints, gaze frame, display, points); the YAML's ``urdf:``/``mjcf:`` is ignored.

        Raises:
            ConfigError: the URDF is not readable or does not match the YAML.
        """
        config = config.model_copy(update={"mjcf": None, "urdf": source})
        return cls(config, Path(source), load_urdf_text(urdf, source))

    def _check_revolute(self, full: pin.Model, name: str, field: str = "head_joints") -> None:
        kind = self.model_kind.upper()
        if not full.existJointName(name):
            raise ConfigError(self.mjcf_path, field, f"a joint named {name!r} in the {kind}")
        joint = full.joints[full.getJointId(name)]
        if joint.nq != 1 or joint.nv != 1:
            raise ConfigError(self.mjcf_path, name, "a 1-DOF hinge joint")

    def _add_gaze_frame(self, full: pin.Model, config: RobotConfig) -> pin.FrameType:
        """Find the gaze frame (or add it at ``gaze_frame``'s offset); returns its frame type."""
        name = config.gaze_site
        spec = config.gaze_frame
        if spec is None:
            if full.existFrame(name, pin.FrameType.OP_FRAME):
                return pin.FrameType.OP_FRAME
            for frame in full.frames:
                if frame.name == name:
                    return frame.type
            what = "a site" if self.model_kind == "mjcf" else "a link or frame"
            raise ConfigError(self.mjcf_path, "gaze_site", f"{what} named {name!r}")
        if not full.existFrame(spec.link, pin.FrameType.BODY):
            raise ConfigError(self.mjcf_path, "gaze_frame.link", f"a link named {spec.link!r}")
        if full.existFrame(name):
            raise ConfigError(
                self.mjcf_path, "gaze_site", f"a name no frame of the model has ({name!r} does)"
            )
        link = full.frames[full.getFrameId(spec.link, pin.FrameType.BODY)]
        offset = pin.SE3(
            pin.rpy.rpyToMatrix(*np.radians(spec.rpy_deg)), np.asarray(spec.xyz, dtype=float)
        )
        full.addFrame(
            pin.Frame(name, link.parentJoint, link.placement * offset, pin.FrameType.OP_FRAME)
        )
        return pin.FrameType.OP_FRAME

    def _velocity_limit(self, full: pin.Model, name: str) -> float:
        """A joint's velocity limit (rad/s): the YAML's override, else the model's."""
        override = self.config.head_velocity_limits_deg_s.get(name)
        if override is not None:
            return math.radians(override)
        value = float(full.velocityLimit[full.joints[full.getJointId(name)].idx_v])
        if not (math.isfinite(value) and value > 0.0):
            raise ConfigError(
                self.mjcf_path, f"head_velocity_limits_deg_s.{name}",
                f"a velocity limit for joint {name!r} (the model has none: give one in the YAML)",
            )
        return value

    def _check_position_limits(
        self, names: Sequence[str], lower: np.ndarray, upper: np.ndarray
    ) -> None:
        for name, lo, hi in zip(names, lower, upper, strict=True):
            if not (math.isfinite(lo) and math.isfinite(hi) and abs(lo) < 1e6
                    and abs(hi) < 1e6 and lo < hi):
                raise ConfigError(
                    self.mjcf_path, name, "position limits lower < upper in the model", (lo, hi)
                )

    def eye_joint_positions(self, eye_yaw: float, eye_pitch: float) -> dict[str, float]:
        """The eye joint positions (rad, within their limits) that point every eye along the
        direction ``(eye_yaw, eye_pitch)`` of the gaze frame (:func:`eye_direction`); empty for
        eyes drawn on a display."""
        return eye_joint_positions(self.eye_chains, eye_yaw, eye_pitch)

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
        J = self._frame_jacobian()
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
        J = self._frame_jacobian()
        return GazePose(M.translation.copy(), M.rotation.copy()), J[:, self.head_idx]

    def _frame_jacobian(self) -> np.ndarray:
        """The gaze frame Jacobian (6 x nv) from :attr:`data`; always 2-D (Pinocchio hands a
        one-joint model's 6 x 1 matrix back as a vector)."""
        J = pin.getFrameJacobian(self.model, self.data, self.gaze_frame_id, pin.LOCAL_WORLD_ALIGNED)
        return np.asarray(J).reshape(6, self.model.nv)
