"""The base class of a phase method."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import SignalCache, Signals, compute_signals
from gazebot.core.phases.segment import Segment
from gazebot.core.phases.trajectory import Trajectory
from gazebot.core.types import Phase

# What one online period runs: the whole method, only the end-of-phase prediction, or nothing.
TriggerMode = Literal["full", "refresh", "skip"]


@dataclass(frozen=True)
class OnlineState:
    """What an online trigger reads of the detector at the end of a period.

    Attributes:
        phase: Current phase.
        phase_start: Its start (s; NaN in ``idle``).
        floor: The next phase never starts before this (s).
        tracking: False while tracking is lost.
        joined_late: The current phase began before the detector saw the hands move.
        last_full: When the method last ran (s).
    """

    phase: Phase
    phase_start: float
    floor: float
    tracking: bool
    joined_late: bool
    last_full: float


class OnlineTrigger(Protocol):
    """A method's cheap per-period check of whether its analysis needs to run."""

    def add(self, g: Sequence[float], g_ok: bool, r: Sequence[float], r_ok: bool) -> None:
        """Add one sample's giver (``g``) and receiver (``r``) hand positions; ``*_ok``: that hand
        was seen."""

    def decide(self, now: float, state: OnlineState) -> TriggerMode:
        """Close the period at ``now``: ``full`` (run the analysis), ``refresh`` (update the
        prediction only) or ``skip``."""


class Segmenter(ABC):
    """Splits a recording into reach, transfer and retreat segments per handover.

    Attributes:
        config: The settings (``config.method`` names the concrete class).
    """

    name: str = ""
    # Online, once the hands are in contact, the method's own :meth:`phase_end` rules end the
    # transfer and the retreat (else the detector reads those ends from the segments).
    rules_after_contact: bool = False

    def __init__(self, config: PhaseConfig) -> None:
        self.config = config

    @abstractmethod
    def segment_sorted(self, trajectory: Trajectory, partial: bool = False) -> list[Segment]:
        """Segments of a trajectory already sorted by time with unique times.

        ``partial``: the data are the samples seen so far by an online detector; a boundary the
        data do not yet show must not be guessed (the phase stays open).
        """

    def segment(self, trajectory: Trajectory) -> list[Segment]:
        """Segments of a whole recording (sorted first, see :meth:`Trajectory.cleaned`)."""
        traj, _, _ = trajectory.cleaned()
        return self.segment_sorted(traj)

    # ---- online hooks (the PhaseDetector calls these; the defaults re-run the whole method)
    def trigger(self) -> OnlineTrigger | None:
        """A fresh cheap trigger for one online detector, or ``None``: analyse every period."""
        return None

    def online_signals(
        self, trajectory: Trajectory, cache: SignalCache | None = None
    ) -> Signals | None:
        """The signals of the samples seen so far (for the end-of-phase prediction);
        ``cache``: the detector's, so a window that only grew is computed only where it
        changed (see :func:`~gazebot.core.phases.filtering.compute_signals`).

        The online detector's trajectories are read-only views of the samples it keeps (a
        method copies what it wants to change)."""
        return compute_signals(trajectory, self.config, cache) if len(trajectory) else None

    def online_segments(
        self, trajectory: Trajectory, s: Signals, now: float, phase: Phase = Phase.IDLE
    ) -> list[Segment]:
        """Segments of the samples seen so far (``s``: :meth:`online_signals` of them).

        ``phase``: the detector's current phase. In a reach, a method with
        ``rules_after_contact`` is read only for its transfers' starts and its segments' ends
        (the detector stops at contact), so it may leave its reach segments' starts unknown
        (NaN) then."""
        return self.segment_sorted(trajectory, partial=True)

    def phase_end(
        self, s: Signals, phase: Phase, phase_start: float, joined_late: bool
    ) -> tuple[float, str] | None:
        """For a method with ``rules_after_contact``: once in a transfer or retreat, when that
        phase ended (``(time, source)``), or ``None`` while it goes on."""
        raise NotImplementedError(f"{self.name} reads phase ends from its segments")


def central_speed(t: np.ndarray, p: np.ndarray, half: float) -> np.ndarray:
    """``|p(t + half) - p(t - half)| / (2 half)`` at every sample time, ``p`` linearly
    interpolated between its valid samples (NaN where ``t +- half`` leaves them)."""
    ok = np.isfinite(p).all(axis=1)
    out = np.full(t.shape[0], np.nan)
    if np.count_nonzero(ok) < 2:
        return out
    tv, pv = t[ok], p[ok]
    lo, hi = t - half, t + half
    inside = (lo >= tv[0] - 1e-9) & (hi <= tv[-1] + 1e-9)
    a = np.stack([np.interp(lo, tv, pv[:, k]) for k in range(3)], axis=1)
    b = np.stack([np.interp(hi, tv, pv[:, k]) for k in range(3)], axis=1)
    out[inside] = np.linalg.norm(b - a, axis=1)[inside] / (2.0 * half)
    return out
