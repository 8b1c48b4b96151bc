"""``ZenohRobotEndpoint``: the robot side of the bus (a simulator node or a real robot's bridge):
publishes tracking, joint states, gripper, load share and robot events; receives head, eye and
arm commands. All as ROS 2 messages on the rmw_zenoh wire (:mod:`gazebot.io.ros2.topics`).

One engine per robot (:mod:`gazebot.io.drivers.ownership`): the endpoint watches the engines'
claims and reports ``competing_engine`` (``info.engines``, the owner first) when more than one
claims the robot; head commands from a publisher it identifies (by the GID in the attachment)
as an engine that does not own the robot are dropped and counted. Head commands from two
publishers within ``compete_window`` s (GIDs in the attachments, claims or not, e.g. a ROS 2
node beside gazebot) are reported as ``competing_engine`` with ``info.publishers`` and
``info.gids``. The heartbeat carries ``info.engines`` and ``info.head_publishers`` and is
``degraded`` while engines compete."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, ClassVar, Generic, TypeVar

from gazebot.core.types import Event, TrackingFrame
from gazebot.io.drivers.ownership import Claim, OwnershipWatch
from gazebot.io.drivers.rmw.attachment import gid_of
from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.rmw.node import Received
from gazebot.io.drivers.zenoh_node import HISTORY_BYTES, ZenohNode, checked
from gazebot.io.ros2 import convert, topics
from gazebot.io.ros2.convert import RosCompressedImage, RosEyeState, RosJointTrajectory, RosString
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.values import (
    ArmCommand,
    BusEvent,
    EyeState,
    JointGoal,
    JointState,
    Json,
    NodeStatus,
    NodeTracking,
)

if TYPE_CHECKING:
    import zenoh

M = TypeVar("M")


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
        compete_window: Head commands from two publishers within this many seconds are
            reported as competing engines.
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
        history_bytes: int = HISTORY_BYTES,
        compete_window: float = 1.0,
    ) -> None:
        super().__init__(session, names, node, owns_session=owns_session,
                         peer_timeout=peer_timeout, clock=clock, max_bytes=max_bytes,
                         history_bytes=history_bytes)
        self.head: Latest[JointGoal] = Latest()
        self.eyes: Latest[EyeState] = Latest()
        self.eye_frame: Latest[RosCompressedImage] = Latest()
        self.arm: Latest[ArmCommand] = Latest()
        self.compete_window = float(compete_window)
        self._compete_lock = threading.Lock()
        self._head_gids: dict[bytes, float] = {}  # publisher GID -> when it last commanded
        self._gid_publishers: dict[bytes, tuple[str, str]] = {}
        self._reported_gids: frozenset[bytes] = frozenset()
        self._reported_claims: frozenset[Claim] = frozenset()
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
        self._head_topic = self.names.resolve(topics.HEAD_COMMAND.name)
        self.owners = ros.declare(OwnershipWatch(session, names, self._on_claims))
        self.announce()

    # -- out -------------------------------------------------------------------------------
    def publish_tracking(self, frame: TrackingFrame) -> TrackingFrame:
        """Publish one tracking sample (each tracked body, the gripper and the load share as
        known, stamped ``frame.t``) and return it."""
        base = self.names.base_frame
        for body, p in convert.tracking_points(frame).items():
            self._point_pubs[body].publish(convert.point_stamped(frame.t, p, base))
        if frame.gripper_closed is not None:
            self._gripper_pub.publish(convert.gripper_state(frame.t, bool(frame.gripper_closed)))
        if frame.load_share is not None:
            self._share_pub.publish(convert.load_share(frame.t, float(frame.load_share)))
        return frame

    def publish_joint_state(self, t: float, position: Mapping[str, float]) -> JointState:
        """Publish the measured joint positions (rad or m, by joint name) on ``/joint_states``."""
        state = JointState(float(t), {k: float(v) for k, v in position.items()})
        self._joints_pub.publish(convert.joint_state(state.t, state.position))
        return state

    def publish_robot_event(self, event: Event) -> BusEvent:
        """Publish an event of the robot's own controller (``robot_reach_started``, ...)."""
        msg = BusEvent.of(event, self.node, time.time(), self.next_event_seq())
        self.publish_event(msg)
        return msg

    # -- competing engines ------------------------------------------------------------------
    def _on_claims(self, claims: list[Claim]) -> None:
        with self._compete_lock:
            report = len(claims) > 1 and frozenset(claims) != self._reported_claims
            self._reported_claims = frozenset(claims) if len(claims) > 1 else frozenset()
        if report:
            self._publish_fault("competing_engine", engines=[str(c) for c in claims],
                                owner=str(claims[0]))

    def _publisher_of(self, gid: bytes) -> tuple[str, str] | None:
        """``(zid, node)`` of the head command publisher with ``gid`` (from the graph)."""
        known = self._gid_publishers.get(gid)
        if known is not None:
            return known
        for e in self.ros.graph.endpoints(self._head_topic, "MP"):
            if gid_of(e.token()) == gid:
                if len(self._gid_publishers) > 1000:  # publishers come and go: stay bounded
                    self._gid_publishers.clear()
                self._gid_publishers[gid] = (e.zid, e.node)
                return e.zid, e.node
        return None

    def _check_head_publisher(self, gid: bytes) -> None:
        """Drop a command from an engine that does not own the robot; report two
        publishers commanding within ``compete_window``."""
        publisher = self._publisher_of(gid)
        owner = self.owners.owner()
        if owner is not None and publisher is not None and publisher != (owner.zid, owner.node):
            raise MessageError(convert.JOINT_TRAJECTORY, f"head command from {publisher[1]} "
                               f"(session {publisher[0]}), which does not own the robot "
                               f"(owner: {owner})")
        now = self.clock()
        with self._compete_lock:
            self._head_gids[gid] = now
            for g, seen in list(self._head_gids.items()):
                if now - seen > self.compete_window:
                    del self._head_gids[g]
            gids = frozenset(self._head_gids)
            report = len(gids) > 1 and not gids <= self._reported_gids
            if report:
                self._reported_gids = gids
            elif len(gids) < 2:
                self._reported_gids = frozenset()
        if report:
            names = []
            for g in sorted(gids):
                who = self._publisher_of(g)
                names.append(f"{who[1]} (session {who[0]})" if who else "unknown")
            self._publish_fault("competing_engine", publishers=names,
                                gids=[g.hex() for g in sorted(gids)])

    def _publish_fault(self, kind: str, **info: Json) -> None:
        last = self.head.peek()
        t = last.t if last is not None else 0.0
        self.publish_event(BusEvent(self.node, "fault", kind, t, t, time.time(), info,
                                    self.next_event_seq()))

    def head_publishers(self) -> int:
        """Publishers that sent head commands within the last ``compete_window`` s."""
        now = self.clock()
        with self._compete_lock:
            return sum(now - seen <= self.compete_window for seen in self._head_gids.values())

    def heartbeat(self, tracking: NodeTracking = "n/a", phase: str | None = None,
                  info: dict[str, Json] | None = None, stopping: bool = False,
                  degraded: bool = False) -> NodeStatus:
        """The node's heartbeat with ``info.engines`` (claims, the owner first) and
        ``info.head_publishers``; ``degraded`` while engines compete."""
        engines = [str(c) for c in self.owners.claims()]
        publishers = self.head_publishers()
        info = {**(info or {}), "engines": engines, "head_publishers": publishers}
        return super().heartbeat(tracking, phase, info, stopping,
                                 degraded or len(engines) > 1 or publishers > 1)

    # -- in --------------------------------------------------------------------------------
    def _on_head(self, ros: RosJointTrajectory, rx: Received) -> None:
        if rx.attachment is not None:
            self._check_head_publisher(rx.attachment.gid)
        goal = convert.trajectory_goal(ros)
        if not goal.time_from_start > 0.0:
            raise MessageError(convert.JOINT_TRAJECTORY, "time_from_start must be > 0, got "
                               f"{goal.time_from_start}")
        self.head.put(goal)

    def _on_eyes(self, ros: RosEyeState, rx: Received) -> None:
        self.eyes.put(convert.eyes_of(ros))

    def _on_frame(self, ros: RosCompressedImage, rx: Received) -> None:
        self.eye_frame.put(ros)  # decoded (and its size checked) where it is shown

    def _on_arm(self, ros: RosJointTrajectory, rx: Received) -> None:
        goal = convert.trajectory_goal(ros)  # a ``gripper`` joint (0..1) may be among them
        self.arm.put(checked(convert.JOINT_TRAJECTORY,
                             lambda: ArmCommand(goal.t, positions=goal.positions)))

    def _on_arm_mode(self, ros: RosString, rx: Received) -> None:
        mode = str(ros.data)
        if mode == "resume":
            cmd = ArmCommand(resume=True)
        elif mode == "home":
            cmd = ArmCommand(pose="home")
        elif mode == "handover":
            cmd = ArmCommand(pose="handover")
        else:
            raise MessageError(convert.STRING,
                               f"arm mode {mode!r}: expected home, handover or resume")
        self.arm.put(cmd)
