"""``ZenohRobotEndpoint``: the robot side of the bus (a simulator node or a real robot's bridge):
publishes tracking, joint states, gripper, load share and robot events; receives head, eye and
arm commands. All as ROS 2 messages on the rmw_zenoh wire (:mod:`gazebot.io.ros2.topics`).

One engine per robot (:mod:`gazebot.io.drivers.ownership`): the endpoint watches the engines'
claims, settles on one owner (a later claim never pre-empts a live owner; a claim whose engine
is not in the ROS graph never owns) and reports ``competing_engine`` (``info.engines``, the
owner first) when more than one claims the robot.

Identity on every command (issue 30): a head, eye or arm command is applied only when its
attachment's GID is the GID of a publisher of that topic alive in the ROS graph (its liveliness
token), that publisher is the owner's node (same session and name) and its sequence number
goes forward. Anything else (no attachment, a GID no live publisher announced, another node, a
GID carrying two streams: :mod:`~gazebot.io.drivers.streams`) is dropped, counted by topic
(:meth:`ZenohRobotEndpoint.unidentified`) and reported as a ``unidentified_command`` fault
(rate-limited). On an open bus this is all that can be checked: an attacker who copies the
owner's GID and stays ahead of its sequence numbers has one command obeyed before the owner's
next one shows the copy (then both are refused while it lasts); to rule that out takes the
authenticated bus (``gazebot bus init``, docs/bus.md), where only the engine's certificate may
publish commands at all.

Head commands from two publishers within ``compete_window`` s (GIDs in the attachments, e.g. a
ROS 2 node beside gazebot) are reported as ``competing_engine`` with ``info.publishers`` and
``info.gids``. The heartbeat carries ``info.engines``, ``info.head_publishers`` and
``info.unidentified_commands`` and is ``degraded`` while engines compete."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, ClassVar, Generic, NoReturn, TypeVar, cast

from gazebot.core.types import Event, TrackingFrame
from gazebot.io.drivers.bounds import check_trajectory
from gazebot.io.drivers.ownership import Claim, OwnershipWatch
from gazebot.io.drivers.rmw.attachment import gid_of
from gazebot.io.drivers.rmw.graph import Entity
from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.rmw.node import Received
from gazebot.io.drivers.streams import SequenceGuard
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
        """Keep ``msg`` as the newest, not yet taken."""
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
        """The newest message, taken or not (``None`` before the first)."""
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
        self._unidentified: dict[str, int] = {}  # topic -> commands dropped as unidentified
        self._unidentified_reported: dict[str, float] = {}  # topic -> when last reported
        self._streams = SequenceGuard(compete_window, clock)
        ros = self.ros
        self._point_pubs = {b: ros.publisher(t.name, t.type) for b, t in topics.TRACKING.items()}
        self._gripper_pub = ros.publisher(topics.GRIPPER.name, topics.GRIPPER.type)
        self._share_pub = ros.publisher(topics.LOAD_SHARE.name, topics.LOAD_SHARE.type)
        self._joints_pub = ros.publisher(topics.JOINT_STATES.name, topics.JOINT_STATES.type)
        # Commands arrive raw: who sent them and their element counts are checked before
        # they are decoded.
        self._trajectory = ros.codec(topics.HEAD_COMMAND.type,
                                     names.resolve(topics.HEAD_COMMAND.name),
                                     topics.HEAD_COMMAND.name)
        ros.subscription(topics.HEAD_COMMAND.name, topics.HEAD_COMMAND.type, self._on_head,
                         raw=True)
        ros.subscription(topics.EYES.name, topics.EYES.type, self._on_eyes)
        if eye_frames:
            ros.subscription(topics.EYE_IMAGE.name, topics.EYE_IMAGE.type, self._on_frame)
        ros.subscription(topics.ARM_COMMAND.name, topics.ARM_COMMAND.type, self._on_arm,
                         raw=True)
        ros.subscription(topics.ARM_MODE.name, topics.ARM_MODE.type, self._on_arm_mode)
        self._head_topic = self.names.resolve(topics.HEAD_COMMAND.name)
        self.owners = ros.declare(OwnershipWatch(session, names, self._on_claims,
                                                 graph=ros.graph))
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
            ordered = self.owners.claims()  # the owner first (not the earliest stated start)
            owner = self.owners.owner()
            self._publish_fault("competing_engine", engines=[str(c) for c in ordered],
                                owner=str(owner) if owner is not None else None,
                                forged=[str(c) for c in self.owners.forged()])

    def _publisher_of(self, gid: bytes, topic: str | None = None) -> tuple[str, str] | None:
        """``(zid, node)`` of the live publisher of ``topic`` (default: head commands) whose
        liveliness token hashes to ``gid``, from the graph."""
        topic = topic or self._head_topic
        with self._compete_lock:
            known = self._gid_publishers.get(gid)
        if known is not None:
            return known
        for e in self.ros.graph.endpoints(topic, "MP"):
            if gid_of(e.token()) == gid:
                with self._compete_lock:
                    self._gid_publishers[gid] = (e.zid, e.node)
                return e.zid, e.node
        return None

    def _on_graph(self, entity: Entity, alive: bool) -> None:
        super()._on_graph(entity, alive)
        if entity.kind == "MP" and not alive:
            # A publisher gone: its GID identifies nothing any more.
            gid = gid_of(entity.token())
            with self._compete_lock:
                self._gid_publishers.pop(gid, None)
            self._streams.forget(gid)

    def _identify(self, rx: Received, what: str) -> tuple[str, str] | None:
        """Drop (raise :class:`MessageError`, counted and reported as
        ``unidentified_command``) a command not from the owner's live publisher of the topic;
        returns the publisher, ``None`` when the publisher is identified but no owner is."""
        att = rx.attachment
        if att is None:
            self._unidentified_drop(rx, what, "no attachment: the publisher cannot be identified")
        publisher = self._publisher_of(att.gid, rx.topic)
        if publisher is None:
            self._unidentified_drop(rx, what, f"GID {att.gid.hex()} is announced by no live "
                                    f"publisher of {rx.topic}")
        why = self._streams.check(att.gid, att.sequence_number)
        if why is not None:
            self._publish_fault("competing_engine", copied_gid=att.gid.hex(), topic=rx.topic,
                                publishers=[f"{publisher[1]} (session {publisher[0]})"])
            self._unidentified_drop(rx, what, f"{why} (of {publisher[1]})")
        owner = self.owners.owner()
        if owner is None:
            self._unidentified_drop(rx, what, f"from {publisher[1]} (session {publisher[0]}), "
                                    "but no engine owns the robot")
        if publisher != (owner.zid, owner.node):
            self._unidentified_drop(rx, what, f"from {publisher[1]} (session {publisher[0]}), "
                                    f"which does not own the robot (owner: {owner})")
        return publisher

    def _unidentified_drop(self, rx: Received, what: str, reason: str) -> NoReturn:
        now = self.clock()
        with self._compete_lock:
            n = self._unidentified[rx.topic] = self._unidentified.get(rx.topic, 0) + 1
            last = self._unidentified_reported.get(rx.topic)
            report = last is None or now - last > self.compete_window
            if report:
                self._unidentified_reported[rx.topic] = now
        if report:  # once per topic and window: a flood cannot flood the events
            self._publish_fault("unidentified_command", topic=rx.topic, reason=reason,
                                count=n)
        raise MessageError(what, f"unidentified command dropped: {reason}")

    def unidentified(self) -> dict[str, int]:
        """Commands dropped as unidentified, by topic."""
        with self._compete_lock:
            return dict(self._unidentified)

    def _check_head_publisher(self, gid: bytes) -> None:
        """Report two publishers commanding the head within ``compete_window``."""
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
        info = {**(info or {}), "engines": engines, "head_publishers": publishers,
                "unidentified_commands": sum(self.unidentified().values())}
        return super().heartbeat(tracking, phase, info, stopping,
                                 degraded or len(engines) > 1 or publishers > 1)

    # -- in --------------------------------------------------------------------------------
    def _decode_trajectory(self, data: bytes) -> RosJointTrajectory:
        check_trajectory(data, convert.JOINT_TRAJECTORY)
        return cast(RosJointTrajectory, self._trajectory.decode(data))

    def _on_head(self, data: bytes, rx: Received) -> None:
        if rx.attachment is not None and self._publisher_of(rx.attachment.gid) is not None:
            self._check_head_publisher(rx.attachment.gid)  # a second publisher is reported
        self._identify(rx, convert.JOINT_TRAJECTORY)
        ros = self._decode_trajectory(data)
        goal = convert.trajectory_goal(ros)
        if not goal.time_from_start > 0.0:
            raise MessageError(convert.JOINT_TRAJECTORY, "time_from_start must be > 0, got "
                               f"{goal.time_from_start}")
        self.head.put(goal)

    def _on_eyes(self, ros: RosEyeState, rx: Received) -> None:
        self._identify(rx, rx.type)
        self.eyes.put(convert.eyes_of(ros))

    def _on_frame(self, ros: RosCompressedImage, rx: Received) -> None:
        self._identify(rx, rx.type)
        self.eye_frame.put(ros)  # decoded (and its size checked) where it is shown

    def _on_arm(self, data: bytes, rx: Received) -> None:
        self._identify(rx, convert.JOINT_TRAJECTORY)
        ros = self._decode_trajectory(data)
        goal = convert.trajectory_goal(ros)  # a ``gripper`` joint (0..1) may be among them
        self.arm.put(checked(convert.JOINT_TRAJECTORY,
                             lambda: ArmCommand(goal.t, positions=goal.positions)))

    def _on_arm_mode(self, ros: RosString, rx: Received) -> None:
        self._identify(rx, convert.STRING)
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
