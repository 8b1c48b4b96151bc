"""gazebot's ROS 2 topics: name (relative to the namespace, ``/gazebot`` by default, unless
absolute) and message type, in one table that the transport and the MCAP recorder share."""

from __future__ import annotations

from dataclasses import dataclass

from gazebot.ros2 import convert as cv

DEFAULT_NAMESPACE = "/gazebot"


@dataclass(frozen=True)
class Topic:
    """One topic: ``name`` (relative, or absolute with a leading ``/``) and ROS ``type``."""

    name: str
    type: str

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
TF = Topic("/tf", cv.TF_MESSAGE)

# The robot.
JOINT_STATES = Topic("/joint_states", cv.JOINT_STATE)
ROBOT_EVENTS = Topic("robot/events", cv.HANDOVER_EVENT)
GRIPPER = Topic("robot/gripper", cv.GRIPPER_STATE)
LOAD_SHARE = Topic("robot/load_share", cv.LOAD_SHARE)

# The engine's output.
HEAD_COMMAND = Topic("head/command", cv.JOINT_TRAJECTORY)
GAZE_TARGET = Topic("gaze_target", cv.POINT_STAMPED)
EYES = Topic("eyes/state", cv.EYE_STATE)
EYE_IMAGE = Topic("eyes/image/compressed", cv.COMPRESSED_IMAGE)
EVENTS = Topic("handover/events", cv.HANDOVER_EVENT)
PHASE = Topic("handover/phase", cv.HANDOVER_PHASE)
DIAGNOSTICS = Topic("/diagnostics", cv.DIAGNOSTIC_ARRAY)

# Arm goals from an operator or planner: joint goals (``gripper`` 0..1 among them) and named
# modes (``home``, ``handover``: the robot config's poses; ``resume``: back to the robot's own
# handover controller).
ARM_COMMAND = Topic("arm/command", cv.JOINT_TRAJECTORY)
ARM_MODE = Topic("arm/mode", "std_msgs/msg/String")

ALL = (
    GIVER_HAND, RECEIVER_HAND, GIVER_FACE, TF, JOINT_STATES, ROBOT_EVENTS, GRIPPER, LOAD_SHARE,
    HEAD_COMMAND, GAZE_TARGET, EYES, EYE_IMAGE, EVENTS, PHASE, DIAGNOSTICS, ARM_COMMAND, ARM_MODE,
)
