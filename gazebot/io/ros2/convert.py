"""gazebot's values <-> ROS 2 messages: the one place that maps the two.

The values are the core's (:class:`~gazebot.core.types.TrackingFrame`,
:class:`~gazebot.core.types.GazeCommand`, :class:`~gazebot.core.types.Event`) and the few the
bus adds (:mod:`gazebot.io.ros2.values`); the messages are rosbags' generated classes of ROS 2
Jazzy (``rosbags.typesys.stores.ros2_jazzy``) and, for ``gazebot_msgs`` (built at run time from
the package's ``.msg`` files), the Protocols below that name their fields.

SI units both sides (m, s, rad); points in the robot base frame, whose ROS name
(``RobotConfig.base_frame``) the caller passes as ``frame_id``. Times are the robot's clock
(simulation time in the simulator) as ``builtin_interfaces/Time``. Nothing non-finite goes on
the wire and nothing non-finite comes off it: a NaN or infinite coordinate, joint value or time,
in either direction, raises :class:`~gazebot.io.ros2.errors.MessageError` (which a transport
counts and drops), as do arrays of inconsistent lengths and images that do not decode.

The ``gazebot_msgs`` builders take the type system as ``store`` (default: the shipped
:func:`~gazebot.io.ros2.typestore.typestore`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Literal, Protocol, TypeVar, cast, get_args

import numpy as np
import numpy.typing as npt
from rosbags.typesys.store import Typestore
from rosbags.typesys.stores import ros2_jazzy as jazzy

from gazebot.core.phases.trajectory import POINTS
from gazebot.core.types import Event, GazeCommand, Phase, PhaseSource, TrackingFrame
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.typestore import typestore
from gazebot.io.ros2.values import (
    CATEGORIES,
    LEVELS,
    BusEvent,
    EventCategory,
    EyeState,
    JointGoal,
    JointState,
    Json,
    NodeStatus,
    category_of,
    plain,
)

__all__ = [
    "BODIES", "CATEGORIES", "COMPRESSED_IMAGE", "DIAGNOSTIC_ARRAY", "EYE_STATE", "GRIPPER_STATE",
    "HANDOVER_EVENT", "HANDOVER_PHASE", "JOINT_STATE", "JOINT_TRAJECTORY", "LEVELS", "LOAD_SHARE",
    "MAX_IMAGE_SIZE", "MAX_INFO_DEPTH", "POINT_STAMPED", "POSE_STAMPED", "STRING", "TF_MESSAGE",
    "TRANSFORM_STAMPED", "CommandMessages", "EventCategory", "Header", "NodeHealth",
    "PhaseState", "RosCompressedImage", "RosDiagnosticArray", "RosEyeState", "RosGripperState",
    "RosHandoverEvent", "RosHandoverPhase", "RosJointState", "RosJointTrajectory", "RosLoadShare",
    "RosPointStamped", "RosPoseStamped", "RosString", "RosTFMessage", "RosTransformStamped",
    "Stamped", "Time", "category_of", "command_messages", "command_phase", "compressed_image",
    "decode_image", "diagnostics", "encode_image", "event_msg", "event_of", "eye_state",
    "eyes_of", "from_time", "gaze_target", "gripper_state", "handover_event", "handover_phase",
    "header", "health_of", "image_of", "image_size", "info_text", "info_value", "joint_positions",
    "joint_state", "joint_trajectory", "load_share", "phase_of", "point_of", "point_stamped",
    "pose_stamped", "share_of", "stamp_of", "tf_points", "to_duration", "to_time",
    "tracking_frame", "tracking_points", "tracking_tf", "trajectory_goal",
]

# ROS 2 Jazzy's generated message classes gazebot uses.
Duration = jazzy.builtin_interfaces__msg__Duration
Header = jazzy.std_msgs__msg__Header
KeyValue = jazzy.diagnostic_msgs__msg__KeyValue
Quaternion = jazzy.geometry_msgs__msg__Quaternion
RosCompressedImage = jazzy.sensor_msgs__msg__CompressedImage
RosDiagnosticArray = jazzy.diagnostic_msgs__msg__DiagnosticArray
RosDiagnosticStatus = jazzy.diagnostic_msgs__msg__DiagnosticStatus
RosJointState = jazzy.sensor_msgs__msg__JointState
RosJointTrajectory = jazzy.trajectory_msgs__msg__JointTrajectory
RosJointTrajectoryPoint = jazzy.trajectory_msgs__msg__JointTrajectoryPoint
RosPoint = jazzy.geometry_msgs__msg__Point
RosPointStamped = jazzy.geometry_msgs__msg__PointStamped
RosPose = jazzy.geometry_msgs__msg__Pose
RosPoseStamped = jazzy.geometry_msgs__msg__PoseStamped
RosString = jazzy.std_msgs__msg__String
RosTFMessage = jazzy.tf2_msgs__msg__TFMessage
RosTransform = jazzy.geometry_msgs__msg__Transform
RosTransformStamped = jazzy.geometry_msgs__msg__TransformStamped
Time = jazzy.builtin_interfaces__msg__Time
Vector3 = jazzy.geometry_msgs__msg__Vector3

POINT_STAMPED = RosPointStamped.__msgtype__
POSE_STAMPED = RosPoseStamped.__msgtype__
TRANSFORM_STAMPED = RosTransformStamped.__msgtype__
TF_MESSAGE = RosTFMessage.__msgtype__
JOINT_STATE = RosJointState.__msgtype__
JOINT_TRAJECTORY = RosJointTrajectory.__msgtype__
DIAGNOSTIC_ARRAY = RosDiagnosticArray.__msgtype__
COMPRESSED_IMAGE = RosCompressedImage.__msgtype__
STRING = RosString.__msgtype__
EYE_STATE = "gazebot_msgs/msg/EyeState"
HANDOVER_PHASE = "gazebot_msgs/msg/HandoverPhase"
HANDOVER_EVENT = "gazebot_msgs/msg/HandoverEvent"
GRIPPER_STATE = "gazebot_msgs/msg/GripperState"
LOAD_SHARE = "gazebot_msgs/msg/LoadShare"

#: The tracked bodies of a :class:`~gazebot.core.types.TrackingFrame`, one topic (or TF frame) each.
BODIES = POINTS

_SOURCES: tuple[str, ...] = get_args(PhaseSource)
_INT32 = 2**31
_IDENTITY = (0.0, 0.0, 0.0, 1.0)


# -- the shapes of gazebot_msgs (their classes are generated from the .msg files at run time) ---


class Stamped(Protocol):
    """A message with a ``std_msgs/Header``."""

    @property
    def header(self) -> Header:
        """The message's header."""


