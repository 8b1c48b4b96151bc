"""gazebot's values <-> ROS 2 messages: the one place that maps the two.

SI units both sides (m, s, rad); points in the robot base frame, whose ROS name
(``RobotConfig.base_frame``) the caller passes as ``frame_id``. Times are the robot's clock
(simulation time in the simulator) as ``builtin_interfaces/Time``.

Engine commands are read by attribute (``t``, ``phase`` and optionally ``phase_source``,
``target_point``, ``head``, ``eye_yaw``, ``eye_pitch``, ``blink``, ``distance``, ``events``), so
any command value with those attributes converts. Nothing non-finite goes on the wire and
nothing non-finite comes off it: a NaN or infinite coordinate, joint value or time, in either
direction, raises :class:`~gazebot.io.ros2.errors.MessageError` (which a transport counts and
drops), as do arrays of inconsistent lengths and images that do not decode.

Every function takes the type system as ``store`` (default: the shipped
:func:`~gazebot.io.ros2.typestore.typestore`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal, get_args

import numpy as np
from rosbags.typesys.store import Typestore

from gazebot.core.phases.trajectory import POINTS
from gazebot.core.types import (
    PHASE_STREAM_KINDS,
    Event,
    EventKind,
    Phase,
    PhaseSource,
    TrackingFrame,
)
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.typestore import typestore

POINT_STAMPED = "geometry_msgs/msg/PointStamped"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
TRANSFORM_STAMPED = "geometry_msgs/msg/TransformStamped"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
JOINT_STATE = "sensor_msgs/msg/JointState"
JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
DIAGNOSTIC_ARRAY = "diagnostic_msgs/msg/DiagnosticArray"
COMPRESSED_IMAGE = "sensor_msgs/msg/CompressedImage"
EYE_STATE = "gazebot_msgs/msg/EyeState"
HANDOVER_PHASE = "gazebot_msgs/msg/HandoverPhase"
HANDOVER_EVENT = "gazebot_msgs/msg/HandoverEvent"
GRIPPER_STATE = "gazebot_msgs/msg/GripperState"
LOAD_SHARE = "gazebot_msgs/msg/LoadShare"

#: The tracked bodies of a :class:`~gazebot.core.types.TrackingFrame`, one topic (or TF frame) each.
BODIES = POINTS


EventCategory = Literal["phase", "robot", "behavior", "fault", "node"]
_CATEGORIES = ("phase", "robot", "behavior", "fault", "node")
_SOURCES = get_args(PhaseSource)
_INT32 = 2**31
_TIME_TYPES = {"Time": "builtin_interfaces/msg/Time", "Duration": "builtin_interfaces/msg/Duration"}


def _store(store: Typestore | None) -> Typestore:
    return typestore() if store is None else store


def _finite(type_name: str, what: str, *values: float) -> None:
    for v in values:  # a plain loop: this runs for every field of every message
        if not math.isfinite(v):
            raise MessageError(type_name, f"{what} is not finite: {values}")


# -- time ---------------------------------------------------------------------------------------


def to_time(t: float, store: Typestore | None = None, kind: str = "Time") -> object:
    """``builtin_interfaces/{kind}`` (``Time`` or ``Duration``) of ``t`` seconds, rounded to ns.

    Raises:
        MessageError: ``t`` is not finite or outside the int32 seconds ROS 2 time holds.
    """
    type_name = _TIME_TYPES[kind]
    if not math.isfinite(t):
        raise MessageError(type_name, f"time is not finite: {t}")
    ns = round(t * 1e9)
    sec, nanosec = divmod(ns, 1_000_000_000)
    if not -_INT32 <= sec < _INT32:
        raise MessageError(type_name, f"{t} s is outside int32 seconds")
    return _store(store).types[type_name](sec=int(sec), nanosec=int(nanosec))


def from_time(stamp: Any) -> float:
    """Seconds of a ``builtin_interfaces/Time`` or ``Duration``."""
    return float(stamp.sec) + 1e-9 * float(stamp.nanosec)


def header(t: float, frame_id: str, store: Typestore | None = None) -> object:
    """``std_msgs/Header`` stamped ``t`` (s) in ``frame_id``."""
    s = _store(store)
    return s.types["std_msgs/msg/Header"](stamp=to_time(t, s), frame_id=frame_id)


def stamp_of(msg: Any) -> float:
    """The header stamp (s) of a stamped message."""
    return from_time(msg.header.stamp)


# -- points, poses, TF --------------------------------------------------------------------------


def _xyz(type_name: str, point: Any) -> tuple[float, float, float]:
    arr = np.asarray(point, dtype=float).reshape(-1)
    if arr.shape != (3,):
        raise MessageError(type_name, f"expected a 3D point, got shape {arr.shape}")
    x, y, z = arr.tolist()
    _finite(type_name, "point", x, y, z)
    return x, y, z


def point_stamped(t: float, point: Any, frame_id: str, store: Typestore | None = None) -> object:
    """``geometry_msgs/PointStamped`` of ``point`` (m) at ``t`` (s) in ``frame_id``.

    Raises:
        MessageError: ``point`` is missing (NaN) or infinite: a missing sample is not sent.
    """
    s = _store(store)
    x, y, z = _xyz(POINT_STAMPED, point)
    return s.types[POINT_STAMPED](
        header=header(t, frame_id, s), point=s.types["geometry_msgs/msg/Point"](x=x, y=y, z=z)
    )


def pose_stamped(t: float, point: Any, frame_id: str, store: Typestore | None = None) -> object:
    """``geometry_msgs/PoseStamped`` at ``point`` (m) with identity orientation (gazebot tracks
    positions only)."""
    s = _store(store)
    x, y, z = _xyz(POSE_STAMPED, point)
    pose = s.types["geometry_msgs/msg/Pose"](
        position=s.types["geometry_msgs/msg/Point"](x=x, y=y, z=z),
        orientation=s.types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
    )
    return s.types[POSE_STAMPED](header=header(t, frame_id, s), pose=pose)


def point_of(msg: Any) -> tuple[float, np.ndarray]:
    """``(t, point)`` of a ``PointStamped``, ``PoseStamped`` or ``TransformStamped`` (its
    position; orientation is ignored).

    Raises:
        MessageError: Another type, or a non-finite coordinate or stamp.
    """
    type_name = getattr(msg, "__msgtype__", type(msg).__name__)
    if type_name == POINT_STAMPED:
        p = msg.point
    elif type_name == POSE_STAMPED:
        p = msg.pose.position
    elif type_name == TRANSFORM_STAMPED:
        p = msg.transform.translation
    else:
        raise MessageError(type_name, "not a PointStamped, PoseStamped or TransformStamped")
    t = stamp_of(msg)
    xyz = (float(p.x), float(p.y), float(p.z))
    _finite(type_name, "point", *xyz)
    return t, np.array(xyz)


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
    points: Mapping[str, Any],
    gripper_closed: bool | None = None,
    load_share: float | None = None,
) -> TrackingFrame:
    """A :class:`TrackingFrame` at ``t`` from points by body name (absent: missing)."""
    unknown = set(points).difference(BODIES)
    if unknown:
        raise ValueError(f"unknown tracked bodies {sorted(unknown)}; expected {BODIES}")
    return TrackingFrame.make(
        t, **{b: points.get(b) for b in BODIES}, gripper_closed=gripper_closed,
        load_share=load_share,
    )


def tracking_tf(
    frame: TrackingFrame,
    parent_frame: str,
    child_frames: Mapping[str, str] | None = None,
    store: Typestore | None = None,
) -> object:
    """``tf2_msgs/TFMessage`` with one transform per tracked body of ``frame`` (identity
    rotation), child frame names ``child_frames[body]`` (default: the body name)."""
    s = _store(store)
    names = child_frames or {}
    transforms = []
    for body, p in tracking_points(frame).items():
        x, y, z = p.tolist()
        transforms.append(
            s.types[TRANSFORM_STAMPED](
                header=header(frame.t, parent_frame, s),
                child_frame_id=names.get(body, body),
                transform=s.types["geometry_msgs/msg/Transform"](
                    translation=s.types["geometry_msgs/msg/Vector3"](x=x, y=y, z=z),
                    rotation=s.types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                ),
            )
        )
    return s.types[TF_MESSAGE](transforms=transforms)


def tf_points(msg: Any) -> dict[str, tuple[float, np.ndarray]]:
    """``child_frame_id`` (leading ``/`` dropped) -> ``(t, translation)`` of a ``TFMessage``.

    Raises:
        MessageError: A transform with a non-finite translation or stamp.
    """
    out = {}
    for tf in msg.transforms:
        out[str(tf.child_frame_id).lstrip("/")] = point_of(tf)
    return out


# -- joints -------------------------------------------------------------------------------------


def joint_state(
    t: float,
    positions: Mapping[str, float],
    velocities: Mapping[str, float] | None = None,
    frame_id: str = "",
    store: Typestore | None = None,
) -> object:
    """``sensor_msgs/JointState`` of joint positions (rad or m) by name, with velocities for the
    same joints when given (else none, as ROS allows)."""
    s = _store(store)
    names = list(positions)
    pos = np.array([float(positions[n]) for n in names], dtype=np.float64)
    _finite(JOINT_STATE, "position", *pos.tolist())
    vel = np.zeros(0)
    if velocities is not None:
        vel = np.array([float(velocities[n]) for n in names], dtype=np.float64)
        _finite(JOINT_STATE, "velocity", *vel.tolist())
    return s.types[JOINT_STATE](
        header=header(t, frame_id, s), name=names, position=pos, velocity=vel,
        effort=np.zeros(0),
    )


def joint_positions(msg: Any) -> tuple[float, dict[str, float]]:
    """``(t, {joint: position})`` of a ``sensor_msgs/JointState``.

    Raises:
        MessageError: ``name`` and ``position`` differ in length, or a position is not finite.
    """
    names = list(msg.name)
    pos = np.asarray(msg.position, dtype=float)
    if pos.shape != (len(names),):
        raise MessageError(
            JOINT_STATE, f"{len(names)} names but {pos.size} positions (need one per name)"
        )
    _finite(JOINT_STATE, "position", *pos.tolist())
    return stamp_of(msg), dict(zip(names, pos.tolist(), strict=True))


# -- engine commands ----------------------------------------------------------------------------


def head_trajectory(
    cmd: Any,
    time_from_start: float,
    velocities: Mapping[str, float] | None = None,
    stamped: bool = False,
    store: Typestore | None = None,
) -> object:
    """``trajectory_msgs/JointTrajectory`` with one point, as ros2_control's
    joint_trajectory_controller takes a streamed goal: ``cmd.head`` positions (rad) in the
    command's joint order, ``velocities`` at the goal (default 0: arrive at rest) and
    ``time_from_start`` (s) to get there.

    ``stamped=False`` leaves ``header.stamp`` zero, which the controller reads as "start on
    receipt" (a command stamped on the robot's clock would start in the past after any
    latency); ``True`` stamps it with ``cmd.t``.

    Raises:
        MessageError: A non-finite position, velocity or time, or no head joint.
    """
    s = _store(store)
    head: Mapping[str, float] = cmd.head
    names = list(head)
    if not names:
        raise MessageError(JOINT_TRAJECTORY, "the command has no head joint")
    pos = np.array([float(head[n]) for n in names], dtype=np.float64)
    vel = np.array([float((velocities or {}).get(n, 0.0)) for n in names], dtype=np.float64)
    _finite(JOINT_TRAJECTORY, "head position", *pos.tolist())
    _finite(JOINT_TRAJECTORY, "head velocity", *vel.tolist())
    if not time_from_start > 0.0:
        raise MessageError(JOINT_TRAJECTORY, f"time_from_start must be > 0, got {time_from_start}")
    point = s.types["trajectory_msgs/msg/JointTrajectoryPoint"](
        positions=pos, velocities=vel, accelerations=np.zeros(0), effort=np.zeros(0),
        time_from_start=to_time(time_from_start, s, "Duration"),
    )
    return s.types[JOINT_TRAJECTORY](
        header=header(float(cmd.t) if stamped else 0.0, "", s), joint_names=names, points=[point]
    )


def trajectory_goal(msg: Any) -> tuple[dict[str, float], float]:
    """``({joint: position}, time_from_start)`` of a trajectory's last point.

    Raises:
        MessageError: No point, lengths that differ from ``joint_names``, non-finite values.
    """
    if not msg.points:
        raise MessageError(JOINT_TRAJECTORY, "no trajectory point")
    last = msg.points[-1]
    names = list(msg.joint_names)
    pos = np.asarray(last.positions, dtype=float)
    if pos.shape != (len(names),):
        raise MessageError(
            JOINT_TRAJECTORY, f"{len(names)} joint_names but {pos.size} positions"
        )
    _finite(JOINT_TRAJECTORY, "position", *pos.tolist())
    return dict(zip(names, pos.tolist(), strict=True)), from_time(last.time_from_start)


def gaze_target(cmd: Any, frame_id: str, store: Typestore | None = None) -> object:
    """``geometry_msgs/PointStamped``: the point ``cmd`` looks at, at ``cmd.t``, in the robot
    base frame ``frame_id``. :class:`MessageError` when the target point is unknown (NaN)."""
    return point_stamped(float(cmd.t), cmd.target_point, frame_id, store)


def eye_state(cmd: Any, frame_id: str, store: Typestore | None = None) -> object:
    """``gazebot_msgs/EyeState`` of ``cmd`` (``eye_yaw``, ``eye_pitch``, ``blink``,
    ``distance``; an unknown distance is NaN on the wire) in the head's gaze frame
    ``frame_id``."""
    s = _store(store)
    yaw, pitch = float(cmd.eye_yaw), float(cmd.eye_pitch)
    blink = float(getattr(cmd, "blink", 0.0))
    _finite(EYE_STATE, "yaw/pitch/blink", yaw, pitch, blink)
    if not 0.0 <= blink <= 1.0:
        raise MessageError(EYE_STATE, f"blink must be within 0..1, got {blink}")
    distance = getattr(cmd, "distance", None)
    d = math.nan if distance is None else float(distance)
    if not (math.isnan(d) or (math.isfinite(d) and d > 0.0)):
        raise MessageError(EYE_STATE, f"distance must be > 0 m or unknown, got {distance}")
    return s.types[EYE_STATE](
        header=header(float(cmd.t), frame_id, s), yaw=yaw, pitch=pitch, blink=blink, distance=d
    )


@dataclass(frozen=True)
class Eyes:
    """What an ``EyeState`` says: ``t`` (s), ``yaw`` / ``pitch`` (rad), ``blink`` (0..1) and
    ``distance`` (m; ``None`` when unknown)."""

    t: float
    yaw: float
    pitch: float
    blink: float
    distance: float | None


def eyes_of(msg: Any) -> Eyes:
    """The :class:`Eyes` of an ``EyeState``.

    Raises:
        MessageError: Non-finite angles, a blink outside 0..1, a distance that is not > 0 (NaN
            is unknown).
    """
    yaw, pitch, blink, d = float(msg.yaw), float(msg.pitch), float(msg.blink), float(msg.distance)
    _finite(EYE_STATE, "yaw/pitch/blink", yaw, pitch, blink)
    if not 0.0 <= blink <= 1.0:
        raise MessageError(EYE_STATE, f"blink must be within 0..1, got {blink}")
    if not (math.isnan(d) or (math.isfinite(d) and d > 0.0)):
        raise MessageError(EYE_STATE, f"distance must be > 0 m or NaN (unknown), got {d}")
    return Eyes(stamp_of(msg), yaw, pitch, blink, None if math.isnan(d) else d)


# -- phase --------------------------------------------------------------------------------------


def phase_parts(phase: Any, source: str | None = None) -> tuple[Phase, str]:
    """The :class:`Phase` and its source (``tracking``, ``robot``, ``gripper``): ``phase`` is a
    plain :class:`Phase` or a value with ``phase`` and ``source`` attributes; ``source``, when
    given, says where it came from (default ``tracking``)."""
    src = source or getattr(phase, "source", None) or "tracking"
    base = getattr(phase, "phase", phase)
    return Phase(getattr(base, "value", base)), str(getattr(src, "value", src))


def command_phase(cmd: Any) -> tuple[Phase, str]:
    """The phase of an engine command and what decided it (``cmd.phase_source`` when the
    command carries one)."""
    return phase_parts(cmd.phase, getattr(cmd, "phase_source", None))


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
    phase: Any,
    phase_start: float,
    expected_end: float = math.nan,
    source: str | None = None,
    store: Typestore | None = None,
) -> object:
    """``gazebot_msgs/HandoverPhase`` at ``t``: ``phase`` from ``source`` (see
    :func:`phase_parts`) started at ``phase_start``, predicted to end at ``expected_end`` (NaN:
    unknown, zero on the wire)."""
    s = _store(store)
    value, source = phase_parts(phase, source)
    if source not in _SOURCES:
        raise MessageError(HANDOVER_PHASE, f"source must be one of {_SOURCES}, got {source!r}")
    end = to_time(expected_end, s) if math.isfinite(expected_end) else to_time(0.0, s)
    return s.types[HANDOVER_PHASE](
        header=header(t, "", s), phase=value.value, source=source,
        phase_start=to_time(phase_start, s), expected_end=end,
    )


def phase_of(msg: Any) -> PhaseState:
    """The :class:`PhaseState` of a ``HandoverPhase``; :class:`MessageError` for an unknown
    phase or source."""
    try:
        phase = Phase(msg.phase)
    except ValueError:
        raise MessageError(HANDOVER_PHASE, f"unknown phase {msg.phase!r}") from None
    if msg.source not in _SOURCES:
        raise MessageError(HANDOVER_PHASE, f"unknown source {msg.source!r}")
    end = from_time(msg.expected_end)
    return PhaseState(
        stamp_of(msg), phase, str(msg.source), from_time(msg.phase_start),
        math.nan if msg.expected_end.sec == 0 and msg.expected_end.nanosec == 0 else end,
    )


# -- events -------------------------------------------------------------------------------------


def category_of(kind: str) -> EventCategory:
    """``phase`` or ``robot`` for :class:`~gazebot.core.types.EventKind` values; ``fault`` for the
    engine's ``fault`` and any other kind."""
    try:
        ek = EventKind(kind)
    except ValueError:
        return "fault"
    if ek is EventKind.FAULT:
        return "fault"
    return "phase" if ek in PHASE_STREAM_KINDS else "robot"


