"""The fields of the ROS messages a recording reader uses, as Protocols: a bag or MCAP file brings
its own message definitions (ROS 1 or ROS 2), so the decoded classes are the file's, not
gazebot's typestore's; any class with these fields reads the same."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol


class Time(Protocol):
    """A ROS time stamp (``builtin_interfaces/Time``)."""

    @property
    def sec(self) -> int:
        """Whole seconds."""

    @property
    def nanosec(self) -> int:
        """The fraction of the second past ``sec``, in ns."""


class Header(Protocol):
    """A ``std_msgs/Header``: only its stamp is read."""

    @property
    def stamp(self) -> Time:
        """Time of the message's data."""


class XYZ(Protocol):
    """A point or vector with ``x``, ``y`` and ``z`` (m)."""

    @property
    def x(self) -> float:
        """x coordinate."""

    @property
    def y(self) -> float:
        """y coordinate."""

    @property
    def z(self) -> float:
        """z coordinate."""


class PointStamped(Protocol):
    """A ``geometry_msgs/PointStamped``."""

    @property
    def header(self) -> Header:
        """Stamp of the point."""

    @property
    def point(self) -> XYZ:
        """The point."""


class Pose(Protocol):
    """A ``geometry_msgs/Pose``: only its position is read."""

    @property
    def position(self) -> XYZ:
        """The position."""


class PoseStamped(Protocol):
    """A ``geometry_msgs/PoseStamped``."""

    @property
    def header(self) -> Header:
        """Stamp of the pose."""

    @property
    def pose(self) -> Pose:
        """The pose."""


class Transform(Protocol):
    """A ``geometry_msgs/Transform``: only its translation is read."""

    @property
    def translation(self) -> XYZ:
        """The translation."""


class TransformStamped(Protocol):
    """A ``geometry_msgs/TransformStamped`` (one entry of a ``/tf`` message)."""

    @property
    def header(self) -> Header:
        """Stamp of the transform."""

    @property
    def child_frame_id(self) -> str:
        """The frame the transform places."""

    @property
    def transform(self) -> Transform:
        """The transform."""


class TFMessage(Protocol):
    """A ``tf2_msgs/TFMessage``: the transforms of ``/tf`` or ``/tf_static``."""

    @property
    def transforms(self) -> Sequence[TransformStamped]:
        """The message's transforms."""


class GripperState(Protocol):
    """A ``gazebot_msgs/GripperState``: whether the robot's gripper is closed."""

    @property
    def header(self) -> Header:
        """Time of the measurement."""

    @property
    def closed(self) -> bool:
        """Whether the gripper is closed (on the object)."""


class LoadShare(Protocol):
    """A ``gazebot_msgs/LoadShare``: the share of the object's weight the robot carries."""

    @property
    def header(self) -> Header:
        """Time of the measurement."""

    @property
    def share(self) -> float:
        """0 (the giver holds all of it) .. 1 (the robot holds all of it)."""


def stamp(header: Header) -> float:
    """Seconds of a header's stamp."""
    return float(header.stamp.sec) + 1e-9 * float(header.stamp.nanosec)
