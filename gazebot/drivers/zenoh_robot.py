"""``ZenohRobotEndpoint``: the robot side of the bus (a simulator node or a real robot's bridge):
publishes tracking, joint states, gripper, load share and robot events; receives head, eye and
arm commands. All as ROS 2 messages on the rmw_zenoh wire (:mod:`gazebot.ros2.topics`)."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any, ClassVar, Generic, TypeVar

from gazebot.drivers.payloads import (
    ArmCommandMsg,
    EventMsg,
    EyeFrameMsg,
    EyeStateMsg,
    HeadCommandMsg,
    JointStateMsg,
    Msg,
    TrackingMsg,
)
from gazebot.drivers.rmw.names import Names
from gazebot.drivers.rmw.node import Received
from gazebot.drivers.zenoh_node import ZenohNode, checked, seq_stamp
from gazebot.ros2 import convert, topics
from gazebot.ros2.errors import MessageError
from gazebot.types import Event, TrackingFrame

if TYPE_CHECKING:
    import zenoh

M = TypeVar("M", bound=Msg)


class Latest(Generic[M]):
    """The newest message of one kind; :meth:`take` returns it once."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._msg: M | None = None
        self._fresh = False
        self.count = 0

    def put(self, msg: M) -> None:
        with self._lock:
            self._msg, self._fresh = msg, True
            self.count += 1

    def take(self) -> M | None:
        """The newest message if not taken before, else ``None``."""
        with self._lock:
            if not self._fresh:
                return None
            self._fresh = False
            return self._msg

    def peek(self) -> M | None:
        with self._lock:
            return self._msg


