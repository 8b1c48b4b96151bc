"""Values that flow between gazebot's stages.

Data flows one way: ``TrackingFrame`` -> phases (``Event``) -> handover state -> behavior
(``GazeTarget``) -> kinematics -> ``GazeCommand``; the phase is the handover state's alone (the
phase detector reads it, the engine applies events to it). All quantities are SI (m, s, rad);
points are in the robot base frame unless a name says otherwise.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, fields, replace
from enum import Enum
from typing import Any, Literal

import numpy as np

NAN3 = np.full(3, np.nan)
#: NumPy's float64 dtype (the dtype of every point gazebot makes).
F64 = np.dtype(np.float64)

def finite_float(value: object) -> float | None:
    """``value`` as a float when it is a finite real number (Python or NumPy), else ``None``."""
    if not isinstance(value, numbers.Real):
        return None
    try:
        x = float(value)
    except OverflowError:  # an int beyond float's range
        return None
    return x if math.isfinite(x) else None


def as_point(value: Any) -> np.ndarray:
    """Return ``value`` as a float (3,) array; ``None`` becomes all-NaN (a missing sample)."""
    if value is None:
        return NAN3.copy()
    arr = np.asarray(value, dtype=float).reshape(-1)
    if arr.shape != (3,):
        raise ValueError(f"expected a 3D point, got shape {arr.shape}")
    return arr


def is_valid_point(p: np.ndarray | None) -> bool:
    """True when ``p`` is a finite 3D point."""
    if p is None:
        return False
    try:
        arr = np.asarray(p, dtype=float)
    except (TypeError, ValueError):
        return False
    return arr.shape == (3,) and bool(np.isfinite(arr).all())


class Phase(str, Enum):
    """Handover phase as seen by the receiver (seed section 6.2).

    ``idle`` is before a handover starts, ``done`` after it ended (until the next reach).
    """

    IDLE = "idle"
    REACH = "reach"
    TRANSFER = "transfer"
    RETREAT = "retreat"
    DONE = "done"


class EventKind(str, Enum):
    """Kinds of events the behavior layer reacts to.

    Phase events come from ``gazebot.core.phases``; robot events come from the robot's own
    controller (``GazeEngine.notify``), e.g. the planned duration of its reach.
    """

    REACH_STARTED = "reach_started"
    TRANSFER_STARTED = "transfer_started"
    RETREAT_STARTED = "retreat_started"
    HANDOVER_DONE = "handover_done"
    TRACKING_LOST = "tracking_lost"
    TRACKING_RESTORED = "tracking_restored"
    ROBOT_REACH_STARTED = "robot_reach_started"
    ROBOT_REACH_ENDED = "robot_reach_ended"
    ROBOT_GRASPED = "robot_grasped"
    ROBOT_RETREAT_STARTED = "robot_retreat_started"
    ROBOT_RETREAT_ENDED = "robot_retreat_ended"
    ROBOT_REACH_INFEASIBLE = "robot_reach_infeasible"  # no reach meets the timing (seed 3.2)
    ROBOT_RELEASED = "robot_released"  # robot-to-human: the robot let go of the object
    FAULT = "fault"  # a sample or event raised inside the engine; info names it and the error


#: The phase each phase event starts (the one event -> phase mapping; detector, handover state,
#: behaviors and the bus all read it).
PHASE_OF_EVENT: dict[EventKind, Phase] = {
    EventKind.REACH_STARTED: Phase.REACH,
    EventKind.TRANSFER_STARTED: Phase.TRANSFER,
    EventKind.RETREAT_STARTED: Phase.RETREAT,
    EventKind.HANDOVER_DONE: Phase.DONE,
}
#: The event that starts each phase (the inverse of :data:`PHASE_OF_EVENT`).
EVENT_OF_PHASE: dict[Phase, EventKind] = {p: k for k, p in PHASE_OF_EVENT.items()}
#: Events of the engine's phase stream (category ``phase`` on the bus): the
#: phase events and the tracking's loss and return.
PHASE_STREAM_KINDS: frozenset[EventKind] = frozenset(
    {*PHASE_OF_EVENT, EventKind.TRACKING_LOST, EventKind.TRACKING_RESTORED}
)

#: What the current phase was last decided by: the tracked hands (the phase detector), the
#: robot's own motion events, or its gripper / load-share sensors.
PhaseSource = Literal["tracking", "robot", "gripper"]
#: The behavior's tracking state: ``ok``, ``hold`` (tracking lost, the gaze held for the
#: behavior's ``tracking_lost.hold_s``) or ``lost`` (looking at its ``tracking_lost`` target);
#: ``waiting`` before the first sample.
TrackingState = Literal["waiting", "ok", "hold", "lost"]
#: ``ok``, or ``degraded`` when a sample or event of this tick raised inside the engine (reported
#: as a ``fault`` event; the command is still safe).
Status = Literal["ok", "degraded"]


@dataclass(frozen=True)
class Event:
    """Something that happened in a handover.

    Attributes:
        kind: What happened.
        t: Estimated time the thing happened (s). For online phase events this can be earlier
            than ``detected_at`` (the detector back-dates a phase start it confirms late).
        detected_at: Time the event became known (s).
        info: Extra data, e.g. ``{"planned_duration": 1.2}`` for robot motions or
            ``{"expected_end": 3.4}`` for a phase whose end is predicted.
    """

    kind: EventKind
    t: float
    detected_at: float
    info: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The event as a JSON object: ``kind``, ``t``, ``detected_at`` and the ``info`` keys."""
        return {"kind": self.kind.value, "t": self.t, "detected_at": self.detected_at, **self.info}


