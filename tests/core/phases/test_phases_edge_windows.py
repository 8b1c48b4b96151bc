"""Issue 33's fixed windows cut from a session of consecutive handovers: a window starts inside
the previous handover (mid-transfer, or at its release with both hands still extended) and ends
as the next one begins. The handover in the middle is found once, complete, with its own reach;
the edge pieces stay pieces (never a second complete handover); offline, a transfer under way
at the first sample is a piece without a reach."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.core.phases import PhaseConfig, Trajectory, run_online, segment
from gazebot.core.phases.synthetic import Hold, SyntheticOptions, generate
from gazebot.core.types import EventKind, Phase


def _cut(tr: Trajectory, a: float, b: float) -> Trajectory:
    m = (tr.t >= a) & (tr.t <= b)
    return Trajectory(tr.t[m], tr.giver_hand[m], tr.receiver_hand[m])


def _session_windows(seed: int, opts: SyntheticOptions, label: tuple) -> list:
    """The two windows of one session of three handovers (see the module docstring)."""
    case = generate(seed, opts)
    h0, h1, h2 = case.truth
    out = []
    for a in (0.5 * (h0.transfer_start + h0.transfer_end), h0.transfer_end + 0.05):
        # ends as the next handover begins (0.4 of its reach under way)
        b = h2.reach_start + 0.4 * (h2.transfer_start - h2.reach_start)
        out.append((_cut(case.trajectory, a, b), h1, (*label, a)))
    return out


def _windows():
    out = []
    for seed in range(12):
        for rate, noise in ((120.0, 0.0015), (30.0, 0.0015), (120.0, 0.003)):
            hold: Hold = "still" if seed % 2 else "pull"
            opts = SyntheticOptions(
                rate=rate, noise=noise, handovers=3, marker_offset=0.3, hold=hold
            )
            out += _session_windows(100 + seed, opts, (seed, hold, rate, noise))
    # Careful handovers (issue 33): the object carried together, or moved together while the
    # pair turns, at 30 Hz with 3 mm noise and at 60 Hz with short tracking dropouts.
    careful: tuple[tuple[int, Hold], ...] = (
        (2, "carry"),
        (3, "coupled"),
        (6, "carry"),
        (11, "coupled"),
    )
    for seed, hold in careful:
        for rate, noise, drop in ((30.0, 0.003, 0.0), (60.0, 0.003, 0.5)):
            opts = SyntheticOptions(
                rate=rate,
                noise=noise,
                handovers=3,
                marker_offset=0.3,
                hold=hold,
                dropouts_per_s=drop,
                irregular=0.1,
            )
            out += _session_windows(500 + seed, opts, (seed, hold, rate, noise, drop))
    return out


@pytest.fixture(scope="module")
def windows():
    return _windows()


def _middle(segs, h1):
    transfers = [s for s in segs if s.phase is Phase.TRANSFER]
    middle = [
        s
        for s in transfers
        if abs(s.start - h1.transfer_start) <= 0.3 and abs(s.end - h1.transfer_end) <= 0.3
    ]
    return transfers, middle


def test_the_middle_transfer_is_found_once_and_no_second_complete_handover(windows):
    for tr, h1, label in windows:
        segs = segment(tr, PhaseConfig())
        transfers, middle = _middle(segs, h1)
        assert len(middle) == 1, label
        # every other transfer is an edge piece: the first edge's (at the window start)
        assert all(s.start <= float(tr.t[0]) + 0.3 for s in transfers if s is not middle[0])
        # the last edge (a reach under way) is at most an open reach
        after = [s for s in segs if s.start > middle[0].end + 1e-9 and s.phase is not Phase.RETREAT]
        assert all(s.phase is Phase.REACH and s.open for s in after), label


def test_the_middle_handover_keeps_its_own_reach(windows):
    # (a window starting mid-transfer: the piece is a transfer from the first sample; at the
    # release: the piece's retreat runs until the hands are farthest apart, not into the reach)
    for tr, h1, label in windows:
        segs = segment(tr, PhaseConfig())
        _, middle = _middle(segs, h1)
        k = middle[0].handover
        reach = [s for s in segs if s.phase is Phase.REACH and s.handover == k]
        assert len(reach) == 1 and abs(reach[0].start - h1.reach_start) <= 0.3, label
        first = segs[0]
        assert first.phase is not Phase.REACH or first.handover == k, label


def test_online_the_middle_transfer_is_reported_once(windows):
    for tr, h1, label in windows:
        starts = [e.t for e in run_online(tr).events if e.kind is EventKind.TRANSFER_STARTED]
        assert sum(abs(t - h1.transfer_start) <= 0.35 for t in starts) == 1, label
        assert all(
            abs(t - h1.transfer_start) <= 0.35 or t <= float(tr.t[0]) + 0.3 for t in starts
        ), label
        assert np.isfinite(starts).all()


def test_online_the_reach_before_the_middle_transfer_is_its_final_approach(windows):
    # The held-out bar: confirmed between 1.0 s before and 0.15 s after the hands have closed
    # 20 % of the gap (the distances at the reach's start and at contact: medians over 0.1 s,
    # through noise and dropouts). Measured 88 of 88.
    for tr, h1, label in windows:
        d = np.linalg.norm(tr.receiver_hand - tr.giver_hand, axis=1)
        i0, i1 = np.searchsorted(tr.t, [h1.reach_start, h1.transfer_start])
        d0 = np.nanmedian(d[(tr.t >= h1.reach_start - 0.05) & (tr.t <= h1.reach_start + 0.05)])
        d1 = np.nanmedian(d[(tr.t >= h1.transfer_start - 0.1) & (tr.t <= h1.transfer_start)])
        fifth = tr.t[i0 + np.flatnonzero(d[i0:i1] <= d0 - 0.2 * (d0 - d1))[0]]
        events = run_online(tr).events
        k = next(
            i
            for i, e in enumerate(events)
            if e.kind is EventKind.TRANSFER_STARTED and abs(e.t - h1.transfer_start) <= 0.35
        )
        reach = [e for e in events[:k] if e.kind is EventKind.REACH_STARTED][-1]
        assert -1.0 <= reach.detected_at - fifth <= 0.15, label


def _ease(t, t0, t1, x0, x1):
    u = np.clip((t - t0) / (t1 - t0), 0.0, 1.0)
    return x0 + (x1 - x0) * (10 * u**3 - 15 * u**4 + 6 * u**5)


def test_hands_at_rest_a_metre_apart_at_the_first_sample_are_no_piece():
    # The giver stands 1.1 m from the receiver, steps back 12 cm, then hands over at 0.28 m.
    # The first samples are a dip (the recording's start counts as high ground) held still
    # and then left by min_approach, as a piece's hands are; but nothing is handed over a
    # metre apart. With 5 mm of noise on the KTH sample (hands 1.13 m apart, the distance
    # then rising 10 cm) that made a transfer piece at the start in 2 of 8 copies. A piece is
    # within the seed's distance margin of the closest the hands come later.
    t = np.arange(0.0, 6.0, 1 / 120)
    x = 1.1 + _ease(t, 0.8, 1.3, 0.0, 0.12) + _ease(t, 1.5, 2.7, 0.0, -0.82)
    x = x + _ease(t, 3.1, 4.3, 0.0, 0.7)
    receiver = np.tile([0.0, 0.0, 1.0], (t.size, 1))
    giver = receiver + np.stack([x, np.zeros_like(t), np.zeros_like(t)], axis=1)
    segs = segment(Trajectory(t, giver, receiver), PhaseConfig())
    assert [s.phase for s in segs] == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    assert 2.6 <= segs[1].start <= 2.8
