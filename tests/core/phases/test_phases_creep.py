"""Hands that creep closer after the approach (issue 33, careful real handovers of a full cup or
pitcher): once the relative speed is under the seed's 15 cm/s, both hands adjusting to each other
for most of a second hold the object already, so the transfer starts at most
``approach_tail_max`` after that crossing even when the pair does not carry the object
together. One hand still arriving at a still one (a robot's slow gripper) has not reached it
yet: there the transfer starts where the approach stops."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.core.phases import PhaseConfig, Trajectory, segment
from gazebot.core.types import Phase

MEET, CREEP_END, PART = 2.0, 2.8, 3.8  # s
CREEP_START = MEET - 0.25  # the creep sets in as the approach slows: no pause between them


def _ease(t, t0, t1, x0, x1):
    u = np.clip((t - t0) / (t1 - t0), 0.0, 1.0)[:, None]
    return np.asarray(x0) + (np.asarray(x1) - np.asarray(x0)) * (10 * u**3 - 15 * u**4 + 6 * u**5)


def _creeping_handover(both: bool, noise: float = 0.0005, seed: int = 0) -> Trajectory:
    """The hands meet 0.35 m apart at MEET and close 3 cm more until CREEP_END (both hands
    1.5 cm each and 1 cm sideways, or the receiver alone 3 cm), hold still, and part at
    PART."""
    t = np.arange(0.0, 5.0, 1 / 120)
    rng = np.random.default_rng(seed)
    creep, side = (0.015, 0.01) if both else (0.0, 0.0)
    giver = (_ease(t, 1.0, MEET, [0.95, 0.0, 1.0], [0.6, 0.0, 1.0])
             + _ease(t, CREEP_START, CREEP_END, [0.0, 0.0, 0.0], [-creep, side, 0.0])
             + _ease(t, PART + 0.1, PART + 0.9, [0.0, 0.0, 0.0], [0.35, 0.0, 0.0]))
    receiver = (_ease(t, 1.1, MEET, [0.0, 0.0, 1.0], [0.25, 0.0, 1.0])
                + _ease(t, CREEP_START, CREEP_END, [0.0, 0.0, 0.0], [0.03 - creep, side, 0.0])
                + _ease(t, PART, PART + 0.8, [0.0, 0.0, 0.0], [-0.3, 0.0, 0.0]))
    return Trajectory(t, giver + rng.normal(0, noise, giver.shape),
                      receiver + rng.normal(0, noise, receiver.shape))


def _transfer(tr: Trajectory):
    (tr_seg,) = [s for s in segment(tr, PhaseConfig()) if s.phase is Phase.TRANSFER]
    return tr_seg


def _crossing(both: bool) -> float:
    """When the noise-free relative speed fell under the seed's 15 cm/s."""
    tr = _creeping_handover(both, noise=0.0)
    rel = tr.receiver_hand - tr.giver_hand
    v = np.linalg.norm(np.gradient(rel, tr.t, axis=0), axis=1)
    fast = np.flatnonzero((v >= 0.15) & (tr.t < CREEP_END))
    return float(tr.t[fast[-1]])


@pytest.mark.parametrize("seed", range(3))
def test_both_hands_creeping_in_hold_the_object_from_the_crossing(seed):
    tr = _creeping_handover(both=True, seed=seed)
    seg = _transfer(tr)
    limit = _crossing(both=True) + PhaseConfig().approach_tail_max
    assert seg.start <= limit + 0.05  # (the smoothing delays the crossing by ~20 ms)
    assert seg.start < CREEP_END - 0.5  # not where the creep ends
    assert abs(seg.end - PART) <= 0.15


@pytest.mark.parametrize("seed", range(3))
def test_one_hand_still_arriving_has_not_reached_the_object(seed):
    tr = _creeping_handover(both=False, seed=seed)
    seg = _transfer(tr)
    # The receiver's slow last 3 cm are its approach: the transfer starts as it stops.
    assert seg.start >= CREEP_END - 0.25
    assert abs(seg.end - PART) <= 0.15


def test_the_share_of_the_slower_hand_sets_the_gate():
    tr = _creeping_handover(both=True)
    strict = PhaseConfig(creep_balance=1.0)
    (seg,) = [s for s in segment(tr, strict) if s.phase is Phase.TRANSFER]
    # A balance no pair reaches: the creep counts as approach again.
    assert seg.start >= CREEP_END - 0.25