def _plain(value: Any) -> Any:
    """``value`` with numpy scalars/arrays and str enums made plain JSON types."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if hasattr(value, "value") and isinstance(value.value, str):
        return value.value
    return value if value is None or isinstance(value, str) else str(value)


def info_text(value: Any) -> str:
    """A ``KeyValue.value``: strings as they are, anything else as JSON (NaN as null)."""
    plain = _plain(value)
    return plain if isinstance(plain, str) else json.dumps(plain, allow_nan=False)


#: Deepest nesting of lists/objects an info value may have (gazebot's own are at most 2 deep;
#: a crafted ``[[[[...`` would otherwise exhaust the interpreter's recursion).
MAX_INFO_DEPTH = 16


def _depth(value: Any) -> int:
    """Nesting depth of parsed JSON (0 for a scalar), without recursion."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, (list, dict)):
            deepest = max(deepest, d + 1)
            stack.extend((c, d + 1) for c in (v.values() if isinstance(v, dict) else v))
    return deepest


def info_value(text: str, type_name: str = HANDOVER_EVENT) -> Any:
    """Inverse of :func:`info_text`: JSON numbers, booleans, null, lists and objects are
    parsed; any other text is a string.

    Raises:
        MessageError: JSON nested deeper than :data:`MAX_INFO_DEPTH` (``type_name`` names the
            message it came in).
    """
    try:
        value = json.loads(text)
    except RecursionError:
        raise MessageError(type_name, f"info value nested deeper than {MAX_INFO_DEPTH}") from None
    except ValueError:
        return text
    if isinstance(value, str):
        return text
    if _depth(value) > MAX_INFO_DEPTH:
        raise MessageError(type_name, f"info value nested deeper than {MAX_INFO_DEPTH}")
    return value


