"""The JSON wire gazebot spoke before issue 18 (``gazebot/io/drivers/payloads.py`` at commit
039ef9b, the messages the benchmark compares; unchanged but for the models it does not use):
strict, frozen, versioned pydantic models serialized as JSON with ``"v": 1``. Kept here as the
peer of ``bench_messages``: the ROS 2 CDR messages replaced it on the bus.
"""

from __future__ import annotations

import base64
import math
from collections.abc import Mapping
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
)

from gazebot.core.types import Event, EventKind, TrackingFrame, is_valid_point

VERSION = 1

Point = tuple[float, float, float]
Unit = Annotated[float, Field(ge=0.0, le=1.0)]
NonNeg = Annotated[float, Field(ge=0.0)]
Seq = Annotated[int, Field(ge=0)]
Name = Annotated[str, Field(min_length=1, max_length=64)]

PHASE_KINDS = frozenset(
    {
        EventKind.REACH_STARTED,
        EventKind.TRANSFER_STARTED,
        EventKind.RETREAT_STARTED,
        EventKind.HANDOVER_DONE,
        EventKind.TRACKING_LOST,
        EventKind.TRACKING_RESTORED,
    }
)


class PayloadError(ValueError):
    """A payload could not be parsed; ``reason`` is a one-line explanation."""

    def __init__(self, model: str, reason: str):
        self.model = model
        self.reason = reason
        super().__init__(f"malformed {model} payload: {reason}")


class PayloadVersionError(PayloadError):
    """A well-formed payload of another protocol version (``version``: what it says, ``None``
    when it is not a JSON object with a ``v``)."""

    def __init__(self, model: str, version: Any):
        self.version = version
        super().__init__(model, f"v: payload version {version!r}, this gazebot speaks {VERSION}")


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
    """Base of every bus payload: strict, frozen, versioned."""

    model_config = ConfigDict(strict=True, extra="forbid", frozen=True, allow_inf_nan=False)

    v: Literal[1] = VERSION

    def encode(self) -> bytes:
        """The JSON bytes put on the bus."""
        return self.model_dump_json().encode()

    @classmethod
    def decode(cls, raw: bytes | bytearray | memoryview | str):
        """Parse ``raw`` JSON strictly; raise :class:`PayloadError` on anything malformed."""
        try:
            msg = cls.model_validate_json(raw if isinstance(raw, str) else bytes(raw))
        except ValidationError as exc:
            errors = exc.errors()
            for err in errors:  # another version first: its other fields may differ too
                if tuple(err["loc"]) == ("v",) and err["type"] != "missing":
                    raise PayloadVersionError(cls.__name__, err.get("input")) from None
            err = errors[0]
            where = ".".join(str(p) for p in err["loc"]) or "<root>"
            raise PayloadError(cls.__name__, f"{where}: {err['msg']}") from None
        # A payload from the bus must say its version; Python callers may leave the default.
        if "v" not in msg.model_fields_set:
            raise PayloadError(cls.__name__, "v: missing version field")
        return msg


