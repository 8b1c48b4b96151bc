"""Phase detection speed against a plain NumPy implementation of the seed's rule.

Offline: segments per second over a synthetic set (100-120 Hz, ~8 s recordings). Online: median
cost of one ``PhaseDetector.update`` per sample. The peer in both is the seed's rule (section
7.2.5: hands within 20 cm of their minimum distance and relative speed below 15 cm/s) written
the straightforward NumPy way; its accuracy on the same set is given in the notes.
"""

from __future__ import annotations

import math
import time

import numpy as np

from benchmarks.common import Result
from gazebot.phases import PhaseConfig, PhaseDetector, Segment, Trajectory, segment
from gazebot.phases.synthetic import SyntheticHandover, synthetic_set
from gazebot.types import Phase, TrackingFrame

MARGIN = 0.20  # m, seed
SPEED = 0.15  # m/s, seed


def seed_rule_segments(traj: Trajectory) -> list[Segment]:
    """The seed's rule on a whole recording, plainly: one transfer = the longest run where the
    distance is within 20 cm of its minimum and the relative speed below 15 cm/s."""
    ok = np.isfinite(traj.giver_hand).all(axis=1) & np.isfinite(traj.receiver_hand).all(axis=1)
    t = traj.t[ok]
    rel = traj.receiver_hand[ok] - traj.giver_hand[ok]
    d = np.linalg.norm(rel, axis=1)
    v = np.linalg.norm(np.gradient(rel, t, axis=0), axis=1)
    mask = (d <= d.min() + MARGIN) & (v < SPEED)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    starts, ends = edges[::2], edges[1::2] - 1
    if starts.size == 0:
        return []
    k = int(np.argmax(ends - starts))
    a, b = t[starts[k]], t[ends[k]]
    return [
        Segment(Phase.REACH, t[0], a),
        Segment(Phase.TRANSFER, a, b),
        Segment(Phase.RETREAT, b, t[-1]),
    ]


class SeedRuleOnline:
    """The seed's rule sample by sample with NumPy: running minimum distance, finite-difference
    relative speed."""

    def __init__(self) -> None:
        self.prev_q: np.ndarray | None = None
        self.prev_t = -math.inf
        self.d_min = math.inf
        self.in_transfer = False

    def update(self, frame: TrackingFrame) -> bool:
        q = frame.receiver_hand - frame.giver_hand
        if not np.all(np.isfinite(q)) or frame.t <= self.prev_t:
            return self.in_transfer
        d = float(np.linalg.norm(q))
        self.d_min = min(self.d_min, d)
        if self.prev_q is not None:
            v = float(np.linalg.norm((q - self.prev_q) / (frame.t - self.prev_t)))
            self.in_transfer = d <= self.d_min + MARGIN and v < SPEED
        self.prev_q, self.prev_t = q, frame.t
        return self.in_transfer


def _transfer_errors(cases: list[SyntheticHandover], fn) -> tuple[float, float]:
    """Median |error| (s) of the first transfer's start and end over single-handover cases."""
    es, ee = [], []
    for c in cases:
        tr = [s for s in fn(c.trajectory) if s.phase is Phase.TRANSFER]
        if tr:
            es.append(abs(tr[0].start - c.truth[0].transfer_start))
            ee.append(abs(tr[0].end - c.truth[0].transfer_end))
    return float(np.median(es)), float(np.median(ee))


def _interleaved(a, b, repeat: int) -> tuple[float, float]:
    """Median wall times (s) of ``a()`` and ``b()``, run alternately after one warm-up each."""
    a(), b()
    ta, tb = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        a()
        ta.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        b()
        tb.append(time.perf_counter() - t0)
    return float(np.median(ta)), float(np.median(tb))


def run() -> list[Result]:
    cases = synthetic_set(12, seed=7, rate=100.0, handovers=1)
    config = PhaseConfig()
    trajs = [c.trajectory for c in cases]

    def ours_offline() -> int:
        return sum(len(segment(tr, config)) for tr in trajs)

    def peer_offline() -> int:
        return sum(len(seed_rule_segments(tr)) for tr in trajs)

    n_ours, n_peer = ours_offline(), peer_offline()
    # Interleaved runs: on a shared machine both see the same load.
    t_ours, t_peer = _interleaved(ours_offline, peer_offline, repeat=9)
    (os_, oe), (ps, pe) = (
        _transfer_errors(cases, lambda tr: segment(tr, config)),
        _transfer_errors(cases, seed_rule_segments),
    )
    results = [
        Result(
            "offline segmentation",
            n_ours / t_ours,
            n_peer / t_peer,
            "segments/s",
            "NumPy seed rule",
            higher_is_better=True,
            note=(
                f"median |err| transfer start/end: ours {os_ * 1e3:.0f}/{oe * 1e3:.0f} ms, "
                f"seed rule {ps * 1e3:.0f}/{pe * 1e3:.0f} ms"
            ),
        )
    ]

    frames = cases[0].trajectory.frames()

    def one_pass(make):
        def run_pass() -> None:
            det = make()
            for f in frames:
                det.update(f)

        return run_pass

    ours, peer = _interleaved(
        one_pass(lambda: PhaseDetector(config)), one_pass(SeedRuleOnline), repeat=15
    )
    ours /= len(frames)
    peer /= len(frames)
    results.append(
        Result(
            "online update per sample",
            ours * 1e6,
            peer * 1e6,
            "us",
            "NumPy seed rule per sample",
            note=f"{len(frames)} samples at 100 Hz; engine budget 1000 us",
        )
    )
    return results