def handover_event(
    source: str,
    category: str,
    kind: str,
    t: float,
    detected_at: float,
    stamp: float,
    info: Mapping[str, Any] | None = None,
    store: Typestore | None = None,
) -> object:
    """``gazebot_msgs/HandoverEvent`` (see the .msg for the fields; ``stamp`` is the header's).

    Raises:
        MessageError: An unknown category, an empty kind, a non-finite time.
    """
    s = _store(store)
    if category not in _CATEGORIES:
        raise MessageError(HANDOVER_EVENT, f"category must be one of {_CATEGORIES}")
    if not kind:
        raise MessageError(HANDOVER_EVENT, "empty kind")
    kv = s.types["diagnostic_msgs/msg/KeyValue"]
    return s.types[HANDOVER_EVENT](
        header=header(stamp, "", s), source=source, category=category, kind=kind,
        t=to_time(t, s), detected_at=to_time(detected_at, s),
        info=[kv(key=str(k), value=info_text(v)) for k, v in (info or {}).items()],
    )


def event_msg(
    event: Event, source: str, stamp: float, store: Typestore | None = None
) -> object:
    """The ``HandoverEvent`` of a phase or robot :class:`~gazebot.core.types.Event`."""
    kind = event.kind.value
    return handover_event(
        source, category_of(kind), kind, float(event.t), float(event.detected_at), stamp,
        event.info, store,
    )