class RosEyeState(Protocol):
    """``gazebot_msgs/msg/EyeState``."""

    __msgtype__: str
    header: Header
    yaw: float
    pitch: float
    blink: float
    distance: float


class RosHandoverPhase(Protocol):
    """``gazebot_msgs/msg/HandoverPhase``."""

    __msgtype__: str
    header: Header
    phase: str
    source: str
    phase_start: Time
    expected_end: Time


class RosHandoverEvent(Protocol):
    """``gazebot_msgs/msg/HandoverEvent``."""

    __msgtype__: str
    header: Header
    source: str
    category: str
    kind: str
    t: Time
    detected_at: Time
    info: list[KeyValue]


class RosGripperState(Protocol):
    """``gazebot_msgs/msg/GripperState``."""

    __msgtype__: str
    header: Header
    closed: bool


class RosLoadShare(Protocol):
    """``gazebot_msgs/msg/LoadShare``."""

    __msgtype__: str
    header: Header
    share: float


_M = TypeVar("_M")


def _new(store: Typestore | None, type_name: str, **fields: object) -> object:
    """A ``gazebot_msgs`` message of ``type_name`` (of the class ``store`` generated from its
    .msg file; the caller names its Protocol)."""
    cls: Callable[..., object] = (typestore() if store is None else store).types[type_name]
    return cls(**fields)


def _finite(type_name: str, what: str, *values: float) -> None:
    for v in values:
        if not math.isfinite(v):
            raise MessageError(type_name, f"{what} is not finite: {values}")


def _value(type_name: str, build: Callable[[], _M]) -> _M:
    """``build()``, a value that refuses its fields (:class:`ValueError`) made a
    :class:`MessageError` of ``type_name``."""
    try:
        return build()
    except ValueError as exc:
        raise MessageError(type_name, str(exc)) from None


# -- time ---------------------------------------------------------------------------------------


def _sec_nanosec(type_name: str, t: float) -> tuple[int, int]:
    if not math.isfinite(t):
        raise MessageError(type_name, f"time is not finite: {t}")
    sec, nanosec = divmod(round(t * 1e9), 1_000_000_000)
    if not -_INT32 <= sec < _INT32:
        raise MessageError(type_name, f"{t} s is outside int32 seconds")
    return int(sec), int(nanosec)


