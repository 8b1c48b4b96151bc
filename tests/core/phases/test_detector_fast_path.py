"""The online detector's fast path (fused signals computed only where new samples change
them, the trigger's per-period rows in plain floats with running maxima and sums, samples kept
in one array, no reach onsets dated during a reach) emits exactly the events and counts of the
straightforward path it replaced (tests/core/phases/signals_reference.py,
tests/core/phases/trigger_reference.py) on the synthetic set, the issue-20 cases, a long rest, and
on
noisy input with NaN, frozen, duplicate, out-of-order and timeless samples."""

from __future__ import annotations

import numpy as np
import pytest

import gazebot.core.phases.methods.gazebot as gazebot_method
from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.detector import run_online
from gazebot.core.phases.filtering import Signals
from gazebot.core.phases.synthetic import (
    SyntheticOptions,
    case_set,
    early_lift_set,
    generate,
    synthetic_set,
)
from gazebot.core.phases.trajectory import Trajectory
from tests.core.phases.signals_reference import reference_signals
from tests.core.phases.trigger_reference import ReferenceTrigger


def _damaged(traj: Trajectory, seed: int) -> Trajectory:
    """NaN rows and coordinates, frozen repeats, a long gap, swapped (out-of-order) and
    duplicated times, NaN times."""
    rng = np.random.default_rng(seed)
    t, g, r = traj.t.copy(), traj.giver_hand.copy(), traj.receiver_hand.copy()
    n = t.shape[0]
    g[rng.choice(n, n // 20, replace=False)] = np.nan
    r[rng.choice(n, n // 40, replace=False), 1] = np.nan
    for k in rng.choice(n - 5, 8, replace=False):
        g[k + 1 : k + 4] = g[k]
    for k in rng.choice(n - 2, 6, replace=False):
        t[[k, k + 1]] = t[[k + 1, k]]
    for k in rng.choice(n - 2, 4, replace=False):
        t[k + 1] = t[k]
    t[rng.choice(n, 3, replace=False)] = np.nan
    k = n // 2
    g[k : k + n // 10] = np.nan
    return Trajectory(t, g, r, traj.giver_face, traj.gripper_closed, traj.load_share)


def _recordings() -> list[Trajectory]:
    out = []
    for i, h in enumerate(synthetic_set(10, seed=7)):
        out += [h.trajectory, _damaged(h.trajectory, i)]
    for kind in ("carry", "still", "quick30", "quick_noisy"):
        out += [h.trajectory for h in case_set(kind, 2, seed=1)]  # type: ignore[arg-type]
    out += [h.trajectory for h in early_lift_set(2, seed=1)]
    noisy = SyntheticOptions(
        rate=30.0, irregular=0.3, noise=0.004, dropouts_per_s=1.0, frozen_per_s=1.0, handovers=3
    )
    out.append(generate(seed=2, options=noisy).trajectory)
    out.append(_after_long_rest(generate(seed=3, options=SyntheticOptions(rate=60.0)).trajectory))
    return out


def _after_long_rest(traj: Trajectory, rest: float = 7.0) -> Trajectory:
    """``traj`` after ``rest`` s of both hands resting where it starts (2 mm noise): longer
    than the online window, so the detector's and the trigger's windows slide while idle."""
    rng = np.random.default_rng(0)
    dt = float(traj.t[1] - traj.t[0])
    t0 = np.arange(0.0, rest, dt)
    g0 = traj.giver_hand[0] + rng.normal(0.0, 0.002, (t0.shape[0], 3))
    r0 = traj.receiver_hand[0] + rng.normal(0.0, 0.002, (t0.shape[0], 3))
    return Trajectory(
        np.concatenate([t0, traj.t - traj.t[0] + rest]),
        np.concatenate([g0, traj.giver_hand]),
        np.concatenate([r0, traj.receiver_hand]),
    )


def _events(traj: Trajectory, config: PhaseConfig) -> tuple[list[tuple], str]:
    res = run_online(traj, config)
    return [(e.kind, e.t, e.detected_at, sorted(e.info.items())) for e in res.events], repr(
        res.stats
    )


def _first_rows(s: Signals, until: float) -> Signals:
    """The grid rows of ``s`` at or before ``until`` (the edge guard's cut, in full)."""
    keep = int(np.searchsorted(s.t, until, side="right"))
    return Signals(*[np.array(a[:keep]) for a in vars(s).values()])


@pytest.fixture(scope="module")
def recordings() -> list[Trajectory]:
    return _recordings()


def test_fast_detector_emits_what_the_straightforward_one_emits(recordings, monkeypatch):
    config = PhaseConfig()
    fast = [_events(tr, config) for tr in recordings]
    # (the reference computes every analysis in full: the detector's signal cache is unused)
    monkeypatch.setattr(
        gazebot_method,
        "compute_signals",
        lambda traj, config, cache=None, until=np.inf: _first_rows(
            reference_signals(traj, config), until
        ),
    )
    monkeypatch.setattr(
        gazebot_method.GazebotSegmenter, "trigger", lambda self: ReferenceTrigger(self.config)
    )
    # (every analysis dates the reach onsets, in a reach too)
    segments = gazebot_method.GazebotSegmenter.online_segments
    monkeypatch.setattr(
        gazebot_method.GazebotSegmenter,
        "online_segments",
        lambda self, traj, s, now, phase=None: segments(self, traj, s, now),
    )
    slow = [_events(tr, config) for tr in recordings]
    assert sum(len(ev) for ev, _ in fast) > 4 * len(recordings)  # the recordings do show phases
    for i, (a, b) in enumerate(zip(fast, slow, strict=True)):
        assert a == b, f"recording {i}"


def test_of_hands_builds_the_trajectory_the_constructor_builds():
    rng = np.random.default_rng(2)
    t, g, r = np.sort(rng.random(40)), rng.random((40, 3)), rng.random((40, 3))
    g[5] = np.nan
    ref, fast = Trajectory(t, g, r), Trajectory.of_hands(t, g, r)
    # (and from a caller's all-NaN block, as the detector passes one)
    given = Trajectory.of_hands(t, g, r, np.full((40, 5), np.nan))
    for name in ("t", "giver_hand", "receiver_hand", "giver_face", "gripper_closed",
                 "load_share"):
        a, b, c = getattr(ref, name), getattr(fast, name), getattr(given, name)
        assert a.shape == b.shape == c.shape and a.dtype == b.dtype == c.dtype
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)



def test_the_predicted_end_reads_the_peak_np_nanargmax_finds():
    from gazebot.core.phases.prediction import _mirrored

    def reference(t, v, onset, nominal, now, c):  # with np.nanargmax, of the speeds read
        v = np.where(t <= now - c.smoothing, v, np.nan)
        ok = np.isfinite(v)
        if not ok.any():
            return onset + nominal
        i = int(np.nanargmax(v))
        peak, last = float(v[i]), float(v[np.flatnonzero(ok)[-1]])
        if peak > c.reach_onset_speed and last < c.peak_passed_fraction * peak:
            return onset + 2.0 * max(float(t[i]) - onset, 0.0)
        return onset + nominal

    c = PhaseConfig()
    rng = np.random.default_rng(4)
    for _ in range(2000):
        n = int(rng.integers(1, 30))
        t = np.arange(n) / 100.0
        v = np.round(rng.random(n), 1)  # ties: the first largest wins
        v[rng.random(n) < 0.3] = np.nan
        v[rng.random(n) < 0.05] = np.inf
        v[rng.random(n) < 0.05] = -np.inf  # (no speed is, but the rule reads it as numpy would)
        if np.isnan(v).all():
            continue
        now = float(t[-1]) + float(rng.uniform(0.0, 0.2))
        assert _mirrored(t, v, 0.05, 0.8, now, c) == reference(t, v, 0.05, 0.8, now, c)


def test_kept_samples_are_the_window_of_the_samples_appended():
    """The detector's sample store (new rows wait in a list until read; the array grows and is
    compacted) holds exactly the samples not older than each cut, in order, however the reads
    and cuts interleave."""
    from gazebot.core.phases.detector import _Samples

    rng = np.random.default_rng(6)
    kept = _Samples()
    rows: list[tuple[float, ...]] = []
    t = 0.0
    for i in range(3000):
        t += float(rng.uniform(0.001, 0.02))
        row = (t, *rng.normal(size=6).tolist())
        kept.append(row)
        rows.append(row)
        cut = t - float(rng.choice([0.5, 2.0, 5.0]))
        kept.drop_before(cut)
        rows = [r for r in rows if r[0] >= cut]
        assert len(kept) == len(rows)
        assert kept.time(0) == rows[0][0] and kept.time(len(rows) - 1) == rows[-1][0]
        if i % int(rng.integers(1, 40)) == 0:
            np.testing.assert_array_equal(kept.rows(), np.array(rows))


def test_a_long_one_hand_loss_keeps_the_detector_bounded():
    """While one hand stays lost (tracking lost: the trigger's periods do not close), the
    detector keeps nothing per sample beyond its window: a minute more of the loss leaves its
    memory where it was, and the tick that restores tracking stays an ordinary one."""
    import tracemalloc

    from gazebot.core.phases.detector import PhaseDetector
    from gazebot.core.types import TrackingFrame

    det = PhaseDetector(PhaseConfig())
    rate, t = 120.0, 0.0
    lost = np.array([np.nan, np.nan, np.nan])

    def feed(seconds: float, receiver_seen: bool) -> None:
        nonlocal t
        for _ in range(int(seconds * rate)):
            t += 1.0 / rate
            receiver = np.array([0.6, 0.0, 1.0]) if receiver_seen else lost
            det.update_all(TrackingFrame.make(t, giver_hand=np.array([0.0, 0.3, 1.0]),
                                              receiver_hand=receiver))

    feed(2.0, True)
    feed(20.0, False)
    assert not det.tracking
    tracemalloc.start()
    try:
        feed(5.0, False)
        before = tracemalloc.get_traced_memory()[0]
        feed(60.0, False)
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert grown < 50_000, f"{grown} bytes more after a minute of one-hand loss"
    feed(1.0, True)
    assert det.tracking