@dataclass(frozen=True)
class HandoverEventValue:
    """Every field of a ``HandoverEvent`` (times in s; ``info`` values parsed back)."""

    source: str
    category: str
    kind: str
    t: float
    detected_at: float
    stamp: float
    info: dict[str, Any] = field(default_factory=dict)

    def to_event(self) -> Event | None:
        """The :class:`~gazebot.core.types.Event` for phase and robot kinds, ``None`` otherwise."""
        try:
            kind = EventKind(self.kind)
        except ValueError:
            return None
        return Event(kind=kind, t=self.t, detected_at=self.detected_at, info=dict(self.info))


def event_of(msg: Any) -> HandoverEventValue:
    """The fields of a ``HandoverEvent``; :class:`MessageError` for an unknown category or a
    repeated info key."""
    if msg.category not in _CATEGORIES:
        raise MessageError(HANDOVER_EVENT, f"unknown category {msg.category!r}")
    keys = [kv.key for kv in msg.info]
    if len(set(keys)) != len(keys):
        raise MessageError(HANDOVER_EVENT, f"repeated info keys {keys}")
    return HandoverEventValue(
        source=str(msg.source), category=str(msg.category), kind=str(msg.kind),
        t=from_time(msg.t), detected_at=from_time(msg.detected_at), stamp=stamp_of(msg),
        info={kv.key: info_value(kv.value) for kv in msg.info},
    )


