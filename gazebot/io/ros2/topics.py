"""gazebot's ROS 2 topics: name (relative to the namespace, ``/gazebot`` by default, unless
absolute), message type and the largest payload a subscriber decodes, in one table that the
transport and the MCAP recorder share.

Size caps (bytes of CDR) are set per topic from what its messages carry, with room to spare: a
point or a flag under 1 KiB, joint goals and events under 16 KiB, ``/tf`` and ``/joint_states``
of a whole robot under 64 KiB, ``/diagnostics`` of a whole ROS system under 256 KiB, and an eye
frame (a 1024x600 JPEG or PNG) under 4 MiB. A larger message is dropped unread and counted."""

from __future__ import annotations

from dataclasses import dataclass

from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2.codec import MAX_PAYLOAD_BYTES

KIB = 1024

DEFAULT_NAMESPACE = "/gazebot"
#: Frame of the eye state and eye frames: the head's ``gaze`` site.
GAZE_FRAME = "gaze"


@dataclass(frozen=True)
class Topic:
    """One topic: ``name`` (relative, or absolute with a leading ``/``), ROS ``type`` and
    ``max_bytes``, the largest payload its subscribers decode."""

    name: str
    type: str
    max_bytes: int = KIB

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
PHASE = Topic("handover/phase", cv.HANDOVER_PHASE)
DIAGNOSTICS = Topic("/diagnostics", cv.DIAGNOSTIC_ARRAY, 256 * KIB)

# Arm goals from an operator or planner: joint goals (``gripper`` 0..1 among them) and named
# modes (``home``, ``handover``: the robot config's poses; ``resume``: back to the robot's own
# handover controller).
ARM_COMMAND = Topic("arm/command", cv.JOINT_TRAJECTORY, 16 * KIB)
ARM_MODE = Topic("arm/mode", "std_msgs/msg/String")

ALL = (
    GIVER_HAND, RECEIVER_HAND, GIVER_FACE, TF, JOINT_STATES, ROBOT_EVENTS, GRIPPER, LOAD_SHARE,
    HEAD_COMMAND, GAZE_TARGET, EYES, EYE_IMAGE, EVENTS, PHASE, DIAGNOSTICS, ARM_COMMAND, ARM_MODE,
)

_CAPS = {t.name: t.max_bytes for t in ALL}


def max_bytes_of(name: str) -> int:
    """The size cap of gazebot's topic ``name`` (as in the table, before namespace and
    remapping); :data:`~gazebot.io.ros2.codec.MAX_PAYLOAD_BYTES` for a topic not in it."""
    return _CAPS.get(name, MAX_PAYLOAD_BYTES)
