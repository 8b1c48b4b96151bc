"""``ZenohRobotDriver``: drive any robot whose bridge speaks gazebot's ROS 2 topics on the
rmw_zenoh wire (:mod:`gazebot.io.ros2.topics`), e.g. ``gazebot sim`` or a ROS 2 robot stack."""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, ClassVar, NoReturn, cast

import numpy as np

from gazebot.core.types import Phase, TrackingFrame
from gazebot.io.drivers.base import RobotDriver
from gazebot.io.drivers.bounds import check_joint_state, check_tf
from gazebot.io.drivers.ownership import Ownership
from gazebot.io.drivers.rmw.attachment import gid_of
from gazebot.io.drivers.rmw.graph import Entity
from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.rmw.node import Received
from gazebot.io.drivers.streams import SequenceGuard
from gazebot.io.drivers.tf_buffer import TfBuffer, TransformError, listen
from gazebot.io.drivers.tracking_assembly import IDLE_FLUSH, REORDER, Part, SampleAssembler
from gazebot.io.drivers.tracking_source import Rival, SourceArbiter, group_of
from gazebot.io.drivers.zenoh_node import HISTORY_BYTES, ZenohNode
from gazebot.io.ros2 import convert, topics
from gazebot.io.ros2.convert import (
    RosCompressedImage,
    RosGripperState,
    RosJointState,
    RosLoadShare,
    RosPointStamped,
    RosPoseStamped,
    RosString,
    RosTFMessage,
)
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.topics import GAZE_FRAME
from gazebot.io.ros2.values import ArmCommand, EyeState, JointGoal, JointState, Point

if TYPE_CHECKING:
    import zenoh

log = logging.getLogger("gazebot.io.drivers")
#: Frames counted one by one in ``untransformed``; beyond, under :data:`OTHER_FRAMES`.
MAX_FRAMES = 100
OTHER_FRAMES = "(other frames)"


