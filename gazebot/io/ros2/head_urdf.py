"""A URDF of the head chain gazebot steers, from its Pinocchio model, whose links are the frames
gazebot writes on ``/tf`` and ``/tf_static`` (:mod:`gazebot.io.ros2.tf`): a file that holds
both draws the head in Foxglove's 3D panel or rviz2 without the robot's own description or a
``robot_state_publisher``.

Links: the base frame (root); one per head-chain joint, ``gazebot/<joint>`` (a sphere at the
joint and a bone to the next joint of the chain, or to the gaze origin), attached to the base by
a ``floating`` joint (its pose comes from ``/tf``, where gazebot writes each joint's frame in the
base frame); and ``gaze`` (a display-sized plate and the line of sight along +x), fixed to its
joint as on ``/tf_static``. The robot's other links (arm, torso) are not in it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from gazebot.core.kinematics.robot import RobotModel
from gazebot.io.ros2.tf import JOINT_PREFIX, HeadFrames, Pose

#: Sizes of the drawn parts (m).
JOINT_RADIUS_M = 0.035
BONE_RADIUS_M = 0.015
SIGHT_LENGTH_M = 0.3


def _origin(parent: ET.Element, position: np.ndarray, rotation: np.ndarray) -> None:
    rpy = pin.rpy.matrixToRpy(np.asarray(rotation, dtype=float))
    ET.SubElement(parent, "origin", xyz=" ".join(f"{v + 0.0:.6g}" for v in position),
                  rpy=" ".join(f"{v + 0.0:.6g}" for v in rpy))


def _visual(link: ET.Element, position: np.ndarray, rotation: np.ndarray, shape: str,
            color: str, **size: str) -> None:
    visual = ET.SubElement(link, "visual")
    _origin(visual, position, rotation)
    geometry = ET.SubElement(visual, "geometry")
    ET.SubElement(geometry, shape, attrib=dict(size))
    material = ET.SubElement(visual, "material", name=color)
    ET.SubElement(material, "color", rgba=_COLORS[color])


_COLORS = {"joint": "0.55 0.6 0.65 1", "bone": "0.75 0.78 0.8 1", "display": "0.1 0.1 0.12 1",
           "sight": "1 0.85 0.1 1"}


def _z_to(v: np.ndarray) -> np.ndarray:
    """A rotation whose +z is along ``v`` (a URDF cylinder's axis)."""
    z = v / np.linalg.norm(v)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _bone(link: ET.Element, to: np.ndarray) -> None:
    """A cylinder from the link's origin to ``to`` (in the link's frame)."""
    length = float(np.linalg.norm(to))
    if length > 1e-4:
        _visual(link, to / 2.0, _z_to(to), "cylinder", "bone", radius=f"{BONE_RADIUS_M:g}",
                length=f"{length:.6g}")


def head_chain_urdf(robot: RobotModel, base_frame: str, name: str | None = None) -> str:
    """The URDF text of ``robot``'s head chain (see the module docstring), its root link
    ``base_frame``."""
    frames = HeadFrames(robot, base_frame)
    rest = robot.head_dict(robot.rest)
    moving = frames.moving(rest)
    (gaze,) = frames.static()
    model = robot.model
    gaze_joint = int(model.frames[robot.gaze_frame_id].parentJoint)
    chain = [model.names[j] for j in model.supports[gaze_joint]]
    order = {n: i for i, n in enumerate(chain)}
    by_joint = {p.child.removeprefix(JOINT_PREFIX): p for p in moving}
    joints = sorted(by_joint, key=lambda n: order.get(n, len(chain)))

    root = ET.Element("robot", name=name or f"{robot.name}_head")
    ET.SubElement(root, "link", name=base_frame)
    gaze_in_base = frames.gaze_pose(rest)
    for i, joint in enumerate(joints):
        pose = by_joint[joint]
        link = ET.SubElement(root, "link", name=pose.child)
        _visual(link, np.zeros(3), np.eye(3), "sphere", "joint", radius=f"{JOINT_RADIUS_M:g}")
        nxt: Pose | None = by_joint[joints[i + 1]] if i + 1 < len(joints) else None
        if joint in order:  # a bone along the chain: to the next joint or the gaze origin
            target = nxt.position if nxt is not None else gaze_in_base.position
            _bone(link, pose.rotation.T @ (target - pose.position))
        urdf_joint = ET.SubElement(root, "joint", name=f"{pose.child}_floating",
                                   type="floating")
        ET.SubElement(urdf_joint, "parent", link=base_frame)
        ET.SubElement(urdf_joint, "child", link=pose.child)
        _origin(urdf_joint, pose.position, pose.rotation)
    link = ET.SubElement(root, "link", name=gaze.child)
    _visual(link, np.zeros(3), np.eye(3), "box", "display", size="0.01 0.16 0.1")
    sight = np.array([SIGHT_LENGTH_M, 0.0, 0.0])
    _visual(link, sight / 2.0, _z_to(sight), "cylinder", "sight", radius="0.004",
            length=f"{SIGHT_LENGTH_M:g}")
    fixed = ET.SubElement(root, "joint", name=f"{gaze.child}_fixed", type="fixed")
    ET.SubElement(fixed, "parent", link=gaze.parent)
    ET.SubElement(fixed, "child", link=gaze.child)
    _origin(fixed, gaze.position, gaze.rotation)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode")