class ZenohRobotEndpoint(ZenohNode):
    """The robot's side of the bus.

    Args:
        session: An open session (closed by :meth:`close` only if ``owns_session``).
        names: Namespace, remapping, domain id and frame names.
        node: This node's name (default ``sim``).
        eye_frames: Subscribe to rendered eye frames. The engine renders frames only while
            someone subscribes, so a robot that draws its eyes from the eye state leaves this off.
    """

    default_node: ClassVar[str] = "sim"

    def __init__(
        self,
        session: zenoh.Session,
        names: Names,
        node: str = "sim",
        *,
        owns_session: bool = False,
        eye_frames: bool = False,
        peer_timeout: float = 2.0,
        clock: Callable[[], float] = time.monotonic,
        max_bytes: dict[str, int] | None = None,
    ) -> None:
        super().__init__(session, names, node, owns_session=owns_session,
                         peer_timeout=peer_timeout, clock=clock, max_bytes=max_bytes)
        self._tracking_seq = 0
        self._joint_seq = 0
        self.head: Latest[HeadCommandMsg] = Latest()
        self.eyes: Latest[EyeStateMsg] = Latest()
        self.eye_frame: Latest[EyeFrameMsg] = Latest()
        self.arm: Latest[ArmCommandMsg] = Latest()
        ros = self.ros
        self._point_pubs = {b: ros.publisher(t.name, t.type) for b, t in topics.TRACKING.items()}
        self._gripper_pub = ros.publisher(topics.GRIPPER.name, topics.GRIPPER.type)
        self._share_pub = ros.publisher(topics.LOAD_SHARE.name, topics.LOAD_SHARE.type)
        self._joints_pub = ros.publisher(topics.JOINT_STATES.name, topics.JOINT_STATES.type)
        ros.subscription(topics.HEAD_COMMAND.name, topics.HEAD_COMMAND.type, self._on_head)
        ros.subscription(topics.EYES.name, topics.EYES.type, self._on_eyes)
        if eye_frames:
            ros.subscription(topics.EYE_IMAGE.name, topics.EYE_IMAGE.type, self._on_frame)
        ros.subscription(topics.ARM_COMMAND.name, topics.ARM_COMMAND.type, self._on_arm)
        ros.subscription(topics.ARM_MODE.name, topics.ARM_MODE.type, self._on_arm_mode)
        self.announce()

    # -- out -------------------------------------------------------------------------------
    def publish_tracking(self, frame: TrackingFrame) -> TrackingMsg:
        """Publish one tracking sample (each tracked body, the gripper and the load share as
        known, stamped ``frame.t``) and return it (numbered)."""
        msg = TrackingMsg.from_frame(frame, self._tracking_seq, time.time())
        self._tracking_seq += 1
        base = self.names.base_frame
        for body, p in convert.tracking_points(frame).items():
            self._point_pubs[body].publish(convert.point_stamped(frame.t, p, base))
        if frame.gripper_closed is not None:
            self._gripper_pub.publish(convert.gripper_state(frame.t, bool(frame.gripper_closed)))
        if frame.load_share is not None:
            self._share_pub.publish(convert.load_share(frame.t, float(frame.load_share)))
        return msg

    def publish_joint_state(self, t: float, position: Mapping[str, float]) -> JointStateMsg:
        """Publish the measured joint positions (rad or m, by joint name) on ``/joint_states``."""
        msg = JointStateMsg(
            seq=self._joint_seq,
            t=float(t),
            stamp=time.time(),
            position={k: float(v) for k, v in position.items()},
        )
        self._joint_seq += 1
        self._joints_pub.publish(convert.joint_state(msg.t, msg.position))
        return msg

    def publish_robot_event(self, event: Event) -> EventMsg:
        """Publish an event of the robot's own controller (``robot_reach_started``, ...)."""
        msg = EventMsg.from_event(event, self.node, self.next_event_seq(), time.time())
        self.publish_event(msg)
        return msg

    # -- in --------------------------------------------------------------------------------
    def _on_head(self, ros: Any, rx: Received) -> None:
        goal, tfs = convert.trajectory_goal(ros)
        last = ros.points[-1]
        names = list(ros.joint_names)
        vel = [float(v) for v in last.velocities]
        velocity = dict(zip(names, vel, strict=True)) if len(vel) == len(names) else {}
        seq, stamp = seq_stamp(rx)
        self.head.put(checked(
            HeadCommandMsg, convert.JOINT_TRAJECTORY, seq=seq, t=convert.stamp_of(ros),
            stamp=stamp, head=goal, velocity=velocity, time_from_start=tfs))

    def _on_eyes(self, ros: Any, rx: Received) -> None:
        eyes = convert.eyes_of(ros)
        seq, stamp = seq_stamp(rx)
        self.eyes.put(checked(
            EyeStateMsg, convert.EYE_STATE, seq=seq, t=eyes.t, stamp=stamp, yaw=eyes.yaw,
            pitch=eyes.pitch, blink=eyes.blink, distance=eyes.distance))

    def _on_frame(self, ros: Any, rx: Received) -> None:
        fmt = "png" if "png" in str(ros.format).lower() else "jpeg"
        seq, stamp = seq_stamp(rx)
        self.eye_frame.put(checked(
            EyeFrameMsg, convert.COMPRESSED_IMAGE, seq=seq, t=convert.stamp_of(ros),
            stamp=stamp, format=fmt, data=bytes(ros.data)))

    def _on_arm(self, ros: Any, rx: Received) -> None:
        goal, _ = convert.trajectory_goal(ros)  # a ``gripper`` joint (0..1) may be among them
        seq, stamp = seq_stamp(rx)
        self.arm.put(checked(ArmCommandMsg, convert.JOINT_TRAJECTORY, seq=seq,
                            t=convert.stamp_of(ros), stamp=stamp, positions=goal))

    def _on_arm_mode(self, ros: Any, rx: Received) -> None:
        mode = str(ros.data)
        seq, stamp = seq_stamp(rx)
        if mode == "resume":
            fields: dict[str, Any] = {"resume": True}
        elif mode in ("home", "handover"):
            fields = {"pose": mode}
        else:
            raise MessageError("std_msgs/msg/String",
                               f"arm mode {mode!r}: expected home, handover or resume")
        self.arm.put(checked(ArmCommandMsg, "std_msgs/msg/String", seq=seq, t=0.0, stamp=stamp,
                            **fields))
