"""Handover phase detection: reach, transfer and retreat from tracked hands.

Offline :func:`segment` splits a whole recording; online :class:`PhaseDetector` sees one
:class:`~gazebot.types.TrackingFrame` at a time (what the engine runs). Both use the seed's
transfer rule (dissertation section 7.2.5) with thresholds from :class:`PhaseConfig`.
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
