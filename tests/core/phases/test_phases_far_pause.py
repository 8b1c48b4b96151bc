"""A giver who lifts the object, carries it part of the way and pauses 1.15 m from the receiver
before the final approach (a careful pitcher handover of the YCB-Handovers recordings, issue 33):
the hands are too far apart to hold one object there, so the pause is no transfer, online or
offline; the transfer is where the hands meet."""

from __future__ import annotations

import numpy as np

from gazebot.core.phases import PhaseConfig, Trajectory, run_online, segment
from gazebot.core.types import EventKind, Phase

MEET, PART = 4.0, 5.1  # s: the hands meet 0.33 m apart, hold, then the receiver pulls away


def _ease(t, t0, t1, x0, x1):
    u = np.clip((t - t0) / (t1 - t0), 0.0, 1.0)[:, None]
    return np.asarray(x0) + (np.asarray(x1) - np.asarray(x0)) * (10 * u**3 - 15 * u**4 + 6 * u**5)


def _lift_pause_then_hand_over(noise: float = 0.001, seed: int = 0) -> Trajectory:
    t = np.arange(0.0, 7.0, 1 / 120)
    rng = np.random.default_rng(seed)
    receiver0 = np.array([0.0, 0.0, 1.0])
    # The giver lifts the object and brings it 0.6 m closer (0.3-1.4 s), pauses 1.16 m from
    # the receiver (1.4-2.0 s), then both approach until they meet 0.33 m apart.
    giver = (_ease(t, 0.3, 1.4, [1.76, 0.0, 1.0], [1.16, 0.0, 1.0])
             + _ease(t, 2.0, MEET, [0.0, 0.0, 0.0], [-0.55, 0.0, 0.0]))
    receiver = _ease(t, 2.6, MEET, receiver0, [0.28, 0.0, 1.0])
    # Both carry it 10 cm together while they hold it, then the receiver pulls away.
    carry = _ease(t, MEET + 0.1, PART, [0.0, 0.0, 0.0], [0.0, 0.1, 0.0])
    away = _ease(t, PART, PART + 0.9, [0.0, 0.0, 0.0], [-0.6, 0.0, 0.0])
    giver = giver + carry
    receiver = receiver + carry + away
    return Trajectory(t, giver + rng.normal(0, noise, giver.shape),
                      receiver + rng.normal(0, noise, receiver.shape))


def test_the_pause_far_from_the_receiver_is_no_transfer_online():
    tr = _lift_pause_then_hand_over()
    d = np.linalg.norm(tr.giver_hand - tr.receiver_hand, axis=1)
    assert 1.1 < d[(tr.t > 1.5) & (tr.t < 1.9)].min() and d.min() < 0.35  # the case's shape
    starts = [e.t for e in run_online(tr).events if e.kind is EventKind.TRANSFER_STARTED]
    # Before max_hold_distance, the pause was a transfer and the real one never came.
    assert len(starts) == 1 and abs(starts[0] - MEET) <= 0.35


def test_the_pause_far_from_the_receiver_is_no_transfer_offline():
    transfers = [s for s in segment(_lift_pause_then_hand_over(), PhaseConfig())
                 if s.phase is Phase.TRANSFER]
    assert len(transfers) == 1 and abs(transfers[0].start - MEET) <= 0.3
    assert abs(transfers[0].end - PART) <= 0.3


def test_max_hold_distance_is_what_rejects_the_pause():
    tr = _lift_pause_then_hand_over()
    far = PhaseConfig(max_hold_distance=1.5)  # a pause this far counts as a hold again
    starts = [e.t for e in run_online(tr, far).events if e.kind is EventKind.TRANSFER_STARTED]
    assert starts and starts[0] < 2.5