# -- gripper and load share ---------------------------------------------------------------------


def gripper_state(t: float, closed: bool, store: Typestore | None = None) -> object:
    """``gazebot_msgs/GripperState`` at ``t``."""
    s = _store(store)
    return s.types[GRIPPER_STATE](header=header(t, "", s), closed=bool(closed))


def load_share(t: float, share: float, store: Typestore | None = None) -> object:
    """``gazebot_msgs/LoadShare`` at ``t``; :class:`MessageError` outside 0..1."""
    share = float(share)
    if not 0.0 <= share <= 1.0:
        raise MessageError(LOAD_SHARE, f"share must be within 0..1, got {share}")
    s = _store(store)
    return s.types[LOAD_SHARE](header=header(t, "", s), share=share)


def share_of(msg: Any) -> tuple[float, float]:
    """``(t, share)`` of a ``LoadShare``; :class:`MessageError` outside 0..1 (or NaN)."""
    share = float(msg.share)
    if not 0.0 <= share <= 1.0:
        raise MessageError(LOAD_SHARE, f"share must be within 0..1, got {share}")
    return stamp_of(msg), share


# -- health -------------------------------------------------------------------------------------

#: ``DiagnosticStatus.level`` of a node's state (``stopping`` is a normal shutdown: OK).
LEVELS = {"ok": 0, "degraded": 1, "error": 2, "stopping": 0}