class TrackingMsg(Msg):
    """``gazebot/<id>/tracking``: one tracking sample (robot base frame, m).

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


class HeadCommandMsg(Msg):
    """``gazebot/<id>/head/command``: head joint goals (rad, finite, within the robot's limits).

    ``answers`` is the ``seq`` of the tracking sample this command answers (``null`` for
    commands not caused by a sample, e.g. the tracking-timeout fallback). ``mode`` is
    ``behavior`` (the gaze behavior chose the target from tracking) or ``tracking_lost`` (the
    behavior's tracking-loss policy: holding the gaze, then looking at its ``tracking_lost``
    target, by default the last known face). ``phase``, ``target``, ``target_point`` and
    ``residual`` (rad) explain the command.
    """

    seq: Seq
    t: float
    stamp: float
    answers: Seq | None = None
    head: dict[Name, float]
    mode: Literal["behavior", "tracking_lost"] = "behavior"
    phase: Name
    target: Name
    target_point: Point | None = None
    residual: NonNeg = 0.0

    @classmethod
    def from_command(
        cls,
        cmd: Any,
        seq: int,
        stamp: float,
        answers: int | None = None,
        mode: Literal["behavior", "tracking_lost"] = "behavior",
    ) -> HeadCommandMsg:
        residual = float(cmd.residual)
        return cls(
            seq=seq,
            t=float(cmd.t),
            stamp=float(stamp),
            answers=answers,
            head={k: float(v) for k, v in cmd.head.items()},
            mode=mode,
            phase=str(getattr(cmd.phase, "value", cmd.phase)),
            target=str(cmd.target),
            target_point=point_or_none(cmd.target_point),
            residual=residual if math.isfinite(residual) and residual >= 0 else 0.0,
        )


class EyeStateMsg(Msg):
    """``gazebot/<id>/eyes``: eye direction on the display (rad; ``yaw`` + = robot's left,
    ``pitch`` + = down), eyelid closure ``blink`` (0 open .. 1 closed) and ``distance`` (m, > 0)
    from the display (the head's ``gaze`` site) to the gaze target, for the eyes' vergence.

    ``distance`` is optional within ``v: 1``: ``null`` or absent means unknown (parallel eyes),
    and it is left out of the JSON when unknown, so such messages read as before.
    """

    seq: Seq
    t: float
    stamp: float
    yaw: float
    pitch: float
    blink: Unit = 0.0
    distance: Annotated[float, Field(gt=0.0)] | None = None

    def encode(self) -> bytes:
        return self.model_dump_json(exclude_none=True).encode()


class EyeFrameMsg(Msg):
    """``gazebot/<id>/eyes/frame``: one rendered display image, ``format`` png or jpeg,
    base64 in ``data``, ``width`` x ``height`` px. Published only while someone subscribes."""

    seq: Seq
    t: float
    stamp: float
    width: Annotated[int, Field(gt=0, le=8192)]
    height: Annotated[int, Field(gt=0, le=8192)]
    format: Literal["png", "jpeg"] = "png"
    data: str

    @classmethod
    def from_image(
        cls, img: np.ndarray, seq: int, t: float, stamp: float, fmt: Literal["png", "jpeg"] = "jpeg"
    ) -> EyeFrameMsg:
        """Encode an (H, W, 3) uint8 RGB image (JPEG by default: several times faster to
        encode than PNG at display sizes; PNG is lossless)."""
        import cv2

        if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8:
            raise ValueError(f"expected an (H, W, 3) uint8 RGB image, got {img.shape} {img.dtype}")
        ok, buf = cv2.imencode(".png" if fmt == "png" else ".jpg", img[:, :, ::-1])
        if not ok:
            raise ValueError(f"could not encode the eye frame as {fmt}")
        return cls(
            seq=seq,
            t=float(t),
            stamp=float(stamp),
            width=int(img.shape[1]),
            height=int(img.shape[0]),
            format=fmt,
            data=base64.b64encode(buf.tobytes()).decode("ascii"),
        )

    def image(self) -> np.ndarray:
        """Decode to an (H, W, 3) uint8 RGB image; :class:`PayloadError` if it does not decode
        or its size differs from ``width`` x ``height``."""
        import cv2

        try:
            raw = base64.b64decode(self.data, validate=True)
        except ValueError as exc:
            raise PayloadError("EyeFrameMsg", f"data: not base64 ({exc})") from None
        img = cv2.imdecode(np.frombuffer(raw, np.uint8), cv2.IMREAD_COLOR)
        if img is None:
            raise PayloadError("EyeFrameMsg", f"data: not a decodable {self.format} image")
        if img.shape[:2] != (self.height, self.width):
            raise PayloadError(
                "EyeFrameMsg", f"image is {img.shape[1]}x{img.shape[0]}, "
                f"header says {self.width}x{self.height}"
            )
        return np.ascontiguousarray(img[:, :, ::-1])


EventCategory = Literal["phase", "robot", "behavior", "fault", "node"]


def category_of(kind: str) -> EventCategory:
    """``phase`` or ``robot`` for :class:`~gazebot.core.types.EventKind` values; ``fault`` else."""
    try:
        ek = EventKind(kind)
    except ValueError:
        return "fault"
    return "phase" if ek in PHASE_KINDS else "robot"


class EventMsg(Msg):
    """``gazebot/<id>/events``: something happened.

    ``category``: ``phase`` (``reach_started`` ... ``handover_done``, ``tracking_lost``,
    ``tracking_restored``; from the engine's phase detector), ``robot`` (``robot_reach_started``
    ... from the robot's controller, ``info.planned_duration`` in s where known), ``behavior``
    (``behavior_state``: ``info.state``; ``gaze_target``: ``info.target``, ``info.point``),
    ``fault`` (``tracking_stale``, ``tracking_timeout`` with ``info.face``, ``tracking_resumed``,
    ``peer_lost``/``peer_restored`` with ``info.peer``, ``payload_dropped``) or ``node``
    (``node_started``, ``engine_resynced`` with ``info.events``, ``node_stopped``).
    ``source`` is the publishing node, ``seq`` its event counter; ``t`` when it happened,
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

    def to_event(self) -> Event | None:
        """The :class:`~gazebot.core.types.Event` for phase and robot events, ``None`` otherwise."""
        try:
            kind = EventKind(self.kind)
        except ValueError:
            return None
        return Event(kind=kind, t=self.t, detected_at=self.detected_at, info=dict(self.info))
