"""How ROS 2 names a message type on the wire: the DDS type name and the REP 2011 type hash.

``geometry_msgs/msg/PointStamped`` is ``geometry_msgs::msg::dds_::PointStamped_`` in DDS and in
rmw_zenoh's key expressions, which end in the type's RIHS01 hash (REP 2011: SHA-256 of the
type description, computed by rosbags from the message definitions).
"""

from __future__ import annotations

from dataclasses import dataclass

from rosbags.typesys.store import Typestore

from gazebot.io.ros2.errors import MessageError


def split_type_name(type_name: str) -> tuple[str, str, str]:
    """``pkg/msg/Name`` -> ``(pkg, "msg", Name)``; :class:`MessageError` for anything else."""
    parts = type_name.split("/")
    if len(parts) != 3 or not all(parts) or parts[1] != "msg":
        raise MessageError(type_name, "expected a ROS 2 message type name pkg/msg/Name")
    return parts[0], parts[1], parts[2]


def dds_type_name(type_name: str) -> str:
    """The DDS type name of ``pkg/msg/Name``: ``pkg::msg::dds_::Name_``."""
    pkg, sub, name = split_type_name(type_name)
    return f"{pkg}::{sub}::dds_::{name}_"


def ros_type_name(dds_name: str) -> str:
    """The ROS type name of a DDS type name (inverse of :func:`dds_type_name`)."""
    parts = dds_name.split("::")
    if len(parts) != 4 or parts[2] != "dds_" or not parts[3].endswith("_") or len(parts[3]) < 2:
        raise MessageError(dds_name, "expected a DDS type name pkg::msg::dds_::Name_")
    return f"{parts[0]}/{parts[1]}/{parts[3][:-1]}"


@dataclass(frozen=True)
class TypeInfo:
    """A message type as ROS 2 names it.

    Attributes:
        name: ROS type name, ``pkg/msg/Name``.
        dds_name: DDS type name, ``pkg::msg::dds_::Name_``.
        hash: REP 2011 type hash, ``RIHS01_<64 hex digits>``.
    """

    name: str
    dds_name: str
    hash: str


def type_info(store: Typestore, type_name: str) -> TypeInfo:
    """Names and hash of ``type_name`` in ``store``; :class:`MessageError` if it is unknown."""
    if type_name not in store.types:
        raise MessageError(type_name, "unknown message type")
    return TypeInfo(type_name, dds_type_name(type_name), store.hash_rihs01(type_name))
