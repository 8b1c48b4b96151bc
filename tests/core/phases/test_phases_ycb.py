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
under this module's 0.8 bar (issue 33 stays open on it)."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.ycb_data import HANDS, RATE, ycb_folders
from gazebot.core.phases import PhaseConfig, run_online, segment
from gazebot.core.types import EventKind, Phase
from gazebot.io.recordings import PointNames, load_recording
from tests.core.phases.degrade import KINDS, degraded

FOLDERS = ycb_folders()
pytestmark = pytest.mark.skipif(
    not FOLDERS,
    reason="YCB-Handovers absent (github paragkhanna1/YCB-Handovers; set GAZEBOT_YCB_DATA)",
)


def _meeting():
    """The recordings whose right hands hold the object together (closest under 0.6 m), each
    analysed once: name, trajectory, hands' distance, transfers (ours and the seed rule's) and
    the online events."""
    out = []
    for folder in FOLDERS:
        tr = load_recording(folder, PointNames(*HANDS), rate=RATE).trajectory
        d = np.linalg.norm(tr.giver_hand - tr.receiver_hand, axis=1)
        if np.nanmin(d) < 0.6:
            ours = _transfers(tr, PhaseConfig())
            seed = _transfers(tr, PhaseConfig(method="seed-7.2.5"), pieces=True)
            out.append((folder.name, tr, d, ours, seed, run_online(tr).events))
    return out


def _transfers(tr, config, pieces=False):
    """The transfers of complete handovers (reach, transfer and retreat): a window that begins
    or ends inside a neighbouring handover holds a piece of it, which is not the handover
    checked (the seed rule's transfers are all kept, pieces too)."""
    segs = segment(tr, config)
    whole = {s.handover for s in segs if s.phase is Phase.REACH}
    whole &= {s.handover for s in segs if s.phase is Phase.RETREAT}
    return [s for s in segs if s.phase is Phase.TRANSFER and (pieces or s.handover in whole)]


def _closest(tr, d, transfer) -> float:
    """When the hands were closest in this handover: between the farthest they were before the
    transfer and the farthest after it (a piece of a neighbouring handover may come closer)."""
    a, b = np.searchsorted(tr.t, [transfer.start, transfer.end])
    i0 = int(np.nanargmax(d[:a])) if a else 0
    i1 = int(b) + int(np.nanargmax(d[b:]))
    return float(tr.t[i0 + int(np.nanargmin(d[i0 : i1 + 1]))])


@pytest.fixture(scope="module")
def recordings():
    found = _meeting()
    if len(found) < 5:
        pytest.skip(f"only {len(found)} YCB-Handovers recordings whose right hands meet")
    return found


def test_offline_one_transfer_within_the_seed_rule_and_holding_the_closest_point(recordings):
    hits = []
    for name, tr, d, ours, seed, _ in recordings:
        ok = len(ours) == 1 and bool(seed)
        if ok:
            o = ours[0]
            s = min(seed, key=lambda x: abs(x.start - o.start))
            ok = abs(o.start - s.start) <= 0.3 and abs(o.end - s.end) <= 0.3
            ok = ok and o.start <= _closest(tr, d, o) <= o.end
        hits.append((name, ok))
    assert np.mean([ok for _, ok in hits]) >= 0.8, hits


def test_online_transfer_starts_within_035_s_of_the_offline_start(recordings):
    hits = []
    for name, _, _, ours, _, events in recordings:
        starts = [e.t for e in events if e.kind is EventKind.TRANSFER_STARTED]
        ok = len(ours) == 1 and sum(abs(t - ours[0].start) <= 0.35 for t in starts) == 1
        hits.append((name, ok))
    assert np.mean([ok for _, ok in hits]) >= 0.9, hits


def test_online_reach_is_the_final_approach(recordings):
    # Confirmed between 1.0 s before and 0.15 s after the hands have closed 20 % of the gap
    # of the final approach (from the farthest they were before the transfer): windows that
    # begin with the giver's earlier movements, lifts and pauses.
    hits = []
    for name, tr, d, ours, _, events in recordings:
        if len(ours) != 1:
            hits.append((name, False))
            continue
        i1 = int(np.searchsorted(tr.t, ours[0].start))
        i0 = int(np.nanargmax(d[:i1]))
        d0, d1 = d[i0], float(np.nanmedian(d[max(i1 - 12, 0) : i1 + 1]))
        fifth = tr.t[i0 + np.flatnonzero(d[i0:i1] <= d0 - 0.2 * (d0 - d1))[0]]
        k = [i for i, e in enumerate(events)
             if e.kind is EventKind.TRANSFER_STARTED and abs(e.t - ours[0].start) <= 0.35]
        reach = [e for e in events[: k[0]] if e.kind is EventKind.REACH_STARTED] if k else []
        hits.append((name, bool(reach) and -1.0 <= reach[-1].detected_at - fifth <= 0.15))
    assert np.mean([ok for _, ok in hits]) >= 0.8, hits


def test_degraded_copies_keep_the_transfer(recordings):
    # 30 Hz, NaN bursts, 5 mm noise, 6 cm marker offsets, and all at once (4 copies each):
    # one transfer within 0.25 s of the clean recording's at both ends.
    hits = []
    for name, tr, _, ours, _, _ in recordings:
        if len(ours) != 1:
            continue
        for how in [*KINDS, "all"]:
            for i in range(4):
                copy = degraded(tr, how, np.random.default_rng(100 + i))
                got = _transfers(copy, PhaseConfig())
                ok = (len(got) == 1 and abs(got[0].start - ours[0].start) <= 0.25
                      and abs(got[0].end - ours[0].end) <= 0.25)
                hits.append((name, how, i, ok))
    assert np.mean([h[-1] for h in hits]) >= 0.97, [h for h in hits if not h[-1]]
