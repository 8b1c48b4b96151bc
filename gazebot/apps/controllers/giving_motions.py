"""A database of human giving motions for the seed's Table 4.4 (section 4.4.3): each motion is
the giver's hand over a whole handover, split into reach, transfer and retreat by the seed's
rule, in the robot's base frame, with where the receiving robot's gripper starts.

The seed's segmentation (4.4.3), quoted: "The reach phase begins at the time instant after
which the distance from the starting position becomes greater than d_1 x d_max. The reach phase
ends (and the transfer phase begins) when the speed drops below v_1 x v_max." Speed "is positive
if the hand is moving away from the starting position", i.e. the rate of change of that
distance. "A phase is valid if its end is detected before the end of the trajectory and if its
duration is non-zero." The seed's sweep found ``d_1 = 0.41``, ``v_1 = 0.43``.

Two sources: recordings gazebot reads (:func:`motion_from_recording`; the robot stands in for
the receiver: its base at the receiver's shoulder, its gripper starting at the receiver's
hand), and the simulator's giver (:func:`gazebot.apps.sim.giving_motions.simulated_motions`,
which builds on :func:`motion_from_path`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

SEED_D1 = 0.41  # fraction of the largest distance from the start at which the reach begins
SEED_V1 = 0.43  # fraction of the peak speed below which the reach ends
# "The sampling rate of the sensors is 7 Hz" (4.4.3): the rule above was tuned on such samples,
# so every path is resampled to this rate before it is split (at a mocap's 120 Hz the
# differentiated distance is noisy enough to end a reach within one sample).
SEED_RATE_HZ = 7.0


@dataclass(frozen=True)
class GivingMotion:
    """One giver's hand path (robot base frame, m) sampled at ``t`` (s), with the robot's
    gripper start and the reach phase found by :func:`seed_reach_phase` (indices into ``t``)."""

    name: str
    t: np.ndarray
    hand: np.ndarray  # (N, 3)
    robot_start: np.ndarray  # (3,)
    reach_start: int
    reach_end: int

    @property
    def reach_duration_s(self) -> float:
        return float(self.t[self.reach_end] - self.t[self.reach_start])

    def hand_at(self, t: float | np.ndarray) -> np.ndarray:
        """The hand at time(s) ``t`` (s), linearly interpolated, held beyond the ends."""
        tt = np.atleast_1d(np.asarray(t, float))
        out = np.column_stack([np.interp(tt, self.t, self.hand[:, i]) for i in range(3)])
        return out[0] if np.ndim(t) == 0 else out


def seed_reach_phase(
    t: np.ndarray, hand: np.ndarray, d1: float = SEED_D1, v1: float = SEED_V1
) -> tuple[int, int] | None:
    """``(start, end)`` sample indices of the reach phase by the seed's rule (module doc), or
    None when no valid reach phase is found (no end before the trajectory's end, or zero
    duration)."""
    hand = np.asarray(hand, float)
    t = np.asarray(t, float)
    if len(t) < 3 or not np.all(np.isfinite(hand)):
        return None
    dist = np.linalg.norm(hand - hand[0], axis=1)
    speed = np.gradient(dist, t)  # signed: positive moving away from the start
    d_max, v_max = float(dist.max()), float(speed.max())
    if d_max <= 0 or v_max <= 0:
        return None
    far = np.flatnonzero(dist > d1 * d_max)
    if not far.size:
        return None
    start = int(far[0])
    slow = np.flatnonzero(speed[start + 1 :] < v1 * v_max)
    if not slow.size:
        return None
    end = start + 1 + int(slow[0])
    if end >= len(t) - 1 or t[end] <= t[start]:
        return None
    return start, end


def resample(t: np.ndarray, points: np.ndarray, rate_hz: float = SEED_RATE_HZ):
    """``(t', points')``: ``points`` (N, 3) at ``t`` linearly interpolated every ``1 / rate_hz``
    s from ``t[0]``."""
    t = np.asarray(t, float)
    tt = np.arange(t[0], t[-1] + 1e-9, 1.0 / rate_hz)
    points = np.asarray(points, float)
    return tt, np.column_stack([np.interp(tt, t, points[:, i]) for i in range(3)])


def motion_from_path(
    name: str, t: np.ndarray, hand: np.ndarray, robot_start: np.ndarray
) -> GivingMotion | None:
    """A :class:`GivingMotion` from a hand path resampled at the seed's 7 Hz, None when the
    seed's rule finds no valid reach phase in it."""
    t, hand = resample(t, hand)
    phase = seed_reach_phase(t, hand)
    if phase is None:
        return None
    return GivingMotion(name, t, hand, np.asarray(robot_start, float), *phase)


def motion_from_recording(
    path: str | Path,
    giver_hand: str,
    receiver_hand: str,
    receiver_base: str,
    rate: float | None = None,
) -> GivingMotion | None:
    """The giving motion of a human-human recording: positions relative to the receiver's
    ``receiver_base`` point (e.g. the shoulder) at the first sample, the robot's gripper
    starting where the receiver's hand is at the reach's start. None: no valid reach phase.

    Raises:
        RecordingError: the recording cannot be read or lacks a named point (the reader's
            message names the file and the names it has).
    """
    from gazebot.io.recordings import PointNames, load_recording

    rec = load_recording(path, PointNames(giver_hand, receiver_hand, receiver_base), rate=rate)
    tr = rec.trajectory
    base = tr.giver_face[0]  # the third point: here the receiver's base point, not a face
    ok = np.all(np.isfinite(tr.giver_hand), axis=1) & np.all(np.isfinite(tr.receiver_hand), axis=1)
    t, hand, recv = tr.t[ok], tr.giver_hand[ok] - base, tr.receiver_hand[ok] - base
    t7, hand7 = resample(t, hand)
    phase = seed_reach_phase(t7, hand7)
    if phase is None:
        return None
    start = np.array([np.interp(t7[phase[0]], t, recv[:, i]) for i in range(3)])
    return GivingMotion(Path(path).name, t7, hand7, start, *phase)
