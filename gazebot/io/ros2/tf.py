"""The head's frames on ``/tf`` and ``/tf_static``, so rviz2 and Foxglove draw the head gazebot
commands and its line of sight.

Frames: one per commanded head joint, ``gazebot/<joint>`` (the joint's frame at the commanded
position, child of the robot's base frame, on ``/tf``; prefixed so it cannot clash with a link
of the robot's own URDF), and ``gaze`` (:data:`~gazebot.io.ros2.topics.GAZE_FRAME`: the head's
gaze site, +x the line of sight), fixed to the joint that carries it, on ``/tf_static``. The
poses come from the robot model gazebot steers by (Pinocchio, its own data: the engine's is not
touched).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from rosbags.typesys.stores import ros2_jazzy as jazzy

from gazebot.core.kinematics.robot import RobotModel
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.topics import GAZE_FRAME

RosTFMessage = jazzy.tf2_msgs__msg__TFMessage
#: Prefix of the frames of gazebot's head joints.
JOINT_PREFIX = "gazebot/"


@dataclass(frozen=True)
class Pose:
    """A frame's pose in its parent: ``position`` (m) and ``rotation`` (3x3, columns x, y, z)."""

    parent: str
    child: str
    position: np.ndarray
    rotation: np.ndarray


def transform_stamped(t: float, pose: Pose) -> cv.RosTransformStamped:
    """``pose`` at time ``t`` as a ``geometry_msgs/TransformStamped``; ``MessageError`` if not
    finite."""
    p = np.asarray(pose.position, dtype=float)
    if p.shape != (3,) or not np.all(np.isfinite(p)) or not np.all(np.isfinite(pose.rotation)):
        raise MessageError(cv.TRANSFORM_STAMPED,
                           f"transform {pose.parent} -> {pose.child} is not finite")
    x, y, z, w = pin.Quaternion(np.asarray(pose.rotation, dtype=float)).coeffs()
    return cv.RosTransformStamped(
        header=cv.header(t, pose.parent), child_frame_id=pose.child,
        transform=cv.RosTransform(
            translation=cv.Vector3(x=float(p[0]), y=float(p[1]), z=float(p[2])),
            rotation=cv.Quaternion(x=float(x), y=float(y), z=float(z), w=float(w))))


def tf_message(t: float, poses: list[Pose]) -> RosTFMessage:
    """``tf2_msgs/TFMessage`` of ``poses`` at time ``t``."""
    return RosTFMessage(transforms=[transform_stamped(t, p) for p in poses])


class HeadFrames:
    """The head's frames of ``robot`` in ``base_frame``.

    Args:
        robot: The robot model (its Pinocchio model is read, never written).
        base_frame: The robot's base frame (``RobotConfig.base_frame``).
    """

    def __init__(self, robot: RobotModel, base_frame: str) -> None:
        self.robot = robot
        self.base_frame = base_frame
        self._data = robot.model.createData()
        self._joint_ids = {n: robot.model.getJointId(n) for n in robot.head_joints}
        gaze = robot.model.frames[robot.gaze_frame_id]
        self._gaze_joint = int(gaze.parentJoint)
        self._gaze_placement = gaze.placement
        # The gaze site's joint is on /tf as well when it is not a commanded head joint.
        names = {jid: n for n, jid in self._joint_ids.items()}
        self._gaze_parent = names.get(self._gaze_joint, robot.model.names[self._gaze_joint])
        self._frames = dict(self._joint_ids)
        self._frames.setdefault(self._gaze_parent, self._gaze_joint)

    def frame_of(self, joint: str) -> str:
        """The ``/tf`` frame name of ``joint``'s frame (``gazebot/<joint>``)."""
        return f"{JOINT_PREFIX}{joint}"

    def static(self) -> list[Pose]:
        """Fixed frames (``/tf_static``): the gaze frame in its joint's frame."""
        M = self._gaze_placement
        return [Pose(self.frame_of(self._gaze_parent), GAZE_FRAME, M.translation.copy(),
                     M.rotation.copy())]

    def moving(self, head: Mapping[str, float]) -> list[Pose]:
        """The head joints' frames (``/tf``) at the head position ``head`` (rad by joint;
        missing joints at rest)."""
        q = self.robot.configuration(self.robot.head_vector(dict(head)))
        pin.forwardKinematics(self.robot.model, self._data, q)
        return [Pose(self.base_frame, self.frame_of(n), self._data.oMi[jid].translation.copy(),
                     self._data.oMi[jid].rotation.copy()) for n, jid in self._frames.items()]

    def gaze_pose(self, head: Mapping[str, float]) -> Pose:
        """The gaze frame in the base frame at ``head`` (for markers)."""
        q = self.robot.configuration(self.robot.head_vector(dict(head)))
        pin.forwardKinematics(self.robot.model, self._data, q)
        M = self._data.oMi[self._gaze_joint] * self._gaze_placement
        return Pose(self.base_frame, GAZE_FRAME, M.translation.copy(), M.rotation.copy())
