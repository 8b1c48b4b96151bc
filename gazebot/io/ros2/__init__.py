"""ROS 2 messages for gazebot: the type system (ROS 2 Jazzy + ``gazebot_msgs`` from its .msg
files), DDS type names and REP 2011 type hashes, CDR codecs, and the conversions between
gazebot's values and the messages.

* :mod:`.typestore`: the rosbags type system, ``gazebot_msgs`` registered from its .msg files.
* :mod:`.names`: DDS type names and RIHS01 type hashes (:class:`TypeInfo`).
* :mod:`.codec`: CDR bytes <-> messages of one type (:class:`Codec`).
* :mod:`.convert`: gazebot values <-> messages (the one mapping place).
* :mod:`.errors`: :class:`MessageError`, what every bad message raises.
"""

from gazebot.io.ros2.codec import MAX_PAYLOAD_BYTES, Codec
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.names import TypeInfo, dds_type_name, ros_type_name, type_info
from gazebot.io.ros2.typestore import build_typestore, msgs_package_dir, typestore

__all__ = [
    "MAX_PAYLOAD_BYTES",
    "Codec",
    "MessageError",
    "TypeInfo",
    "build_typestore",
    "dds_type_name",
    "msgs_package_dir",
    "ros_type_name",
    "type_info",
    "typestore",
]
