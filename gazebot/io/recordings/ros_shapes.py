"""The fields of the ROS messages a recording reader uses, as Protocols: a bag or MCAP file brings
its own message definitions (ROS 1 or ROS 2), so the decoded classes are the file's, not
gazebot's typestore's; any class with these fields reads the same."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol


class Time(Protocol):
    @property
    def sec(self) -> int: ...
    @property
    def nanosec(self) -> int: ...


class Header(Protocol):
    @property
    def stamp(self) -> Time: ...


class XYZ(Protocol):
    @property
    def x(self) -> float: ...
    @property
    def y(self) -> float: ...
    @property
    def z(self) -> float: ...


class PointStamped(Protocol):
    @property
    def header(self) -> Header: ...
    @property
    def point(self) -> XYZ: ...


class Pose(Protocol):
    @property
    def position(self) -> XYZ: ...


class PoseStamped(Protocol):
    @property
    def header(self) -> Header: ...
    @property
    def pose(self) -> Pose: ...


class Transform(Protocol):
    @property
    def translation(self) -> XYZ: ...


class TransformStamped(Protocol):
    @property
    def header(self) -> Header: ...
    @property
    def child_frame_id(self) -> str: ...
    @property
    def transform(self) -> Transform: ...


class TFMessage(Protocol):
    @property
    def transforms(self) -> Sequence[TransformStamped]: ...


class GripperState(Protocol):
    @property
    def header(self) -> Header: ...
    @property
    def closed(self) -> bool: ...


class LoadShare(Protocol):
    @property
    def header(self) -> Header: ...
    @property
    def share(self) -> float: ...


def stamp(header: Header) -> float:
    """Seconds of a header's stamp."""
    return float(header.stamp.sec) + 1e-9 * float(header.stamp.nanosec)