def to_time(t: float) -> Time:
    """``builtin_interfaces/Time`` of ``t`` seconds, rounded to ns.

    Raises:
        MessageError: ``t`` is not finite or outside the int32 seconds ROS 2 time holds.
    """
    return Time(*_sec_nanosec(Time.__msgtype__, t))


def to_duration(t: float) -> Duration:
    """``builtin_interfaces/Duration`` of ``t`` seconds (see :func:`to_time`)."""
    return Duration(*_sec_nanosec(Duration.__msgtype__, t))


def from_time(stamp: Time | Duration) -> float:
    """Seconds of a ``builtin_interfaces/Time`` or ``Duration``."""
    return float(stamp.sec) + 1e-9 * float(stamp.nanosec)


def header(t: float, frame_id: str) -> Header:
    """``std_msgs/Header`` stamped ``t`` (s) in ``frame_id``."""
    return Header(stamp=to_time(t), frame_id=frame_id)


def stamp_of(msg: Stamped) -> float:
    """The header stamp (s) of a stamped message."""
    return from_time(msg.header.stamp)


# -- points, poses, TF --------------------------------------------------------------------------


def _xyz(type_name: str, point: npt.ArrayLike) -> tuple[float, float, float]:
    arr = np.asarray(point, dtype=float).reshape(-1)
    if arr.shape != (3,):
        raise MessageError(type_name, f"expected a 3D point, got shape {arr.shape}")
    x, y, z = (float(v) for v in arr)
    _finite(type_name, "point", x, y, z)
    return x, y, z


def point_stamped(t: float, point: npt.ArrayLike, frame_id: str) -> RosPointStamped:
    """``geometry_msgs/PointStamped`` of ``point`` (m) at ``t`` (s) in ``frame_id``.

    Raises:
        MessageError: ``point`` is missing (NaN) or infinite: a missing sample is not sent.
    """
    return RosPointStamped(header(t, frame_id), RosPoint(*_xyz(POINT_STAMPED, point)))


def pose_stamped(t: float, point: npt.ArrayLike, frame_id: str) -> RosPoseStamped:
    """``geometry_msgs/PoseStamped`` at ``point`` (m) with identity orientation (gazebot tracks
    positions only)."""
    pose = RosPose(RosPoint(*_xyz(POSE_STAMPED, point)), Quaternion(*_IDENTITY))
    return RosPoseStamped(header(t, frame_id), pose)


def point_of(
    msg: RosPointStamped | RosPoseStamped | RosTransformStamped,
) -> tuple[float, np.ndarray]:
    """``(t, point)`` of a ``PointStamped``, ``PoseStamped`` or ``TransformStamped`` (its
    position; orientation is ignored).

    Raises:
        MessageError: Another type, or a non-finite coordinate or stamp.
    """
    p: RosPoint | Vector3
    if isinstance(msg, RosPointStamped):
        p = msg.point
    elif isinstance(msg, RosPoseStamped):
        p = msg.pose.position
    elif isinstance(msg, RosTransformStamped):
        p = msg.transform.translation
    else:
        got = getattr(msg, "__msgtype__", type(msg).__name__)
        raise MessageError(got, "not a PointStamped, PoseStamped or TransformStamped")
    xyz = (float(p.x), float(p.y), float(p.z))
    _finite(msg.__msgtype__, "point", *xyz)
    return stamp_of(msg), np.array(xyz)


def tracking_points(frame: TrackingFrame) -> dict[str, np.ndarray]:
    """The bodies of ``frame`` that were tracked (finite), by :data:`BODIES` name."""
    out = {}
    for body in BODIES:
        p = np.asarray(getattr(frame, body), dtype=float)
        if p.shape == (3,) and bool(np.all(np.isfinite(p))):
            out[body] = p
    return out


def tracking_frame(
    t: float,
    points: Mapping[str, npt.ArrayLike | None],
    gripper_closed: bool | None = None,
    load_share: float | None = None,
) -> TrackingFrame:
    """A :class:`TrackingFrame` at ``t`` from points by body name (absent: missing)."""
    unknown = set(points).difference(BODIES)
    if unknown:
        raise ValueError(f"unknown tracked bodies {sorted(unknown)}; expected {BODIES}")
    return TrackingFrame.make(
        t, giver_hand=points.get("giver_hand"), receiver_hand=points.get("receiver_hand"),
        giver_face=points.get("giver_face"), gripper_closed=gripper_closed,
        load_share=load_share,
    )