class ZenohRobotDriver(ZenohNode, RobotDriver):
    """The engine side of the bus: publishes head commands, the gaze target, eye state (and
    frames while subscribed), the phase, arm goals, events and health; receives tracking (as
    ``PointStamped``, ``PoseStamped`` or ``/tf`` frames), joint states, the gripper, the load
    share, the robot's events and the other nodes' health.

    Args:
        session: An open session (left open by :meth:`close` unless ``owns_session``).
        names: Namespace, remapping, domain id and frame names.
        node: This node's name (default ``engine``).
        owns_session: Close ``session`` in :meth:`close` (set by :meth:`open`).
        peer_timeout: Heartbeat timeout (s) after which a peer counts as lost.
        tracking_backlog: Unread tracking samples kept (oldest dropped beyond, counted in
            ``tracking_skipped``): 12 = 0.1 s at 120 Hz, the most the engine may lag.
        assemble_idle: Time (s) without any tracking part after which pending samples are
            complete anyway; completeness is otherwise decided from the stamps (see
            :mod:`gazebot.io.drivers.tracking_assembly`).
        assemble_reorder: Newer samples after which a part missing from a sample counts as
            not tracked at its stamp (how far one tracking topic may run ahead of another).
        source_timeout: A tracking source silent this long (s) gives way to the next one
            (see :mod:`gazebot.io.drivers.tracking_source`); until then another source's samples
            are dropped, counted by topic and reported as rivals.
        tf: A transform buffer to feed from ``/tf`` and ``/tf_static``: tracking in another
            frame than the base frame is transformed into it at the sample's stamp; a frame
            with no transform is dropped, counted in ``untransformed`` and warned about once.
            ``None``: tracking in another frame is dropped as malformed.
    """

    default_node: ClassVar[str] = "engine"

    def __init__(
        self,
        session: zenoh.Session,
        names: Names,
        node: str = "engine",
        *,
        owns_session: bool = False,
        peer_timeout: float = 2.0,
        tracking_backlog: int = 12,
        assemble_idle: float = IDLE_FLUSH,
        assemble_reorder: int = REORDER,
        clock: Callable[[], float] = time.monotonic,
        max_bytes: dict[str, int] | None = None,
        history_bytes: int = HISTORY_BYTES,
        source_timeout: float = 1.0,
        tf: TfBuffer | None = None,
    ) -> None:
        super().__init__(session, names, node, owns_session=owns_session,
                         peer_timeout=peer_timeout, clock=clock, max_bytes=max_bytes,
                         history_bytes=history_bytes)
        self._cond = threading.Condition(threading.Lock())
        self._queue: deque[TrackingFrame] = deque()
        self.tracking_backlog = tracking_backlog
        self.tracking_received = 0
        self.tracking_skipped = 0
        self._joints: JointState | None = None
        self._ownership: Ownership | None = None
        self._sources = SourceArbiter(source_timeout, clock)
        self._gid_lock = threading.Lock()
        self._gid_labels: dict[bytes, str] = {}  # publisher GID -> its source label
        self._bound: dict[str, bytes] = {}  # publisher token -> the GID it sends with
        self._streams = SequenceGuard(source_timeout, clock)
        self._assembler = SampleAssembler(self._expected_parts, assemble_idle,
                                          assemble_reorder, clock=clock)
        self.tf = tf
        self.untransformed: dict[str, int] = {}  # tracking dropped for want of a transform
        ros = self.ros
        self._head_pub = ros.publisher(topics.HEAD_COMMAND.name, topics.HEAD_COMMAND.type)
        self._target_pub = ros.publisher(topics.GAZE_TARGET.name, topics.GAZE_TARGET.type)
        self._eyes_pub = ros.publisher(topics.EYES.name, topics.EYES.type)
        self._frame_pub = ros.publisher(topics.EYE_IMAGE.name, topics.EYE_IMAGE.type)
        self._phase_pub = ros.publisher(topics.PHASE.name, topics.PHASE.type)
        self._arm_pub = ros.publisher(topics.ARM_COMMAND.name, topics.ARM_COMMAND.type)
        self._arm_mode_pub = ros.publisher(topics.ARM_MODE.name, topics.ARM_MODE.type)
        if tf is not None:  # first: the latched frames may come before the first sample
            listen(ros, tf)
        self._part_topics: dict[str, str] = {}
        for body, t in topics.TRACKING.items():
            sub = ros.subscription(t.name, (t.type, convert.POSE_STAMPED),
                                   self._point_handler(body))
            self._part_topics[body] = sub.topic
        self._tf_codec = ros.codec(topics.TF.type, names.resolve(topics.TF.name), topics.TF.name)
        self._joints_codec = ros.codec(topics.JOINT_STATES.type,
                                       names.resolve(topics.JOINT_STATES.name),
                                       topics.JOINT_STATES.name)
        if names.tf_frames:  # raw: the element count is checked before decoding
            sub = ros.subscription(topics.TF.name, topics.TF.type, self._on_tf, raw=True)
            for body in names.tf_frames:
                self._part_topics.setdefault(body, sub.topic)
        for part, t, fn in (("gripper", topics.GRIPPER, self._on_gripper),
                            ("load_share", topics.LOAD_SHARE, self._on_share)):
            self._part_topics[part] = ros.subscription(t.name, t.type, fn).topic
        ros.subscription(topics.JOINT_STATES.name, topics.JOINT_STATES.type, self._on_joints,
                         raw=True)
        self.announce()

    # -- tracking in -----------------------------------------------------------------------
    def _expected_parts(self) -> set[str]:
        """The sample parts whose topic has a publisher now (of the group's owning source,
        once there is one)."""
        owners = self._sources.owners()
        published = set()
        for e in self.ros.graph.entities():
            if e.kind == "MP":
                published.add((e.topic, source_label(e)))
        out = set()
        for part, topic in self._part_topics.items():
            owner = owners.get(group_of(part))
            if any(t == topic and (owner is None or owner == src) for t, src in published):
                out.add(part)
        return out

    def _source(self, part: str, rx: Received) -> str:
        """The node that published a received part: the live publisher of the topic whose
        token hashes to the GID of the attachment (as rmw_zenoh computes GIDs). An
        implementation with GIDs of its own (random ones, e.g. zenoh-ros2-sdk) is bound to the
        topic's only publisher by the first GID it sends, and only that GID is that publisher's
        while its token lives. A part from no such publisher, or of a GID carrying two streams
        (:mod:`~gazebot.io.drivers.streams`), is refused (a rival, counted and dropped:
        :class:`MessageError`)."""
        att = rx.attachment
        if att is None:
            self._refuse(part, UNANNOUNCED, rx, "no attachment")
        with self._gid_lock:
            label = self._gid_labels.get(att.gid)
        if label is None:
            label = self._bind(rx.topic, att.gid)
        if label is None:
            self._refuse(part, UNANNOUNCED, rx,
                         f"GID {att.gid.hex()} announced by no live publisher of {rx.topic}")
        why = self._streams.check(att.gid, att.sequence_number)
        if why is not None:
            self._refuse(part, f"a copy of the GID of {label}", rx, why)
        return label

    def _bind(self, topic: str, gid: bytes) -> str | None:
        """The label of the publisher of ``topic`` that ``gid`` is (see :meth:`_source`)."""
        publishers = self.ros.graph.endpoints(topic, "MP")
        with self._gid_lock:
            for e in publishers:
                own = gid_of(e.token())
                if own == gid:
                    self._bound[e.token()] = gid
                    label = self._gid_labels[gid] = source_label(e)
                    return label
            if len(publishers) == 1 and publishers[0].token() not in self._bound:
                e = publishers[0]
                self._bound[e.token()] = gid
                label = self._gid_labels[gid] = source_label(e)
                return label
        return None

    def _refuse(self, part: str, source: str, rx: Received, why: str) -> NoReturn:
        owner = self._sources.refuse(part, source)
        raise MessageError(rx.type, f"tracking from {source} ignored ({why}); {owner} "
                           f"publishes the {group_of(part)}")

    def _on_graph(self, entity: Entity, alive: bool) -> None:
        super()._on_graph(entity, alive)
        if entity.kind == "MP" and not alive:  # its GID identifies nothing any more
            with self._gid_lock:
                gid = self._bound.pop(entity.token(), gid_of(entity.token()))
                self._gid_labels.pop(gid, None)
            self._streams.forget(gid)

    def tracking_sources(self) -> dict[str, str]:
        """Tracking part (``giver_hand``, ``giver_face``, ``gripper``, ...) -> its source now."""
        return self._sources.owners()

    def tracking_rivals(self, new_only: bool = False) -> list[Rival]:
        """Sources whose tracking was ignored lately (``new_only``: not returned before)."""
        return self._sources.new_rivals() if new_only else self._sources.rivals()

    def _point(self, ros: RosPointStamped | RosPoseStamped) -> tuple[float, np.ndarray] | None:
        """The sample's stamp and point in the base frame; ``None`` when its frame has no
        transform to the base frame (counted, warned about once per frame)."""
        t, p = convert.point_of(ros)
        base = self._to_base(str(ros.header.frame_id), t, p, ros.__msgtype__)
        return None if base is None else (t, base)

    def _to_base(self, frame: str, t: float, p: np.ndarray, what: str) -> np.ndarray | None:
        """``p`` given in ``frame`` at time ``t``, in the base frame (through :attr:`tf`);
        ``None`` when ``frame`` has no transform to it (counted, warned about once per frame).

        Raises:
            MessageError: another frame without a tf buffer, or a result that is not finite.
        """
        if self.names.is_base_frame(frame):
            return p
        if self.tf is None:
            raise MessageError(what, f"frame_id {frame!r}, expected the robot base frame "
                               f"{self.names.base_frame!r}")
        try:
            base = self.tf.transform_point(self.names.base_frame, frame, p, t)
        except TransformError as exc:
            with self._cond:
                if frame not in self.untransformed and len(self.untransformed) >= MAX_FRAMES:
                    frame = OTHER_FRAMES  # a sender of ever new frame ids: stay bounded
                n = self.untransformed[frame] = self.untransformed.get(frame, 0) + 1
            if n == 1:
                log.warning("tracking in frame %r dropped: %s (no transform to the base frame "
                            "%r on /tf or /tf_static)", frame, exc, self.names.base_frame)
            return None
        if not np.all(np.isfinite(base)):  # finite values far out of range
            raise MessageError(what, f"point in {frame!r} is not finite in the base frame")
        return base

    def _point_handler(
        self, body: str
    ) -> Callable[[RosPointStamped | RosPoseStamped, Received], None]:
        return lambda ros, rx: self._on_point(body, ros, rx)

    def _on_point(self, body: str, ros: RosPointStamped | RosPoseStamped, rx: Received) -> None:
        point = self._point(ros)
        if point is not None:
            self._add(body, *point, rx)

    def _on_tf(self, data: bytes, rx: Received) -> None:
        check_tf(data, rx.type)
        ros = cast(RosTFMessage, self._tf_codec.decode(data))
        by_child = {child.lstrip("/"): body for body, child in self.names.tf_frames.items()}
        for tf in ros.transforms:
            body = by_child.get(str(tf.child_frame_id).lstrip("/"))
            if body is None:
                continue
            parent = str(tf.header.frame_id)
            if self.tf is None and not self.names.is_base_frame(parent):
                continue  # a frame of the robot's own tree, not a tracked body in the base
            t, p = convert.point_of(tf)
            base = self._to_base(parent, t, p, ros.__msgtype__)
            if base is not None:
                self._add(body, t, base, rx)

    def _on_gripper(self, ros: RosGripperState, rx: Received) -> None:
        self._add("gripper", convert.stamp_of(ros), bool(ros.closed), rx)

    def _on_share(self, ros: RosLoadShare, rx: Received) -> None:
        t, share = convert.share_of(ros)
        self._add("load_share", t, share, rx)

    def _add(self, part: str, t: float, value: Part, rx: Received) -> None:
        if not math.isfinite(t):
            raise MessageError(part, f"stamp is not finite: {t}")
        source = self._source(part, rx)
        owner = self._sources.admit(part, source)
        if owner is not None:
            raise MessageError(rx.type, f"second tracking source {source} ignored: {owner} "
                               f"publishes the {group_of(part)}")
        with self._cond:
            self._enqueue(self._assembler.add(part, t, value))

    def _enqueue(self, samples: list[TrackingFrame]) -> None:
        for msg in samples:
            if len(self._queue) >= self.tracking_backlog:
                self._queue.popleft()
                self.tracking_skipped += 1
            self._queue.append(msg)
            self.tracking_received += 1
        if samples:
            self._cond.notify_all()

    def _on_joints(self, data: bytes, rx: Received) -> None:
        check_joint_state(data, rx.type)
        self._joints = convert.joint_positions(cast(RosJointState, self._joints_codec.decode(data)))

    @property
    def tracking_late(self) -> int:
        """Tracking parts that arrived after their sample was complete (dropped)."""
        return self._assembler.late

    # -- ownership -------------------------------------------------------------------------
    def claim(self, timeout: float = 0.5) -> None:
        """Declare this engine's claim on the robot (once), waiting up to ``timeout`` s to learn
        the other engines' claims."""
        if self._ownership is None and not self.closed:
            self._ownership = self.ros.declare(Ownership(self.session, self.names, self.node,
                                                         graph=self.ros.graph))
            self._ownership.declare(timeout)

    def owns_robot(self) -> bool:
        """Whether this engine's claim is the one the claims settle on."""
        return self._ownership is not None and self._ownership.is_owner()

    def rival_engines(self) -> list[str]:
        """The other engines claiming the robot (none before :meth:`claim`)."""
        return [] if self._ownership is None else [str(c) for c in self._ownership.rivals()]

    # -- RobotDriver -----------------------------------------------------------------------
    def wait_tracking(self, timeout: float) -> TrackingFrame | None:
        """The oldest assembled tracking sample, waiting up to ``timeout`` s (a closed driver does
        not wait); ``None`` if there is none."""
        end = self.clock() + max(0.0, timeout)
        with self._cond:
            while not self._queue and not self.closed:
                self._enqueue(self._assembler.flush_stale())
                now = self.clock()
                if self._queue or now >= end:
                    break
                due = self._assembler.next_deadline()
                wait = end - now if due is None else min(end, max(due, now + 1e-3)) - now
                self._cond.wait(wait)
            return self._queue.popleft() if self._queue else None

    def joint_state(self) -> JointState | None:
        """The latest joint state received, ``None`` before the first one."""
        return self._joints

    def send_head(self, goal: JointGoal) -> None:
        """Publish head joint goals on ``head/command`` (``JointTrajectory``)."""
        self._head_pub.publish(convert.joint_trajectory(goal))

    def send_gaze_target(self, t: float, point: Point) -> None:
        """Publish the point looked at on ``gaze_target`` (``PointStamped`` in the base frame)."""
        self._target_pub.publish(convert.point_stamped(t, point, self.names.base_frame))

    def send_phase(self, t: float, phase: str, phase_start: float) -> None:
        """Publish the phase on the latched ``handover/phase``."""
        self._phase_pub.publish(convert.handover_phase(t, Phase(phase), phase_start))

    def send_eyes(self, eyes: EyeState) -> None:
        """Publish the eye state on ``eyes/state``."""
        self._eyes_pub.publish(convert.eye_state(eyes, GAZE_FRAME, self.ros.store))

    def send_eye_frame(self, image: RosCompressedImage) -> None:
        """Publish a rendered eye frame on ``eyes/image/compressed``."""
        self._frame_pub.publish(image)

    def wants_eye_frames(self) -> bool:
        """Whether a subscription of ``eyes/image/compressed`` exists (frames are costly to
        render)."""
        # Rendering and encoding frames is costly: only while someone subscribes to them.
        return not self.closed and self._frame_pub.subscribed()

    def send_arm(self, cmd: ArmCommand) -> None:
        """Publish joint goals on ``arm/command``, or a named pose or ``resume`` on ``arm/mode``;
        a gripper goal goes on ``arm/command``."""
        if cmd.positions is not None:
            goal = dict(cmd.positions)
            if cmd.gripper is not None:
                goal["gripper"] = cmd.gripper
            self._arm_pub.publish(convert.joint_trajectory(JointGoal(cmd.t, goal, {}, 1.0)))
            return
        self._arm_mode_pub.publish(RosString("resume" if cmd.resume else str(cmd.pose)))
        if cmd.gripper is not None:
            self._arm_pub.publish(convert.joint_trajectory(
                JointGoal(cmd.t, {"gripper": cmd.gripper}, {}, 1.0)))

    def close(self) -> None:
        """Close the node (see :meth:`ZenohNode.close`) and wake a :meth:`wait_tracking` in
        progress."""
        if self.closed:
            return
        super().close()
        with self._cond:
            self._cond.notify_all()  # wake a wait_tracking() in progress


#: The source of tracking samples no live publisher announced.
UNANNOUNCED = "an unannounced publisher"


def source_label(entity: Entity) -> str:
    """A tracking source's name: its node's name and its session."""
    return f"{entity.node} (session {entity.zid})"
