"""The timing of one rendered handover video, kept next to it: ``NAME.json`` beside ``NAME.mp4``.

``reach_start_time`` is the seed's (6.4: "the difference between the start of the human hand's
reaching motion and the start of the robot arm's reaching motion"): the giver's reach start minus
the robot's (s; positive when the robot started first). The other times are seconds from the
video's start: the robot's own events (when each first happened) and the handover phases as the
gaze engine saw them (the first control tick in each phase). ``None``: not known (the event never
happened, or the renderer reports no times, e.g. the synthetic dry-run renderer).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

from gazebot.io.atomic import atomic_path

__all__ = ["TIME_COLUMNS", "VideoTimes", "read_video_times", "times_path", "write_video_times"]

PHASES = ("reach", "transfer", "retreat", "done")
# Columns of ``videos.csv`` after the video's spec, in this order.
TIME_COLUMNS = (
    "reach_start_time",
    "robot_reach_start",
    "giver_reach_start",
    *(f"{p}_phase_start" for p in PHASES),
    "duration",
)


@dataclass(frozen=True)
class VideoTimes:
    """What happened when in one handover video (s; ``None`` = unknown; see the module doc)."""

    reach_start_time: float | None = None
    robot_reach_start: float | None = None
    giver_reach_start: float | None = None
    phase_starts: dict[str, float] = field(default_factory=dict)  # engine phase -> first tick
    robot_events: dict[str, float] = field(default_factory=dict)  # event kind -> first time
    duration: float | None = None  # last control tick (s)
    completed: bool | None = None  # the handover finished before the renderer's cut-off

    def row(self) -> list[str]:
        """The :data:`TIME_COLUMNS` cells (``""`` for unknown, seconds to the millisecond)."""
        values = (
            self.reach_start_time,
            self.robot_reach_start,
            self.giver_reach_start,
            *(self.phase_starts.get(p) for p in PHASES),
            self.duration,
        )
        return [fmt_seconds(v) for v in values]

    @classmethod
    def from_recording(cls, rec) -> VideoTimes:
        """The times of a :class:`gazebot.apps.sim.record.HandoverRecording`."""
        phase_starts: dict[str, float] = {}
        for tick in rec.ticks:
            phase_starts.setdefault(str(tick.phase), float(tick.t))
        robot_events: dict[str, float] = {}
        for ev in rec.robot_events:
            robot_events.setdefault(ev.kind.value, float(ev.t))
        rst = rec.ticks[-1].reach_start_time if rec.ticks else math.nan
        rst = float(rst) if math.isfinite(rst) else None
        robot = robot_events.get("robot_reach_started")
        return cls(
            reach_start_time=rst,
            robot_reach_start=robot,
            giver_reach_start=None if rst is None or robot is None else robot + rst,
            phase_starts={p: t for p, t in phase_starts.items() if p in PHASES},
            robot_events=robot_events,
            duration=float(rec.ticks[-1].t) if rec.ticks else None,
            completed=bool(rec.completed),
        )


def fmt_seconds(v: float | None) -> str:
    return "" if v is None else f"{v:.3f}"


def times_path(video: str | Path) -> Path:
    """The sidecar of ``video``: the same name with ``.json``."""
    return Path(video).with_suffix(".json")


def write_video_times(video: str | Path, times: VideoTimes) -> Path:
    """Write ``times`` as ``video``'s sidecar (atomically) and return its path."""
    path = times_path(video)
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(asdict(times), indent=2, sort_keys=True), encoding="utf-8")
    return path


def _seconds(path: Path, data: dict, key: str) -> float | None:
    v = data.get(key)
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ValueError(
            f"{path}: field {key!r} must be a finite number of seconds or null, got {v!r}"
        )
    return float(v)


def _seconds_map(path: Path, data: dict, key: str) -> dict[str, float]:
    m = data.get(key) or {}
    if not isinstance(m, dict):
        raise ValueError(f"{path}: field {key!r} must map names to seconds, got {m!r}")
    out = {str(k): _seconds(path, m, k) for k in m}
    return {k: v for k, v in out.items() if v is not None}


def read_video_times(video: str | Path) -> VideoTimes | None:
    """``video``'s sidecar, or ``None`` if it has none; a malformed one raises ``ValueError``
    naming the file and the field."""
    path = times_path(video)
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path}: not a JSON video-times file ({exc})") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path}: expected a JSON object of video times")
    completed = data.get("completed")
    if completed is not None and not isinstance(completed, bool):
        raise ValueError(f"{path}: field 'completed' must be true, false or null")
    return VideoTimes(
        reach_start_time=_seconds(path, data, "reach_start_time"),
        robot_reach_start=_seconds(path, data, "robot_reach_start"),
        giver_reach_start=_seconds(path, data, "giver_reach_start"),
        phase_starts=_seconds_map(path, data, "phase_starts"),
        robot_events=_seconds_map(path, data, "robot_events"),
        duration=_seconds(path, data, "duration"),
        completed=completed,
    )
