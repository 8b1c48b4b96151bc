"""Handover phase detection: reach, transfer and retreat from tracked hands.

Both detectors use the seed's transfer rule (dissertation section 7.2.5: hands within 20 cm of
their minimum distance, relative speed under 15 cm/s) with every threshold in
:class:`PhaseConfig` (``configs/phases.yaml``).

- Offline, :func:`segment` splits a whole :class:`Trajectory` (see :func:`load_trajectory_csv`)
  into contiguous :class:`Segment` s per handover.
- Online, :class:`PhaseDetector` sees one :class:`~gazebot.types.TrackingFrame` at a time (what
  the engine runs): ``update(frame) -> Event | None`` with ``.phase``, ``.phase_start``,
  ``.expected_phase_end`` and ``.resync(event)``; :func:`run_online` replays a recording.
- :mod:`gazebot.phases.synthetic` generates handovers with known phase times for tests and
  benchmarks.
"""

from gazebot.phases.config import PhaseConfig, default_phase_config_path, load_phase_config
from gazebot.phases.offline import Signals, compute_signals, segment
from gazebot.phases.online import DetectorStats, OnlineResult, PhaseDetector, run_online
from gazebot.phases.segment import Segment, segments_from_events
from gazebot.phases.trajectory import Trajectory, TrajectoryFormatError, load_trajectory_csv

__all__ = [
    "DetectorStats",
    "OnlineResult",
    "PhaseConfig",
    "PhaseDetector",
    "Segment",
    "Signals",
    "Trajectory",
    "TrajectoryFormatError",
    "compute_signals",
    "default_phase_config_path",
    "load_phase_config",
    "load_trajectory_csv",
    "run_online",
    "segment",
    "segments_from_events",
]
