"""Tracking a Cartesian end-effector velocity plan on the arm: Pinocchio differential IK (damped
least squares on the gripper frame's 6D twist) within the joint limits and speeds.

The seed's controllers plan the end effector's position only and keep its orientation fixed
(3.3.2: "the robot always has a fixed orientation in our studies"; 4.4.4), so the twist asks for
the planned linear velocity plus a correction toward the planned position, and an angular
velocity that holds the orientation the reach started with.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from gazebot.core.config import ConfigError


class ArmIK:
    """Differential IK for the arm joints of a robot MJCF (the other joints locked).

    Args:
        mjcf: The robot's MJCF file.
        arm_joints: Arm joint names (the order of every joint vector here).
        frame: The end-effector site (the robot's ``gripper_site``).
        max_joint_speed: Joint speed limit (rad/s), one value or one per joint.
        lower, upper: Joint position limits (rad); default: the MJCF's.
        damping: Damped least-squares lambda (m or rad).
        k_pos: Gain of the position correction (1/s); ``k_rot``: of the orientation hold (1/s).
    """

    def __init__(
        self,
        mjcf: str | Path,
        arm_joints: Sequence[str],
        frame: str,
        max_joint_speed: float | np.ndarray,
        lower: np.ndarray | None = None,
        upper: np.ndarray | None = None,
        damping: float = 0.05,
        k_pos: float = 5.0,
        k_rot: float = 3.0,
    ) -> None:
        try:
            full = pin.buildModelFromMJCF(str(mjcf))
        except (RuntimeError, ValueError) as exc:
            raise ConfigError(mjcf, "<mjcf>", "a robot MJCF Pinocchio can load", str(exc)) from exc
        missing = [j for j in arm_joints if not full.existJointName(j)]
        if missing:
            raise ConfigError(mjcf, "arm_joints", f"joints named {missing} in the MJCF")
        if not full.existFrame(frame, pin.FrameType.OP_FRAME):
            raise ConfigError(mjcf, "gripper_site", f"a site named {frame!r}")
        # The full model with the other joints held at zero: a reduced model would drop a site
        # that shares its name with a locked joint (the grippers' ``gripper``).
        self.model = full
        self.data = self.model.createData()
        self.frame_id = self.model.getFrameId(frame, pin.FrameType.OP_FRAME)
        joints = [self.model.joints[self.model.getJointId(j)] for j in arm_joints]
        if any(j.nq != 1 or j.nv != 1 for j in joints):
            raise ConfigError(mjcf, "arm_joints", "one-degree-of-freedom (hinge) arm joints")
        self._idx = np.array([j.idx_q for j in joints], int)  # in the caller's order
        self._vidx = np.array([j.idx_v for j in joints], int)
        n = len(arm_joints)
        self.lower = np.asarray(
            self.model.lowerPositionLimit[self._idx] if lower is None else lower, float
        )
        self.upper = np.asarray(
            self.model.upperPositionLimit[self._idx] if upper is None else upper, float
        )
        self.max_speed = np.broadcast_to(np.asarray(max_joint_speed, float), (n,)).copy()
        if not np.all(self.max_speed > 0):
            raise ValueError("joint speed limits must be positive")
        self.damping, self.k_pos, self.k_rot = float(damping), float(k_pos), float(k_rot)
        self._q = pin.neutral(self.model)

    def _full(self, q: np.ndarray) -> np.ndarray:
        self._q[self._idx] = q
        return self._q

    def pose(self, q: np.ndarray) -> pin.SE3:
        """The end-effector frame's pose in the base frame at arm joints ``q`` (rad)."""
        qf = self._full(np.asarray(q, float))
        pin.framesForwardKinematics(self.model, self.data, qf)
        return self.data.oMf[self.frame_id].copy()

    def step(
        self,
        q: np.ndarray,
        velocity: np.ndarray,
        position: np.ndarray,
        rotation: np.ndarray,
        dt: float,
    ) -> np.ndarray:
        """Joint positions after ``dt`` s that move the end effector at ``velocity`` (m/s)
        toward ``position`` (m) while holding ``rotation`` (3x3), never beyond the joint speed
        limits or the joint ranges. Always finite."""
        q = np.asarray(q, float)
        qf = self._full(q)
        pin.computeJointJacobians(self.model, self.data, qf)
        pin.updateFramePlacements(self.model, self.data)
        oMf = self.data.oMf[self.frame_id]
        J = pin.getFrameJacobian(self.model, self.data, self.frame_id, pin.LOCAL_WORLD_ALIGNED)
        J = J[:, self._vidx]
        twist = np.zeros(6)
        twist[:3] = np.asarray(velocity, float) + self.k_pos * (
            np.asarray(position) - oMf.translation
        )
        twist[3:] = self.k_rot * pin.log3(np.asarray(rotation) @ oMf.rotation.T)
        JJt = J @ J.T + self.damping**2 * np.eye(6)
        qdot = J.T @ np.linalg.solve(JJt, twist)
        if not np.all(np.isfinite(qdot)):
            return q.copy()
        # Scale the whole motion (keeps its direction) so no joint exceeds its speed.
        scale = float(np.max(np.abs(qdot) / self.max_speed))
        if scale > 1.0:
            qdot = qdot / scale
        return np.clip(q + qdot * dt, self.lower, self.upper)
