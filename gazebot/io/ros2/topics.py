"""gazebot's ROS 2 topics: name (relative to the namespace, ``/gazebot`` by default, unless
absolute), message type and the largest payload a subscriber decodes, in one table that the
transport and the MCAP recorder share.

Size caps (bytes of CDR) are set per topic from what its messages carry, with room to spare: a
point or a flag under 1 KiB, joint goals and events under 16 KiB, ``/tf`` and ``/joint_states``
of a whole robot under 64 KiB, a robot's URDF under 1 MiB, ``/diagnostics`` of a whole ROS
system under 256 KiB, and an eye frame (a 1024x600 JPEG or PNG) under 4 MiB. A larger message
is dropped unread and counted.

Durability is per topic too: ``volatile`` (ROS 2's default) or ``transient_local`` (latched: a
subscription that starts later still receives the last ``depth`` messages), as
``robot_state_publisher`` publishes ``/robot_description`` and tf2 ``/tf_static``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2.codec import MAX_PAYLOAD_BYTES
from gazebot.io.ros2.markers import MARKER_ARRAY

KIB = 1024

DEFAULT_NAMESPACE = "/gazebot"
#: Frame of the eye state and eye frames: the head's ``gaze`` site.
GAZE_FRAME = "gaze"


Durability = Literal["volatile", "transient_local"]


@dataclass(frozen=True)
class Topic:
    """One topic: ``name`` (relative, or absolute with a leading ``/``), ROS ``type``,
    ``max_bytes``, the largest payload its subscribers decode, its ``durability`` and ``depth``
    (messages kept: keep last ``depth``)."""

    name: str
    type: str
    max_bytes: int = KIB
    durability: Durability = "volatile"
    depth: int = 10

    def resolve(self, namespace: str = DEFAULT_NAMESPACE) -> str:
        """The fully qualified name under ``namespace`` (absolute names stay as they are)."""
        if self.name.startswith("/"):
            return self.name
        ns = namespace.rstrip("/")
        return f"{ns}/{self.name}"


# Tracking in (PoseStamped and /tf are accepted as alternatives by the subscriber).
GIVER_HAND = Topic("tracking/giver_hand", cv.POINT_STAMPED)
RECEIVER_HAND = Topic("tracking/receiver_hand", cv.POINT_STAMPED)
GIVER_FACE = Topic("tracking/giver_face", cv.POINT_STAMPED)
TRACKING = {"giver_hand": GIVER_HAND, "receiver_hand": RECEIVER_HAND, "giver_face": GIVER_FACE}
TF = Topic("/tf", cv.TF_MESSAGE, 64 * KIB)
# Latched, as the ROS 2 stack publishes them: fixed frames and the robot's URDF.
TF_STATIC = Topic("/tf_static", cv.TF_MESSAGE, 64 * KIB, "transient_local", 1)
# A URDF expanded from xacro: tens to hundreds of KiB.
ROBOT_DESCRIPTION = Topic("/robot_description", cv.STRING, 1024 * KIB, "transient_local", 1)

# The robot.
JOINT_STATES = Topic("/joint_states", cv.JOINT_STATE, 64 * KIB)
ROBOT_EVENTS = Topic("robot/events", cv.HANDOVER_EVENT, 16 * KIB)
GRIPPER = Topic("robot/gripper", cv.GRIPPER_STATE)
LOAD_SHARE = Topic("robot/load_share", cv.LOAD_SHARE)

# The engine's output.
HEAD_COMMAND = Topic("head/command", cv.JOINT_TRAJECTORY, 16 * KIB)
GAZE_TARGET = Topic("gaze_target", cv.POINT_STAMPED)
EYES = Topic("eyes/state", cv.EYE_STATE)
EYE_IMAGE = Topic("eyes/image/compressed", cv.COMPRESSED_IMAGE, MAX_PAYLOAD_BYTES)
EVENTS = Topic("handover/events", cv.HANDOVER_EVENT, 16 * KIB)
# Latched: a tool that starts mid-handover learns the phase at once.
PHASE = Topic("handover/phase", cv.HANDOVER_PHASE, KIB, "transient_local", 1)
# For rviz2 and Foxglove: gaze ray and target, hands, face and the phase as text.
MARKERS = Topic("markers", MARKER_ARRAY, 64 * KIB)
DIAGNOSTICS = Topic("/diagnostics", cv.DIAGNOSTIC_ARRAY, 256 * KIB)

# Arm goals from an operator or planner: joint goals (``gripper`` 0..1 among them) and named
# modes (``home``, ``handover``: the robot config's poses; ``resume``: back to the robot's own
# handover controller).
ARM_COMMAND = Topic("arm/command", cv.JOINT_TRAJECTORY, 16 * KIB)
ARM_MODE = Topic("arm/mode", "std_msgs/msg/String")

ALL = (
    GIVER_HAND, RECEIVER_HAND, GIVER_FACE, TF, TF_STATIC, ROBOT_DESCRIPTION, JOINT_STATES,
    ROBOT_EVENTS, GRIPPER, LOAD_SHARE, HEAD_COMMAND, GAZE_TARGET, EYES, EYE_IMAGE, EVENTS, PHASE,
    MARKERS, DIAGNOSTICS, ARM_COMMAND, ARM_MODE,
)

_CAPS = {t.name: t.max_bytes for t in ALL}
_BY_NAME = {t.name: t for t in ALL}


def durability_of(name: str) -> tuple[Durability, int]:
    """The ``(durability, depth)`` of gazebot's topic ``name`` (as in the table);
    ``("volatile", 10)``, ROS 2's default, for a topic not in it."""
    t = _BY_NAME.get(name)
    return (t.durability, t.depth) if t is not None else ("volatile", 10)


def max_bytes_of(name: str) -> int:
    """The size cap of gazebot's topic ``name`` (as in the table, before namespace and
    remapping); :data:`~gazebot.io.ros2.codec.MAX_PAYLOAD_BYTES` for a topic not in it."""
    return _CAPS.get(name, MAX_PAYLOAD_BYTES)
