"""Handover phase detection: reach, transfer and retreat from tracked hands.

One entry point per use, every setting in :class:`PhaseConfig` (``configs/phases.yaml``),
``method`` choosing the rules:

- offline, :func:`segment` splits a whole :class:`Trajectory` into :class:`Segment` s;
- online, :func:`make_detector` gives the :class:`PhaseDetector` the engine runs (evidence:
  ``update(frame, view, report)`` reports the boundaries the tracking shows beyond the handover
  state's phase, which it reads through a read-only view); :class:`OnlineDetector` pairs one
  with a handover state of its own, and :func:`run_online` replays a recording through that.

Parts: :mod:`.filtering` (frozen samples, resampling, smoothing), :mod:`.rules` (one rule per
phase boundary of the ``gazebot`` method), :mod:`.methods` (``gazebot``, ``seed-7.2.5``,
``seed-4.4.3``), :mod:`.prediction` (end-of-phase prediction), :mod:`.detector` (online),
:mod:`.synthetic` (generated handovers with known phase times). Recording formats (CSV, C3D,
ROS bags) are read by :mod:`gazebot.io.recordings`.
"""

from gazebot.core.phases.config import (
    PhaseConfig,
    default_phase_config_path,
    load_phase_config,
)
from gazebot.core.phases.detector import (
    DetectorStats,
    OnlineDetector,
    OnlineResult,
    PhaseDetector,
    make_detector,
    run_online,
)
from gazebot.core.phases.filtering import Signals, compute_signals
from gazebot.core.phases.methods import make_segmenter
from gazebot.core.phases.segment import Segment, segments_from_events
from gazebot.core.phases.trajectory import Trajectory


def segment(trajectory: Trajectory, config: PhaseConfig | None = None) -> list[Segment]:
    """Split a whole recording into reach, transfer and retreat segments per handover, with
    ``config.method`` (default ``gazebot``). The trajectory is sorted by time first (duplicate
    times dropped). Within a handover the segments are contiguous; handovers never overlap. A
    recording cut short ends in the phase under way (``Segment.open``)."""
    return make_segmenter(config if config is not None else PhaseConfig()).segment(trajectory)


__all__ = [
    "DetectorStats",
    "OnlineDetector",
    "OnlineResult",
    "PhaseConfig",
    "PhaseDetector",
    "Segment",
    "Signals",
    "Trajectory",
    "compute_signals",
    "default_phase_config_path",
    "load_phase_config",
    "make_detector",
    "run_online",
    "segment",
    "segments_from_events",
]