@dataclass(frozen=True)
class TrackingFrame:
    """One sample of tracked points (robot base frame, m) at time ``t`` (s).

    A missing point is all-NaN. ``gripper_closed`` and ``load_share`` are optional evidence the
    robot reports for the transfer phase (seed section 4.3): the gripper state and the share of
    the object's weight the robot carries (0..1).
    """

    t: float
    giver_hand: np.ndarray = field(default_factory=NAN3.copy)
    receiver_hand: np.ndarray = field(default_factory=NAN3.copy)
    giver_face: np.ndarray = field(default_factory=NAN3.copy)
    gripper_closed: bool | None = None
    load_share: float | None = None

    @classmethod
    def make(
        cls,
        t: float,
        giver_hand: Any = None,
        receiver_hand: Any = None,
        giver_face: Any = None,
        gripper_closed: bool | None = None,
        load_share: float | None = None,
    ) -> TrackingFrame:
        """Build a frame from anything array-like; ``None`` means missing."""
        return cls(
            t=float(t),
            giver_hand=as_point(giver_hand),
            receiver_hand=as_point(receiver_hand),
            giver_face=as_point(giver_face),
            gripper_closed=gripper_closed,
            load_share=load_share,
        )


@dataclass(frozen=True)
class GazeTarget:
    """Where the behavior wants the robot to look.

    ``kind`` is one of ``face``, ``hand``, ``object``, ``handover_location``, ``rest`` or a
    named point; ``point`` is its current position (base frame, m), NaN if unknown.
    """

    kind: str
    point: np.ndarray


@dataclass(frozen=True)
class GazeContext:
    """What a behavior sees at one tick besides the handover state: the time and the points.

    The phase is not here: the behavior reads it from the one
    :class:`~gazebot.core.handover.HandoverState` it is given.

    Attributes:
        t: Current time (s).
        points: Current 3D points by target name (base frame, m): at least ``face``, ``hand``,
            ``object``, ``handover_location`` and ``rest``; NaN where unknown.
        tracking_end: The phase detector's prediction of the current phase's end (s); NaN when
            unknown (or when the detector is not in the handover's phase).
    """

    t: float
    points: dict[str, np.ndarray]
    tracking_end: float = math.nan


@dataclass(frozen=True)
class GazeCommand:
    """The one command value, from the engine through the runtime loop to the wire
    (:mod:`gazebot.io.ros2.convert` maps it to the ROS messages; nothing else copies its
    fields).

    The engine fills everything but the lids and the vergence; the runtime loop adds ``blink``,
    ``distance`` and ``answers_sample`` with :meth:`replaced`.

    Attributes:
        t: Time of the tracking frame this answers (s).
        phase: The handover state's phase (the one the behavior runs).
        phase_source: What decided that phase: ``tracking``, ``robot`` or ``gripper``.
        target: Gaze target kind (``face``, ``hand``, ...).
        target_point: The 3D point looked at (base frame, m).
        head: Head joint goals by joint name (rad), finite and within the joint limits.
        eye_yaw: Eye yaw on the display (rad, + = robot's left), within the eye range.
        eye_pitch: Eye pitch on the display (rad, + = down), within the eye range.
        residual: Angle between the final line of sight (head + eyes) and the target (rad).
        gaze_shift: Angle (rad) the line of sight to the target turned since the previous tick
            (from the head's ``gaze`` frame); drives the blink model.
        tracking: The behavior's tracking state (see :data:`TrackingState`).
        status: ``ok`` or ``degraded`` (see :data:`Status`).
        blink: Lid closure, 0 open .. 1 closed (the runtime loop's blink model; 0 from the
            engine alone).
        distance: Distance (m) from the ``gaze`` frame to the target, for vergence; ``None``
            when unknown.
        answers_sample: Whether the tick answered a tracking sample (``False``: silence).
        events: Events that fired during this tick.
    """

    t: float
    phase: Phase
    target: str
    target_point: np.ndarray
    head: dict[str, float]
    eye_yaw: float
    eye_pitch: float
    residual: float = 0.0
    phase_source: PhaseSource = "tracking"
    gaze_shift: float = 0.0
    tracking: TrackingState = "ok"
    status: Status = "ok"
    blink: float = 0.0
    distance: float | None = None
    answers_sample: bool = True
    events: tuple[Event, ...] = ()

    def replaced(self, **changes: Any) -> GazeCommand:
        """This command with ``changes`` (field names) applied (:func:`dataclasses.replace`;
        a name that is no field is a ``TypeError`` naming it)."""
        unknown = changes.keys() - _COMMAND_FIELDS
        if unknown:
            raise TypeError(f"GazeCommand has no fields {sorted(unknown)}")
        return replace(self, **changes)

    def is_finite(self) -> bool:
        """True when every joint and eye value (and the time) is finite."""
        vals = [self.t, self.eye_yaw, self.eye_pitch, self.blink, *self.head.values()]
        return all(math.isfinite(v) for v in vals)


_COMMAND_FIELDS = frozenset(f.name for f in fields(GazeCommand))
