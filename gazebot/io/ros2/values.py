"""The values gazebot's nodes exchange that the core has no type for: a joint goal, the eye state
a display draws, an arm command, a measured joint state, an event as the bus carries it (with its
source and category) and a node's health. Everything else on the bus is one of the core's own
values (:class:`~gazebot.core.types.TrackingFrame`, :class:`~gazebot.core.types.GazeCommand`,
:class:`~gazebot.core.types.Event`) or a ROS 2 message; :mod:`gazebot.io.ros2.convert` maps
them to the messages and back.

Each value checks itself when built (finite numbers, ranges): a :class:`ValueError` names the
field. Units are SI (s, m, rad); ``t`` is the robot's clock, ``stamp`` the sender's wall clock.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np
import numpy.typing as npt

from gazebot.core.types import PHASE_STREAM_KINDS, Event, EventKind, GazeCommand, is_valid_point

#: A point (m, robot base frame).
Point = tuple[float, float, float]
#: JSON data as an event's info or a status' values carry it.
Json = str | int | float | bool | None | Sequence["Json"] | Mapping[str, "Json"]

EventCategory = Literal["phase", "robot", "behavior", "fault", "node"]
CATEGORIES: tuple[str, ...] = get_args(EventCategory)
NodeState = Literal["ok", "degraded", "error", "stopping"]
NodeTracking = Literal["ok", "waiting", "hold", "lost", "n/a"]
#: Longest node name, event kind or joint name accepted from the bus.
MAX_NAME = 64


def finite_point(p: npt.ArrayLike | None) -> Point | None:
    """``(x, y, z)`` of a finite point, ``None`` for a missing (NaN, ``None``) one."""
    if p is None:
        return None
    arr = np.asarray(p, dtype=float).reshape(-1)
    if arr.shape != (3,) or not is_valid_point(arr):
        return None
    return (float(arr[0]), float(arr[1]), float(arr[2]))


def plain(value: object) -> Json:
    """``value`` as JSON data: numpy scalars and arrays made plain, non-finite floats ``None``,
    str enums their value, anything else its ``str``."""
    if isinstance(value, Mapping):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if value is None or isinstance(value, str):
        return value
    enum_value = getattr(value, "value", None)
    return enum_value if isinstance(enum_value, str) else str(value)


def _finite(what: str, *values: float) -> None:
    for v in values:
        if not math.isfinite(v):
            raise ValueError(f"{what} is not finite: {v}")


def _finite_joints(what: str, joints: Mapping[str, float]) -> None:
    for name, v in joints.items():
        if not 0 < len(name) <= MAX_NAME:
            raise ValueError(f"{what}: joint name must be 1..{MAX_NAME} characters, got {name!r}")
        if not math.isfinite(v):
            raise ValueError(f"{what}.{name} is not finite: {v}")


@dataclass(frozen=True)
class JointGoal:
    """Joint goals as ros2_control's joint_trajectory_controller takes one streamed point
    (``head/command``, ``arm/command``): ``positions`` (rad, m; ``gripper`` 0..1) by joint, the
    goal's rate of change ``velocities`` (by joint; absent: 0) and ``time_from_start`` (s, > 0)
    to reach it. ``t`` is the robot time the goal answers."""

    t: float
    positions: dict[str, float]
    velocities: dict[str, float] = field(default_factory=dict)
    time_from_start: float = 1.0 / 120.0

    def __post_init__(self) -> None:
        _finite("t", self.t)
        _finite_joints("positions", self.positions)
        _finite_joints("velocities", self.velocities)
        if not (math.isfinite(self.time_from_start) and self.time_from_start > 0.0):
            raise ValueError(f"time_from_start must be > 0 s, got {self.time_from_start}")

    @classmethod
    def head_of(
        cls,
        cmd: GazeCommand,
        previous: JointGoal | None = None,
        period: float = 1.0 / 120.0,
        max_period: float = 0.25,
    ) -> JointGoal:
        """The head goal of an engine command. ``velocities`` is the goal's rate of change since
        ``previous`` (zero without one, or after a pause longer than ``max_period`` s);
        ``time_from_start`` the time since it (``period`` without one)."""
        head = {k: float(v) for k, v in cmd.head.items()}
        t = float(cmd.t)
        dt = t - previous.t if previous is not None else math.nan
        if previous is not None and 0.0 < dt <= max_period:
            velocity = {k: (q - previous.positions.get(k, q)) / dt for k, q in head.items()}
        else:
            velocity, dt = dict.fromkeys(head, 0.0), period
        return cls(t, head, velocity, dt)


@dataclass(frozen=True)
class EyeState:
    """What the eye display draws (``gazebot_msgs/EyeState``): eye direction (rad; ``yaw`` + =
    robot's left, ``pitch`` + = down), lid closure ``blink`` (0 open .. 1 closed) and
    ``distance`` (m, > 0; ``None`` unknown: parallel eyes) from the display to the gaze
    target, for vergence, at robot time ``t``."""

    t: float
    yaw: float
    pitch: float
    blink: float = 0.0
    distance: float | None = None

    def __post_init__(self) -> None:
        _finite("yaw/pitch/blink", self.t, self.yaw, self.pitch, self.blink)
        if not 0.0 <= self.blink <= 1.0:
            raise ValueError(f"blink must be within 0..1, got {self.blink}")
        d = self.distance
        if d is not None and not (math.isfinite(d) and d > 0.0):
            raise ValueError(f"distance must be > 0 m or unknown, got {d}")

    @classmethod
    def of(cls, cmd: GazeCommand) -> EyeState:
        """The eye state of an engine command."""
        return cls(float(cmd.t), float(cmd.eye_yaw), float(cmd.eye_pitch), float(cmd.blink),
                   None if cmd.distance is None else float(cmd.distance))


ArmPose = Literal["home", "handover"]


@dataclass(frozen=True)
class ArmCommand:
    """An arm command (``arm/command`` joint goals, ``arm/mode``): exactly one of ``positions``
    (joint goals by name, rad; ``gripper`` 0..1 among them), ``pose`` (``home`` or
    ``handover`` from the robot config) or ``resume`` (hand the arm back to the robot's own
    handover controller). ``gripper`` (0 open .. 1 closed) may accompany ``positions`` or
    ``pose``."""

    t: float = 0.0
    positions: dict[str, float] | None = None
    pose: ArmPose | None = None
    resume: bool = False
    gripper: float | None = None

    def __post_init__(self) -> None:
        given = [self.positions is not None, self.pose is not None, self.resume]
        if sum(given) != 1:
            raise ValueError("exactly one of 'positions', 'pose' or 'resume' must be given")
        if self.positions is not None:
            _finite_joints("positions", self.positions)
        if self.pose is not None and self.pose not in get_args(ArmPose):
            raise ValueError(f"pose must be one of {get_args(ArmPose)}, got {self.pose!r}")
        g = self.gripper
        if g is not None and not 0.0 <= g <= 1.0:
            raise ValueError(f"gripper must be within 0..1, got {g}")


@dataclass(frozen=True)
class JointState:
    """Measured joint positions (rad for revolute, m for prismatic joints) by name at robot
    time ``t`` (``/joint_states``)."""

    t: float
    position: dict[str, float]


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


@dataclass(frozen=True)
class BusEvent:
    """An event on the bus (``gazebot_msgs/HandoverEvent``): the core's
    :class:`~gazebot.core.types.Event` with who published it and how it is filed.

    ``category``: ``phase`` (``reach_started`` ... ``handover_done``, ``tracking_lost``,
    ``tracking_restored``), ``robot`` (``robot_reach_started`` ..., ``info.planned_duration``
    in s where known), ``behavior`` (``behavior_state``, ``gaze_target``), ``fault``
    (``tracking_stale``, ``peer_lost``, ``node_fault``, ...) or ``node`` (``node_started``,
    ``engine_resynced``, ``node_stopped``). ``source`` is the publishing node, ``seq`` its event
    counter (the publisher's sequence number on the wire); ``t`` when it happened,
    ``detected_at`` when it became known (robot clock, s), ``stamp`` the header's stamp.
    """

    source: str
    category: EventCategory
    kind: str
    t: float
    detected_at: float
    stamp: float
    info: dict[str, Json] = field(default_factory=dict)
    seq: int = 0

    def __post_init__(self) -> None:
        for name in ("source", "kind"):
            value = getattr(self, name)
            if not 0 < len(value) <= MAX_NAME:
                raise ValueError(f"{name} must be 1..{MAX_NAME} characters, got {len(value)}")
        if self.category not in CATEGORIES:
            raise ValueError(f"category must be one of {CATEGORIES}, got {self.category!r}")
        _finite("t/detected_at/stamp", self.t, self.detected_at, self.stamp)
        if self.seq < 0:
            raise ValueError(f"seq must be >= 0, got {self.seq}")

    @classmethod
    def of(cls, event: Event, source: str, stamp: float, seq: int = 0) -> BusEvent:
        """The bus event of a core :class:`~gazebot.core.types.Event` published by ``source``."""
        kind = event.kind.value
        info = {str(k): plain(v) for k, v in event.info.items()}
        return cls(source, category_of(kind), kind, float(event.t), float(event.detected_at),
                   float(stamp), info, seq)

    @property
    def identity(self) -> tuple[str, str, int, int]:
        """The event across nodes and lives: source, kind, and its stamp and time to the
        resolution of the wire's ``builtin_interfaces/Time`` (1 ns)."""
        return (self.source, self.kind, round(self.stamp * 1e9), round(self.t * 1e9))

    def to_event(self) -> Event | None:
        """The core :class:`~gazebot.core.types.Event` of a phase or robot kind, ``None``
        otherwise."""
        try:
            kind = EventKind(self.kind)
        except ValueError:
            return None
        return Event(kind=kind, t=self.t, detected_at=self.detected_at, info=dict(self.info))


#: ``DiagnosticStatus.level`` of a node's state (``stopping`` is a normal shutdown: OK).
LEVELS: dict[str, int] = {"ok": 0, "degraded": 1, "error": 2, "stopping": 0}


@dataclass(frozen=True)
class NodeStatus:
    """A node's heartbeat (one ``DiagnosticStatus`` named ``gazebot: <node>`` on
    ``/diagnostics``).

    ``state``: ``ok``, ``degraded`` (a peer is lost or tracking is not ``ok``), ``error`` or
    ``stopping``. ``tracking``: ``ok`` (fresh samples), ``waiting`` (none yet), ``hold``
    (samples stopped: holding the gaze), ``lost`` (timed out), ``n/a`` (a node that does not
    consume tracking). ``peers``: liveliness of the other nodes seen; ``dropped``: malformed
    messages dropped so far, by topic; ``phase``: the engine's phase; ``uptime`` in s.
    """

    node: str
    state: NodeState
    tracking: NodeTracking = "n/a"
    phase: str | None = None
    uptime: float = 0.0
    stamp: float = 0.0
    seq: int = 0
    peers: dict[str, bool] = field(default_factory=dict)
    dropped: dict[str, int] = field(default_factory=dict)
    info: dict[str, Json] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.state not in LEVELS:
            raise ValueError(f"state must be one of {tuple(LEVELS)}, got {self.state!r}")
        if self.tracking not in get_args(NodeTracking):
            raise ValueError(f"tracking must be one of {get_args(NodeTracking)}, "
                             f"got {self.tracking!r}")
        if not (math.isfinite(self.uptime) and self.uptime >= 0.0):
            raise ValueError(f"uptime must be >= 0 s, got {self.uptime}")
