"""Issue 33 on real handovers: the public YCB-Handovers recordings (a mocap suit's segment
origins, 0.23-0.39 m apart at the hold; 7.5 s windows that begin and end inside neighbouring
handovers), when they are on this machine. The bars are the issue's held-out ones, as shares
of the recordings whose right hands meet (the others hand over with the left); a window's
piece of a neighbouring handover is not the handover checked.

Measured on 43 such recordings (pairs 1-6; 35 careful handovers of a full pitcher or cup, 22
forward and 13 reverse, where the other participant gives; 8 of other objects or not careful):
offline 37 (the seed rule's own run cut by a one-frame marker glitch, by a regrip jolt before
the minimum distance, or broken by raw-speed noise and glitches around 15 cm/s in a quick
hold; a start 0.30 s before a run the seed rule restarts after a bump; two ends 0.05-0.11 s
before a closest point where the pair's common motion speeds up into the release), online
start 43, online reach on the final approach 37 (the others: a receiver who closes a fifth of
the gap before the giver moves), degraded copies 855 of 860. On 16 careful ones read on
2026-12-06 after those rules were set (handover 4, forward and reverse): offline 16, online
start 16, reach 13, degraded copies 316 of 320 (with the release not before the hands' last
closest point; 15 and 314 before). With 5 more read on 2026-12-07 (pairs 5 and 6), 21: offline
21 (20 before a giver's speed minimum while the hands still closed in stopped counting as its
departure), online start 21, reach 16, degraded copies 415 of 420: the reach share, 0.76, is
under this module's 0.8 bar (issue 33 stays open on it). On 9 more read on 2026-12-07 with
the rules unchanged (handover 5 or 6 of pairs 1-5): offline 7, online start 8, reach 6,
degraded copies 176 of 180 (the online share, 0.89, is under this module's 0.9 bar); with
20 of the 21 read again the same day (the same figures as before): offline 27, online start
28, reach 21, degraded copies 572 of 580 of 29. Once a reach taken back part of the way is
revised, a stall is 0.6 s and the final approach's gap starts after any 5 cm take-back:
reach 25 of 29 (3 receivers reaching first, one recording without its online start); the
others unchanged."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.ycb_data import assess, ycb_folders

FOLDERS = ycb_folders()
pytestmark = pytest.mark.skipif(
    not FOLDERS,
    reason="YCB-Handovers absent (github paragkhanna1/YCB-Handovers; set GAZEBOT_YCB_DATA)",
)


@pytest.fixture(scope="module")
def recordings():
    """The recordings whose right hands hold the object together, each scored once against
    the issue's bars (``benchmarks.ycb_data.assess``: the scoring ``python -m
    benchmarks.ycb_data`` prints per recording), with their degraded copies."""
    found = [a for a in (assess(folder, degrade=True) for folder in FOLDERS) if a.meets]
    if len(found) < 5:
        pytest.skip(f"only {len(found)} YCB-Handovers recordings whose right hands meet")
    return found


def test_offline_one_transfer_within_the_seed_rule_and_holding_the_closest_point(recordings):
    hits = [(a.name, a.offline) for a in recordings]
    assert np.mean([ok for _, ok in hits]) >= 0.8, hits


def test_online_transfer_starts_within_035_s_of_the_offline_start(recordings):
    hits = [(a.name, a.online) for a in recordings]
    assert np.mean([ok for _, ok in hits]) >= 0.9, hits


def test_online_reach_is_the_final_approach(recordings):
    # Confirmed between 1.0 s before and 0.15 s after the hands have closed 20 % of the gap
    # of the final approach (from where the hands were last farthest apart before the
    # transfer, after any approach taken back 5 cm): windows that begin with the giver's
    # earlier movements, lifts, pauses and approaches taken back.
    hits = [(a.name, a.reach, round(a.reach_lag, 2)) for a in recordings]
    assert np.mean([h[1] for h in hits]) >= 0.8, hits


def test_degraded_copies_keep_the_transfer(recordings):
    # 30 Hz, NaN bursts, 5 mm noise, 6 cm marker offsets, and all at once (4 copies each):
    # one transfer within 0.25 s of the clean recording's at both ends.
    # (assess makes copies only of recordings with one complete transfer)
    hits = [(a.name, *h) for a in recordings for h in a.degraded]
    assert np.mean([h[-1] for h in hits]) >= 0.97, [h for h in hits if not h[-1]]