def tracking_tf(
    frame: TrackingFrame,
    parent_frame: str,
    child_frames: Mapping[str, str] | None = None,
) -> RosTFMessage:
    """``tf2_msgs/TFMessage`` with one transform per tracked body of ``frame`` (identity
    rotation), child frame names ``child_frames[body]`` (default: the body name)."""
    names = child_frames or {}
    transforms = [
        RosTransformStamped(
            header(frame.t, parent_frame), names.get(body, body),
            RosTransform(Vector3(*(float(v) for v in p)), Quaternion(*_IDENTITY)),
        )
        for body, p in tracking_points(frame).items()
    ]
    return RosTFMessage(transforms=transforms)


def tf_points(msg: RosTFMessage) -> dict[str, tuple[float, np.ndarray]]:
    """``child_frame_id`` (leading ``/`` dropped) -> ``(t, translation)`` of a ``TFMessage``.

    Raises:
        MessageError: A transform with a non-finite translation or stamp.
    """
    return {str(tf.child_frame_id).lstrip("/"): point_of(tf) for tf in msg.transforms}


# -- joints -------------------------------------------------------------------------------------


def _floats(values: Iterable[float]) -> np.ndarray:
    return np.array([float(v) for v in values], dtype=np.float64)


def joint_state(
    t: float,
    positions: Mapping[str, float],
    velocities: Mapping[str, float] | None = None,
    frame_id: str = "",
) -> RosJointState:
    """``sensor_msgs/JointState`` of joint positions (rad or m) by name, with velocities for the
    same joints when given (else none, as ROS allows)."""
    names = list(positions)
    pos = _floats(positions[n] for n in names)
    _finite(JOINT_STATE, "position", *pos.tolist())
    vel = np.zeros(0)
    if velocities is not None:
        vel = _floats(velocities[n] for n in names)
        _finite(JOINT_STATE, "velocity", *vel.tolist())
    return RosJointState(header(t, frame_id), names, pos, vel, np.zeros(0))


def joint_positions(msg: RosJointState) -> JointState:
    """The :class:`~gazebot.io.ros2.values.JointState` of a ``sensor_msgs/JointState``.

    Raises:
        MessageError: ``name`` and ``position`` differ in length, or a position is not finite.
    """
    names = [str(n) for n in msg.name]
    pos = np.asarray(msg.position, dtype=float)
    if pos.shape != (len(names),):
        raise MessageError(
            JOINT_STATE, f"{len(names)} names but {pos.size} positions (need one per name)"
        )
    _finite(JOINT_STATE, "position", *pos.tolist())
    return JointState(stamp_of(msg), dict(zip(names, pos.tolist(), strict=True)))


# -- joint goals --------------------------------------------------------------------------------


def joint_trajectory(goal: JointGoal, stamped: bool = False) -> RosJointTrajectory:
    """``trajectory_msgs/JointTrajectory`` with one point, as ros2_control's
    joint_trajectory_controller takes a streamed goal: ``goal.positions`` in the goal's joint
    order, ``goal.velocities`` at the goal (absent: 0, arrive at rest) and
    ``goal.time_from_start`` (s) to get there.

    ``stamped=False`` leaves ``header.stamp`` zero, which the controller reads as "start on
    receipt" (a command stamped on the robot's clock would start in the past after any
    latency); ``True`` stamps it with ``goal.t``.

    Raises:
        MessageError: No joint, or a ``time_from_start`` that is not > 0.
    """
    names = list(goal.positions)
    if not names:
        raise MessageError(JOINT_TRAJECTORY, "the goal has no joint")
    if not goal.time_from_start > 0.0:
        raise MessageError(JOINT_TRAJECTORY,
                           f"time_from_start must be > 0, got {goal.time_from_start}")
    point = RosJointTrajectoryPoint(
        positions=_floats(goal.positions[n] for n in names),
        velocities=_floats(goal.velocities.get(n, 0.0) for n in names),
        accelerations=np.zeros(0), effort=np.zeros(0),
        time_from_start=to_duration(goal.time_from_start),
    )
    return RosJointTrajectory(header(goal.t if stamped else 0.0, ""), names, [point])