def diagnostics(status: Any, t: float, store: Typestore | None = None) -> object:
    """``diagnostic_msgs/DiagnosticArray`` with one ``DiagnosticStatus`` for a node.

    ``status`` is read by attribute: ``node``, ``state`` (``ok``, ``degraded``, ``error``,
    ``stopping``: the level), and optionally ``tracking``, ``phase``, ``uptime`` (s),
    ``peers`` (node -> alive), ``dropped`` (topic -> count) and ``info``; they become the
    status' key/values (``peer/<node>``: ``alive``/``lost``, ``dropped/<topic>``: count).
    The status is named ``gazebot: <node>``.
    """
    s = _store(store)
    state = str(status.state)
    if state not in LEVELS:
        raise MessageError(DIAGNOSTIC_ARRAY, f"state must be one of {tuple(LEVELS)}")
    values: list[tuple[str, Any]] = []
    for key in ("tracking", "phase", "uptime"):
        value = getattr(status, key, None)
        if value is not None:
            values.append((key, value))
    values += [(f"peer/{n}", "alive" if up else "lost")
               for n, up in (getattr(status, "peers", None) or {}).items()]
    values += [(f"dropped/{k}", n) for k, n in (getattr(status, "dropped", None) or {}).items()]
    values += list((getattr(status, "info", None) or {}).items())
    kv = s.types["diagnostic_msgs/msg/KeyValue"]
    st = s.types["diagnostic_msgs/msg/DiagnosticStatus"](
        level=LEVELS[state], name=f"gazebot: {status.node}", message=state, hardware_id="",
        values=[kv(key=str(k), value=info_text(v)) for k, v in values],
    )
    return s.types[DIAGNOSTIC_ARRAY](header=header(t, "", s), status=[st])


