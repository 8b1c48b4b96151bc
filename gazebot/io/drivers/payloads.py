"""The values gazebot's nodes exchange, validated strictly (frozen pydantic models): what a driver
hands the engine node and back. On the bus they travel as ROS 2 messages
(:mod:`gazebot.io.drivers.topics`, converted by :mod:`gazebot.io.ros2.convert`); building one from
wire data checks types, ranges and finiteness, and a violation is counted and dropped by the
transport.

Units are SI (s, m, rad); points are ``(x, y, z)`` in the robot base frame, ``None`` when
missing. ``t`` is the robot's clock (simulation time for the simulator), ``stamp`` the sender's
wall clock (``time.time()``), used for staleness and latency.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Annotated, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    model_validator,
)

from gazebot.core.types import (
    Event,
    EventKind,
    GazeCommand,
    TrackingFrame,
    is_valid_point,
)
from gazebot.io.ros2 import convert
from gazebot.io.ros2.errors import MessageError

if TYPE_CHECKING:
    from gazebot.core.runtime import LoopCommand

Point = tuple[float, float, float]
Unit = Annotated[float, Field(ge=0.0, le=1.0)]
NonNeg = Annotated[float, Field(ge=0.0)]
Seq = Annotated[int, Field(ge=0)]
Name = Annotated[str, Field(min_length=1, max_length=64)]



class PayloadError(ValueError):
    """A payload could not be parsed; ``reason`` is a one-line explanation."""

    def __init__(self, model: str, reason: str):
        self.model = model
        self.reason = reason
        super().__init__(f"malformed {model} payload: {reason}")


def point_or_none(p: Any) -> Point | None:
    """``[x, y, z]`` for a finite point, ``None`` for a missing (NaN/None) one."""
    if p is None:
        return None
    arr = np.asarray(p, dtype=float).reshape(-1)
    if arr.shape != (3,) or not is_valid_point(arr):
        return None
    return (float(arr[0]), float(arr[1]), float(arr[2]))


def jsonable(value: Any) -> Any:
    """``value`` with numpy scalars/arrays made plain and non-finite floats made ``None``."""
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [jsonable(v) for v in (value.tolist() if isinstance(value, np.ndarray) else value)]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if value is None or isinstance(value, str):
        return value
    if hasattr(value, "value") and isinstance(value.value, str):  # str enums
        return value.value
    return str(value)


class Msg(BaseModel):
    """Base of every value: strict, frozen, no unknown fields, no NaN or infinity."""

    model_config = ConfigDict(strict=True, extra="forbid", frozen=True, allow_inf_nan=False)


class TrackingMsg(Msg):
    """One tracking sample (robot base frame, m), on the wire the ``tracking/*``,
    ``gripper/state`` and ``load_share`` messages of one stamp.

    Fields: ``seq`` sample counter, ``t`` robot time (s), ``stamp`` wall time (s),
    ``giver_hand``, ``receiver_hand``, ``giver_face`` (``[x, y, z]`` or ``null`` if not
    tracked), optional ``gripper_closed`` (bool) and ``load_share`` (0..1, share of the object's
    weight the robot carries).
    """

    seq: Seq
    t: float
    stamp: float
    giver_hand: Point | None = None
    receiver_hand: Point | None = None
    giver_face: Point | None = None
    gripper_closed: bool | None = None
    load_share: Unit | None = None

    @classmethod
    def from_frame(cls, frame: TrackingFrame, seq: int, stamp: float) -> TrackingMsg:
        return cls(
            seq=seq,
            t=float(frame.t),
            stamp=float(stamp),
            giver_hand=point_or_none(frame.giver_hand),
            receiver_hand=point_or_none(frame.receiver_hand),
            giver_face=point_or_none(frame.giver_face),
            gripper_closed=None if frame.gripper_closed is None else bool(frame.gripper_closed),
            load_share=None if frame.load_share is None else float(frame.load_share),
        )

    def to_frame(self) -> TrackingFrame:
        return TrackingFrame.make(
            self.t,
            giver_hand=self.giver_hand,
            receiver_hand=self.receiver_hand,
            giver_face=self.giver_face,
            gripper_closed=self.gripper_closed,
            load_share=self.load_share,
        )


class JointStateMsg(Msg):
    """``/joint_states``: measured joint positions by joint name (rad for revolute,
    m for prismatic joints; head, arm and gripper joints as the robot names them)."""

    seq: Seq
    t: float
    stamp: float
    position: dict[Name, float]


class HeadCommandMsg(Msg):
    """``head/command``: head joint goals (rad, finite, within the robot's limits), the goal's
    rate of change ``velocity`` (rad/s, by joint) and ``time_from_start`` (s, > 0) to reach it:
    one ``JointTrajectory`` point as ros2_control's joint_trajectory_controller takes it. ``t`` is
    the robot time the command answers (0 when the wire did not carry it)."""

    seq: Seq
    t: float
    stamp: float
    head: dict[Name, float]
    velocity: dict[Name, float] = Field(default_factory=dict)
    time_from_start: Annotated[float, Field(gt=0.0)] = 1.0 / 120.0

    @classmethod
    def from_command(
        cls,
        cmd: GazeCommand | LoopCommand,
        seq: int,
        stamp: float,
        previous: HeadCommandMsg | None = None,
        period: float = 1.0 / 120.0,
        max_period: float = 0.25,
    ) -> HeadCommandMsg:
        """The head part of an engine command. ``velocity`` is the goal's rate of change since
        ``previous`` (zero without one, or after a pause longer than ``max_period`` s);
        ``time_from_start`` the time since it (``period`` without one)."""
        head = {k: float(v) for k, v in cmd.head.items()}
        t = float(cmd.t)
        dt = t - previous.t if previous is not None else math.nan
        if previous is not None and 0.0 < dt <= max_period:
            velocity = {k: (q - previous.head.get(k, q)) / dt for k, q in head.items()}
        else:
            velocity, dt = dict.fromkeys(head, 0.0), period
        return cls(seq=seq, t=t, stamp=float(stamp), head=head, velocity=velocity,
                   time_from_start=dt)


class EyeStateMsg(Msg):
    """``eyes/state`` (``gazebot_msgs/EyeState``): eye direction on the display (rad; ``yaw``
    + = robot's left, ``pitch`` + = down), eyelid closure ``blink`` (0 open .. 1 closed) and
    ``distance`` (m, > 0) from the display (the head's ``gaze`` site) to the gaze target, for the
    eyes' vergence.

    ``distance`` ``None``: unknown (parallel eyes; NaN on the wire).
    """

    seq: Seq
    t: float
    stamp: float
    yaw: float
    pitch: float
    blink: Unit = 0.0
    distance: Annotated[float, Field(gt=0.0)] | None = None


class EyeFrameMsg(Msg):
    """``eyes/image/compressed`` (``sensor_msgs/CompressedImage``): one rendered display image,
    ``format`` png or jpeg, the encoded bytes in ``data``. Published only while someone
    subscribes."""

    seq: Seq
    t: float
    stamp: float
    format: Literal["png", "jpeg"] = "jpeg"
    data: bytes

    @classmethod
    def from_image(
        cls, img: np.ndarray, seq: int, t: float, stamp: float, fmt: Literal["png", "jpeg"] = "jpeg"
    ) -> EyeFrameMsg:
        """Encode an (H, W, 3) uint8 RGB image (JPEG by default: several times faster to
        encode than PNG at display sizes; PNG is lossless)."""
        return cls(seq=seq, t=float(t), stamp=float(stamp), format=fmt,
                   data=convert.encode_image(img, fmt))

    def image(self, max_size: tuple[int, int] | None = None) -> np.ndarray:
        """Decode to an (H, W, 3) uint8 RGB image of at most ``max_size`` (width, height;
        default :data:`gazebot.io.ros2.convert.MAX_IMAGE_SIZE`), checked from the header before
        decoding; :class:`PayloadError` if it is larger or does not decode."""
        try:
            return convert.decode_image(self.data, max_size or convert.MAX_IMAGE_SIZE)
        except MessageError as exc:
            raise PayloadError("EyeFrameMsg", f"data: {exc.reason}") from None


class ArmCommandMsg(Msg):
    """``arm/command`` (joint goals) or ``arm/mode`` (``home``, ``handover``, ``resume``): drive
    the arm, overriding the robot's own handover
    controller until ``resume`` is sent.

    Exactly one of ``positions`` (joint goals by name, rad; ``gripper`` 0..1), ``pose``
    (``home`` or ``handover`` from the robot config) or ``resume`` (``true``: hand the arm back to
    the robot's controller) is given. ``gripper`` (0 open .. 1 closed) may accompany
    ``positions`` or ``pose``.
    """

    seq: Seq
    t: float
    stamp: float
    positions: dict[Name, float] | None = None
    pose: Literal["home", "handover"] | None = None
    resume: bool = False
    gripper: Unit | None = None

    @model_validator(mode="after")
    def _one_goal(self) -> ArmCommandMsg:
        given = [self.positions is not None, self.pose is not None, self.resume]
        if sum(given) != 1:
            raise ValueError("exactly one of 'positions', 'pose' or 'resume' must be given")
        return self


# One category rule for the wire and the payloads (the phase stream: types.PHASE_STREAM_KINDS).
EventCategory = convert.EventCategory
category_of = convert.category_of


class EventMsg(Msg):
    """``events`` (``gazebot_msgs/HandoverEvent``): something happened.

    ``category``: ``phase`` (``reach_started`` ... ``handover_done``, ``tracking_lost``,
    ``tracking_restored``; from the engine's phase detector), ``robot`` (``robot_reach_started``
    ... from the robot's controller, ``info.planned_duration`` in s where known), ``behavior``
    (``behavior_state``: ``info.state``; ``gaze_target``: ``info.target``, ``info.point``),
    ``fault`` (``tracking_stale``, ``tracking_timeout`` with ``info.face``, ``tracking_resumed``,
    ``peer_lost``/``peer_restored`` with ``info.peer``, ``payload_dropped``) or ``node``
    (``node_started``, ``engine_resynced`` with ``info.events``, ``node_stopped``).
    ``source`` is the publishing node, ``seq`` its event counter (the publisher's sequence
    number on the wire); ``t`` when it happened,
    ``detected_at`` when it became known (robot clock, s).
    """

    seq: Seq
    source: Name
    category: EventCategory
    kind: Name
    t: float
    detected_at: float
    stamp: float
    info: dict[str, Any] = Field(default_factory=dict)

    @classmethod
    def from_event(
        cls, event: Event, source: str, seq: int, stamp: float
    ) -> EventMsg:
        kind = event.kind.value
        return cls(
            seq=seq,
            source=source,
            category=category_of(kind),
            kind=kind,
            t=float(event.t),
            detected_at=float(event.detected_at),
            stamp=float(stamp),
            info=jsonable(event.info),
        )

    @property
    def identity(self) -> tuple[str, str, int, int]:
        """The event across nodes and lives: source, kind, and its stamp and time to the
        nanosecond (the resolution of the wire's ``builtin_interfaces/Time``)."""
        return (self.source, self.kind, round(self.stamp * 1e9), round(self.t * 1e9))

    def to_event(self) -> Event | None:
        """The :class:`~gazebot.core.types.Event` for phase and robot events, ``None`` otherwise."""
        try:
            kind = EventKind(self.kind)
        except ValueError:
            return None
        return Event(kind=kind, t=self.t, detected_at=self.detected_at, info=dict(self.info))


class StatusMsg(Msg):
    """Heartbeat of ``node`` (a ``DiagnosticStatus`` on ``/diagnostics``) (every 0.5 s by default).

    ``state``: ``ok``, ``degraded`` (a peer is lost or tracking is not ``ok``) or ``stopping``.
    ``tracking``: ``ok`` (fresh samples), ``waiting`` (none yet), ``hold`` (samples stopped:
    holding the gaze), ``lost`` (timed out: looking at the last face), ``n/a`` (a node that
    does not consume tracking). ``peers``: liveliness of the other nodes seen (node -> alive).
    ``dropped``: malformed messages dropped so far, by topic. ``phase``: the engine's phase.
    """

    node: Name
    seq: Seq
    stamp: float
    uptime: NonNeg
    state: Literal["ok", "degraded", "stopping"]
    tracking: Literal["ok", "waiting", "hold", "lost", "n/a"] = "n/a"
    peers: dict[Name, bool] = Field(default_factory=dict)
    dropped: dict[str, Annotated[int, Field(ge=0)]] = Field(default_factory=dict)
    phase: str | None = None
    info: dict[str, Any] = Field(default_factory=dict)