def trajectory_goal(msg: RosJointTrajectory) -> JointGoal:
    """The :class:`~gazebot.io.ros2.values.JointGoal` of a trajectory's last point (``t``: the
    header stamp; velocities only when there is one per joint).

    Raises:
        MessageError: No point, lengths that differ from ``joint_names``, non-finite values.
    """
    if not msg.points:
        raise MessageError(JOINT_TRAJECTORY, "no trajectory point")
    last = msg.points[-1]
    names = [str(n) for n in msg.joint_names]
    pos = np.asarray(last.positions, dtype=float)
    if pos.shape != (len(names),):
        raise MessageError(
            JOINT_TRAJECTORY, f"{len(names)} joint_names but {pos.size} positions"
        )
    _finite(JOINT_TRAJECTORY, "position", *pos.tolist())
    vel = np.asarray(last.velocities, dtype=float)
    velocities = dict(zip(names, vel.tolist(), strict=True)) if vel.shape == pos.shape else {}
    return _value(JOINT_TRAJECTORY, lambda: JointGoal(
        stamp_of(msg), dict(zip(names, pos.tolist(), strict=True)), velocities,
        from_time(last.time_from_start)))


# -- engine commands ----------------------------------------------------------------------------


def gaze_target(cmd: GazeCommand, frame_id: str) -> RosPointStamped:
    """``geometry_msgs/PointStamped``: the point ``cmd`` looks at, at ``cmd.t``, in the robot
    base frame ``frame_id``. :class:`MessageError` when the target point is unknown (NaN)."""
    return point_stamped(float(cmd.t), cmd.target_point, frame_id)


def eye_state(eyes: EyeState, frame_id: str, store: Typestore | None = None) -> RosEyeState:
    """``gazebot_msgs/EyeState`` of ``eyes`` (an unknown distance is NaN on the wire) in the
    head's gaze frame ``frame_id``."""
    d = math.nan if eyes.distance is None else eyes.distance
    msg = _new(store, EYE_STATE, header=header(eyes.t, frame_id), yaw=eyes.yaw,
               pitch=eyes.pitch, blink=eyes.blink, distance=d)
    return cast(RosEyeState, msg)


def eyes_of(msg: RosEyeState) -> EyeState:
    """The :class:`~gazebot.io.ros2.values.EyeState` of an ``EyeState`` message.

    Raises:
        MessageError: Non-finite angles, a blink outside 0..1, a distance that is not > 0 (NaN
            is unknown).
    """
    d = float(msg.distance)
    return _value(EYE_STATE, lambda: EyeState(
        stamp_of(msg), float(msg.yaw), float(msg.pitch), float(msg.blink),
        None if math.isnan(d) else d))


# -- phase --------------------------------------------------------------------------------------


def command_phase(cmd: GazeCommand) -> tuple[Phase, PhaseSource]:
    """The phase of an engine command and what decided it."""
    return cmd.phase, cmd.phase_source


@dataclass(frozen=True)
class PhaseState:
    """What a ``HandoverPhase`` says (times in s; ``expected_end`` NaN when unknown)."""

    t: float
    phase: Phase
    source: str
    phase_start: float
    expected_end: float = math.nan


def handover_phase(
    t: float,
    phase: Phase,
    phase_start: float,
    expected_end: float = math.nan,
    source: str = "tracking",
    store: Typestore | None = None,
) -> RosHandoverPhase:
    """``gazebot_msgs/HandoverPhase`` at ``t``: ``phase`` as decided by ``source``
    (``tracking``, ``robot``, ``gripper``), started at ``phase_start``, predicted to end at
    ``expected_end`` (NaN: unknown, zero on the wire)."""
    if source not in _SOURCES:
        raise MessageError(HANDOVER_PHASE, f"source must be one of {_SOURCES}, got {source!r}")
    end = to_time(expected_end if math.isfinite(expected_end) else 0.0)
    msg = _new(store, HANDOVER_PHASE, header=header(t, ""), phase=Phase(phase).value,
               source=source, phase_start=to_time(phase_start), expected_end=end)
    return cast(RosHandoverPhase, msg)


def phase_of(msg: RosHandoverPhase) -> PhaseState:
    """The :class:`PhaseState` of a ``HandoverPhase``; :class:`MessageError` for an unknown
    phase or source."""
    try:
        phase = Phase(msg.phase)
    except ValueError:
        raise MessageError(HANDOVER_PHASE, f"unknown phase {msg.phase!r}") from None
    if msg.source not in _SOURCES:
        raise MessageError(HANDOVER_PHASE, f"unknown source {msg.source!r}")
    end = msg.expected_end
    return PhaseState(
        stamp_of(msg), phase, str(msg.source), from_time(msg.phase_start),
        math.nan if end.sec == 0 and end.nanosec == 0 else from_time(end),
    )


