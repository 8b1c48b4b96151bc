"""Issue 33's regression on the public dynamic-handover motions (30 Hz markerless body
tracking, many pairs on the move), when they are on this machine: no worse than the issue
found them (15 of 16 offline within 0.3 s of the seed rule's ends, 14 of 16 online starts
within 0.35 s, 58 of 64 degraded copies within 0.25 s), as shares of the motions among the
first 30 where the seed rule finds a transfer. Measured with ``python -m benchmarks.dyn_data``:
17 such motions, offline 16, online start 15, degraded copies 62 of 68 (the same on the tree
the issue was filed against, 57d18fb)."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.dyn_data import assess, dyn_files

FILES = dyn_files()
pytestmark = pytest.mark.skipif(
    not FILES,
    reason="dynamic-handover motions absent (github hyeonseong-kim98/dynamic_handover_dataset; "
    "set GAZEBOT_DYN_DATA)",
)


@pytest.fixture(scope="module")
def motions():
    """The first 30 motions where the seed rule finds a transfer, each scored once
    (``benchmarks.dyn_data.assess``), with their degraded copies."""
    return [a for a in (assess(path) for path in FILES[:30]) if a.scored]


def test_offline_transfer_within_the_seed_rule(motions):
    hits = [(a.name, a.offline) for a in motions]
    assert np.mean([ok for _, ok in hits]) >= 15 / 16, hits


def test_online_transfer_starts_within_035_s_of_the_offline_start(motions):
    hits = [(a.name, a.online) for a in motions]
    assert np.mean([ok for _, ok in hits]) >= 14 / 16, hits


def test_degraded_copies_keep_the_transfer(motions):
    hits = [(a.name, *h) for a in motions for h in a.degraded]
    assert np.mean([h[-1] for h in hits]) >= 58 / 64, [h for h in hits if not h[-1]]