@dataclass(frozen=True)
class NodeHealth:
    """One ``DiagnosticStatus`` of a gazebot node: ``node``, ``level`` (0 OK, 1 WARN, 2 ERROR,
    3 STALE), ``state`` (its message) and ``values`` parsed by :func:`info_value`."""

    node: str
    level: int
    state: str
    values: dict[str, Any]


def health_of(msg: Any) -> list[NodeHealth]:
    """The gazebot nodes' statuses in a ``DiagnosticArray`` (other statuses are skipped)."""
    out = []
    for st in msg.status:
        if str(st.name).startswith("gazebot: "):
            out.append(NodeHealth(
                str(st.name)[len("gazebot: "):], int(st.level), str(st.message),
                {kv.key: info_value(kv.value, DIAGNOSTIC_ARRAY) for kv in st.values},
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
    """JPEG (default: several times faster to encode than PNG at display sizes) or PNG
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
    img: np.ndarray,
    t: float,
    frame_id: str,
    fmt: Literal["jpeg", "png"] = "jpeg",
    store: Typestore | None = None,
) -> object:
    """``sensor_msgs/CompressedImage`` of an (H, W, 3) uint8 RGB image (see
    :func:`encode_image`)."""
    buf = encode_image(img, fmt)
    s = _store(store)
    return s.types[COMPRESSED_IMAGE](
        header=header(t, frame_id, s), format=fmt, data=np.frombuffer(buf, np.uint8)
    )


def image_of(msg: Any, max_size: tuple[int, int] = MAX_IMAGE_SIZE) -> np.ndarray:
    """The (H, W, 3) uint8 RGB image of a ``CompressedImage`` (JPEG or PNG, at most
    ``max_size``; see :func:`decode_image`).

    Raises:
        MessageError: The data is not a PNG or JPEG of at most ``max_size``.
    """
    return decode_image(np.asarray(msg.data, dtype=np.uint8).reshape(-1), max_size)


def command_messages(
    cmd: Any,
    base_frame: str,
    gaze_frame: str,
    time_from_start: float,
    store: Typestore | None = None,
) -> dict[str, object]:
    """The messages one engine command becomes, by role: ``head/command`` (when the robot has
    head joints), ``gaze_target`` (when the target point is known), ``eyes`` and ``events``
    (a list of ``HandoverEvent`` from ``cmd.events``, source ``engine``)."""
    s = _store(store)
    out: dict[str, object] = {}
    if cmd.head:
        out["head/command"] = head_trajectory(cmd, time_from_start, store=s)
    p = np.asarray(cmd.target_point, dtype=float)
    if p.shape == (3,) and bool(np.all(np.isfinite(p))):
        out["gaze_target"] = gaze_target(cmd, base_frame, s)
    out["eyes"] = eye_state(cmd, gaze_frame, s)
    out["events"] = [event_msg(e, "engine", float(cmd.t), s) for e in _events(cmd)]
    return out


def _events(cmd: Any) -> Iterable[Event]:
    return tuple(getattr(cmd, "events", ()) or ())