# -- events -------------------------------------------------------------------------------------


def info_text(value: object) -> str:
    """A ``KeyValue.value``: strings as they are, anything else as JSON (NaN as null)."""
    data = plain(value)
    return data if isinstance(data, str) else json.dumps(data, allow_nan=False)


#: Deepest nesting of lists/objects an info value may have (gazebot's own are at most 2 deep;
#: a crafted ``[[[[...`` would otherwise exhaust the interpreter's recursion).
MAX_INFO_DEPTH = 16


def _depth(value: Json) -> int:
    """Nesting depth of parsed JSON (0 for a scalar), without recursion."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, (list, dict)):
            deepest = max(deepest, d + 1)
            stack.extend((c, d + 1) for c in (v.values() if isinstance(v, dict) else v))
    return deepest


def info_value(text: str, type_name: str = HANDOVER_EVENT) -> Json:
    """Inverse of :func:`info_text`: JSON numbers, booleans, null, lists and objects are
    parsed; any other text is a string.

    Raises:
        MessageError: JSON nested deeper than :data:`MAX_INFO_DEPTH` (``type_name`` names the
            message it came in).
    """
    try:
        value: Json = json.loads(text)
    except RecursionError:
        raise MessageError(type_name, f"info value nested deeper than {MAX_INFO_DEPTH}") from None
    except ValueError:
        return text
    if isinstance(value, str):
        return text
    if _depth(value) > MAX_INFO_DEPTH:
        raise MessageError(type_name, f"info value nested deeper than {MAX_INFO_DEPTH}")
    return value


def handover_event(event: BusEvent, store: Typestore | None = None) -> RosHandoverEvent:
    """``gazebot_msgs/HandoverEvent`` of a bus event (``stamp`` is the header's)."""
    msg = _new(
        store, HANDOVER_EVENT, header=header(event.stamp, ""), source=event.source,
        category=event.category, kind=event.kind, t=to_time(event.t),
        detected_at=to_time(event.detected_at),
        info=[KeyValue(key=str(k), value=info_text(v)) for k, v in event.info.items()],
    )
    return cast(RosHandoverEvent, msg)


def event_msg(
    event: Event, source: str, stamp: float, store: Typestore | None = None
) -> RosHandoverEvent:
    """The ``HandoverEvent`` of a core :class:`~gazebot.core.types.Event` published by
    ``source``."""
    return handover_event(BusEvent.of(event, source, stamp), store)


def event_of(msg: RosHandoverEvent, seq: int = 0) -> BusEvent:
    """The :class:`~gazebot.io.ros2.values.BusEvent` of a ``HandoverEvent`` (``seq``: the
    publisher's sequence number); :class:`MessageError` for an unknown category, a repeated
    info key or fields gazebot cannot use (an empty or overlong source or kind)."""
    category = str(msg.category)
    if category not in CATEGORIES:
        raise MessageError(HANDOVER_EVENT, f"unknown category {category!r}")
    keys = [str(kv.key) for kv in msg.info]
    if len(set(keys)) != len(keys):
        raise MessageError(HANDOVER_EVENT, f"repeated info keys {keys}")
    info = {str(kv.key): info_value(kv.value) for kv in msg.info}
    return _value(HANDOVER_EVENT, lambda: BusEvent(
        str(msg.source), cast(EventCategory, category), str(msg.kind), from_time(msg.t),
        from_time(msg.detected_at), stamp_of(msg), info, max(0, seq)))


# -- gripper and load share ---------------------------------------------------------------------


def gripper_state(t: float, closed: bool, store: Typestore | None = None) -> RosGripperState:
    """``gazebot_msgs/GripperState`` at ``t``."""
    msg = _new(store, GRIPPER_STATE, header=header(t, ""), closed=bool(closed))
    return cast(RosGripperState, msg)


def load_share(t: float, share: float, store: Typestore | None = None) -> RosLoadShare:
    """``gazebot_msgs/LoadShare`` at ``t``; :class:`MessageError` outside 0..1."""
    share = float(share)
    if not 0.0 <= share <= 1.0:
        raise MessageError(LOAD_SHARE, f"share must be within 0..1, got {share}")
    return cast(RosLoadShare, _new(store, LOAD_SHARE, header=header(t, ""), share=share))


def share_of(msg: RosLoadShare) -> tuple[float, float]:
    """``(t, share)`` of a ``LoadShare``; :class:`MessageError` outside 0..1 (or NaN)."""
    share = float(msg.share)
    if not 0.0 <= share <= 1.0:
        raise MessageError(LOAD_SHARE, f"share must be within 0..1, got {share}")
    return stamp_of(msg), share


# -- health -------------------------------------------------------------------------------------


def diagnostics(status: NodeStatus, t: float) -> RosDiagnosticArray:
    """``diagnostic_msgs/DiagnosticArray`` with one ``DiagnosticStatus`` for a node, named
    ``gazebot: <node>``, level by ``status.state``; its key/values are ``tracking``, ``phase``
    and ``uptime`` (when known), ``peer/<node>`` (``alive``/``lost``), ``dropped/<topic>``
    (count) and the status' ``info``."""
    values: list[tuple[str, object]] = [("tracking", status.tracking)]
    if status.phase is not None:
        values.append(("phase", status.phase))
    values.append(("uptime", status.uptime))
    values += [(f"peer/{n}", "alive" if up else "lost") for n, up in status.peers.items()]
    values += [(f"dropped/{k}", n) for k, n in status.dropped.items()]
    values += list(status.info.items())
    st = RosDiagnosticStatus(
        level=LEVELS[status.state], name=f"gazebot: {status.node}", message=status.state,
        hardware_id="", values=[KeyValue(key=str(k), value=info_text(v)) for k, v in values],
    )
    return RosDiagnosticArray(header(t, ""), [st])


@dataclass(frozen=True)
class NodeHealth:
    """One ``DiagnosticStatus`` of a gazebot node as read off the bus: ``node``, ``level`` (0
    OK, 1 WARN, 2 ERROR, 3 STALE), ``state`` (its message) and ``values`` parsed by
    :func:`info_value`."""

    node: str
    level: int
    state: str
    values: dict[str, Json]


def health_of(msg: RosDiagnosticArray) -> list[NodeHealth]:
    """The gazebot nodes' statuses in a ``DiagnosticArray`` (other statuses are skipped)."""
    out = []
    for st in msg.status:
        name = str(st.name)
        if name.startswith("gazebot: "):
            out.append(NodeHealth(
                name[len("gazebot: "):], int(st.level), str(st.message),
                {str(kv.key): info_value(kv.value, DIAGNOSTIC_ARRAY) for kv in st.values},
            ))
    return out


# -- eye frames ---------------------------------------------------------------------------------

#: Largest image (width, height) :func:`decode_image` decodes by default: the eye display
#: is 1024x600; a 4096x4096 RGB image is 48 MiB decoded. A few hundred kB of PNG can claim
#: 20000x20000 (1.2 GB decoded): the header is read and such an image refused undecoded.
MAX_IMAGE_SIZE = (4096, 4096)

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# JPEG start-of-frame markers (baseline, progressive, lossless, arithmetic); not C4/C8/CC.
_JPEG_SOF = frozenset({0xC0, 0xC1, 0xC2, 0xC3, 0xC5, 0xC6, 0xC7, 0xC9, 0xCA, 0xCB, 0xCD, 0xCE,
                       0xCF})


def image_size(data: bytes) -> tuple[str, int, int]:
    """``(format, width, height)`` of PNG or JPEG ``data``, read from its header only.

    Raises:
        MessageError: Neither a PNG nor a JPEG, or a header that is cut short.
    """
    if data.startswith(_PNG_SIGNATURE):
        if len(data) < 24 or data[12:16] != b"IHDR":
            raise MessageError(COMPRESSED_IMAGE, "PNG without an IHDR header")
        return "png", int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    if data.startswith(b"\xff\xd8"):
        i = 2
        while i + 4 <= len(data):
            if data[i] != 0xFF:
                raise MessageError(COMPRESSED_IMAGE, f"JPEG: no segment marker at byte {i}")
            marker = data[i + 1]
            if marker == 0xFF:  # fill byte
                i += 1
                continue
            if marker == 0x01 or 0xD0 <= marker <= 0xD8:  # segments without a length
                i += 2
                continue
            length = int.from_bytes(data[i + 2:i + 4], "big")
            if marker in _JPEG_SOF:
                if i + 9 > len(data):
                    break
                height = int.from_bytes(data[i + 5:i + 7], "big")
                width = int.from_bytes(data[i + 7:i + 9], "big")
                return "jpeg", width, height
            if marker in (0xD9, 0xDA) or length < 2:  # end of image / scan before a frame
                break
            i += 2 + length
        raise MessageError(COMPRESSED_IMAGE, "JPEG without a frame header")
    raise MessageError(COMPRESSED_IMAGE, "data is not a decodable image (neither PNG nor JPEG)")


def encode_image(img: np.ndarray, fmt: Literal["jpeg", "png"] = "jpeg") -> bytes:
    """JPEG (default; smaller at display sizes) or PNG
    (lossless) bytes of an (H, W, 3) uint8 RGB image.

    Raises:
        MessageError: Not an (H, W, 3) uint8 image, or the encoder failed.
    """
    import cv2

    if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8:
        raise MessageError(
            COMPRESSED_IMAGE, f"expected an (H, W, 3) uint8 RGB image, got {img.shape} {img.dtype}"
        )
    ok, buf = cv2.imencode(".png" if fmt == "png" else ".jpg", img[:, :, ::-1])
    if not ok:
        raise MessageError(COMPRESSED_IMAGE, f"could not encode the image as {fmt}")
    return buf.tobytes()


def decode_image(
    data: bytes | np.ndarray, max_size: tuple[int, int] = MAX_IMAGE_SIZE
) -> np.ndarray:
    """The (H, W, 3) uint8 RGB image of PNG or JPEG ``data``: the one image decoder of gazebot's
    wire. The header's dimensions are checked against ``max_size`` (width, height) before
    anything is decoded.

    Raises:
        MessageError: Not a PNG or JPEG, larger than ``max_size``, or it does not decode.
    """
    import cv2

    raw = data.tobytes() if isinstance(data, np.ndarray) else bytes(data)
    fmt, width, height = image_size(raw)
    if not (0 < width <= max_size[0] and 0 < height <= max_size[1]):
        raise MessageError(COMPRESSED_IMAGE, f"{fmt} image is {width}x{height}, at most "
                           f"{max_size[0]}x{max_size[1]} is decoded")
    img = cv2.imdecode(np.frombuffer(raw, np.uint8), cv2.IMREAD_COLOR)
    if img is None or img.shape[:2] != (height, width):
        raise MessageError(COMPRESSED_IMAGE, f"data is not a decodable image ({fmt})")
    return np.ascontiguousarray(img[:, :, ::-1])


def compressed_image(
    img: np.ndarray, t: float, frame_id: str, fmt: Literal["jpeg", "png"] = "jpeg"
) -> RosCompressedImage:
    """``sensor_msgs/CompressedImage`` of an (H, W, 3) uint8 RGB image (see
    :func:`encode_image`)."""
    data = np.frombuffer(encode_image(img, fmt), np.uint8)
    return RosCompressedImage(header(t, frame_id), fmt, data)


def image_of(
    msg: RosCompressedImage, max_size: tuple[int, int] = MAX_IMAGE_SIZE
) -> np.ndarray:
    """The (H, W, 3) uint8 RGB image of a ``CompressedImage`` (JPEG or PNG, at most
    ``max_size``; see :func:`decode_image`).

    Raises:
        MessageError: The data is not a PNG or JPEG of at most ``max_size``.
    """
    return decode_image(np.asarray(msg.data, dtype=np.uint8).reshape(-1), max_size)


@dataclass(frozen=True)
class CommandMessages:
    """The messages one engine command becomes: ``head`` (``head/command``, when the robot has
    head joints), ``gaze_target`` (when the target point is known), ``eyes`` and ``events``
    (the command's events, source ``engine``)."""

    head: RosJointTrajectory | None
    gaze_target: RosPointStamped | None
    eyes: RosEyeState
    events: list[RosHandoverEvent]


def command_messages(
    cmd: GazeCommand,
    base_frame: str,
    gaze_frame: str,
    time_from_start: float,
    store: Typestore | None = None,
) -> CommandMessages:
    """The messages of one engine command (its head goal reached in ``time_from_start`` s)."""
    head = (joint_trajectory(JointGoal(cmd.t, dict(cmd.head), {}, time_from_start))
            if cmd.head else None)
    p = np.asarray(cmd.target_point, dtype=float)
    known = p.shape == (3,) and bool(np.all(np.isfinite(p)))
    return CommandMessages(
        head=head,
        gaze_target=gaze_target(cmd, base_frame) if known else None,
        eyes=eye_state(_value(EYE_STATE, lambda: EyeState.of(cmd)), gaze_frame, store),
        events=[event_msg(e, "engine", float(cmd.t), store) for e in cmd.events],
    )
