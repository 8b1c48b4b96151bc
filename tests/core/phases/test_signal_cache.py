"""The online detector's signal cache: signals of a window that grew by a few samples, computed
only where the new samples change them, equal the full computation bit for bit, on clean and
damaged samples (NaN, stale repeats, long gaps, a hand seen late); a window that does not
extend the last one (a new first sample, changed samples, another configuration) is computed in
full."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import SignalCache, Signals, compute_signals
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.core.phases.trajectory import Trajectory


def _window(traj: Trajectory, i0: int, i1: int) -> Trajectory:
    return Trajectory.of_hands(
        traj.t[i0:i1].copy(), traj.giver_hand[i0:i1].copy(), traj.receiver_hand[i0:i1].copy()
    )


def _assert_same(a: Signals, b: Signals, where: str) -> None:
    for name in b.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=where + name)


def _grow(
    traj: Trajectory,
    config: PhaseConfig,
    steps: list[int],
    start: int = 0,
    append_only: bool = False,
    guard: float | None = None,
) -> tuple[int, int]:
    """Feed growing windows through one cache; each must equal the full computation (``guard``:
    both cut ``guard`` before the newest sample, the online detector's edge guard). Returns
    how many windows there were and how many were extensions of the previous one."""
    cache = SignalCache(append_only=append_only)
    extended = calls = 0
    n = start + 3
    for step in steps:
        if n + step > len(traj):
            break
        n += step
        calls += 1
        before = cache._rows
        if guard is None:
            ours = compute_signals(_window(traj, start, n), config, cache)
            want = compute_signals(_window(traj, start, n), config)
        else:
            until = float(traj.t[n - 1]) - guard
            ours = compute_signals(_window(traj, start, n), config, cache, until=until)
            whole = compute_signals(_window(traj, start, n), config)
            keep = int(np.searchsorted(whole.t, until, side="right"))
            want = Signals(*[a[:keep] for a in vars(whole).values()])
        extended += int(cache._owned and cache._rows > before)
        _assert_same(ours, want, f"n={n} ")
    return calls, extended


CASES = [
    SyntheticOptions(rate=120.0, posture="standing"),
    SyntheticOptions(rate=30.0, irregular=0.3, noise=0.004),
    SyntheticOptions(rate=8.0, noise=0.004),
    SyntheticOptions(rate=240.0, noise=0.002),
    SyntheticOptions(rate=60.0, noise=0.003, dropouts_per_s=1.0, frozen_per_s=1.0),
]


@pytest.mark.parametrize("append_only", [False, True], ids=["compared", "append-only"])
@pytest.mark.parametrize("options", CASES, ids=["120Hz", "30Hz", "8Hz", "240Hz", "60Hz-damaged"])
def test_growing_window_equals_the_full_computation(
    options: SyntheticOptions, append_only: bool
) -> None:
    """Also with ``append_only`` (the detector's: the kept samples are not compared), and with
    the rows cut at the edge guard."""
    traj = generate(seed=4, options=options).trajectory
    rng = np.random.default_rng(1)
    steps = [int(k) for k in rng.integers(1, 12, size=len(traj) // 3)]
    calls, extended = _grow(traj, PhaseConfig(), steps, append_only=append_only)
    assert extended > calls // 2  # the cache is used, not only the fallback
    calls, extended = _grow(
        traj, PhaseConfig(), steps, start=len(traj) // 4, append_only=append_only, guard=0.04
    )
    assert extended > calls // 2


@pytest.mark.parametrize("append_only", [False, True], ids=["compared", "append-only"])
def test_window_with_new_damage_extended_equals_the_full_computation(append_only: bool) -> None:
    traj = generate(seed=4, options=SyntheticOptions(rate=100.0, noise=0.002)).trajectory
    g, r = traj.giver_hand.copy(), traj.receiver_hand.copy()
    g[300] = np.nan  # a missing sample
    r[420] = r[419]  # a stale repeat
    t = traj.t.copy()
    t[500:] += 0.4  # a gap longer than max_gap_hold
    damaged = Trajectory(t, g, r)
    calls, extended = _grow(damaged, PhaseConfig(), [4] * (len(traj) // 4), append_only=append_only)
    assert extended > calls // 2  # damaged windows are extended too, not recomputed


def test_window_with_a_long_gap_only_equals_the_full_computation() -> None:
    traj = generate(seed=4, options=SyntheticOptions(rate=100.0, noise=0.002)).trajectory
    t = traj.t.copy()
    t[300:] += 0.4  # a gap longer than max_gap_hold, every sample seen
    t[450:] += 0.1  # and one shorter
    _grow(Trajectory(t, traj.giver_hand, traj.receiver_hand), PhaseConfig(), [1, 2, 3, 5] * 60)


def test_hand_seen_late_or_resting_equals_the_full_computation() -> None:
    traj = generate(seed=6, options=SyntheticOptions(rate=60.0, noise=0.0)).trajectory
    g, r = traj.giver_hand.copy(), traj.receiver_hand.copy()
    r[:40] = np.nan  # the receiver's hand unseen at first
    g[200:260] = g[200]  # a resting (repeated) hand, then frozen repeats while it moves
    g[330:336] = g[330]
    r[400:410] = np.nan  # a dropout
    _grow(Trajectory(traj.t, g, r), PhaseConfig(), [1, 3, 2, 4] * 60)


def test_changed_samples_or_config_are_not_reused() -> None:
    traj = generate(seed=4, options=SyntheticOptions(rate=100.0, noise=0.002)).trajectory
    config = PhaseConfig()
    cache = SignalCache()
    compute_signals(_window(traj, 0, 200), config, cache)
    moved = _window(traj, 0, 210)
    moved.giver_hand[150] += 0.01  # an older sample differs from the one the cache saw
    _assert_same(compute_signals(moved, config, cache), compute_signals(moved, config), "")
    other = PhaseConfig(smoothing=0.2)
    longer = _window(traj, 0, 220)
    _assert_same(compute_signals(longer, other, cache), compute_signals(longer, other), "")


def test_cached_signals_are_read_only() -> None:
    traj = generate(seed=4, options=SyntheticOptions(rate=100.0, noise=0.002)).trajectory
    cache = SignalCache()
    compute_signals(_window(traj, 0, 200), PhaseConfig(), cache)
    s = compute_signals(_window(traj, 0, 205), PhaseConfig(), cache)
    with pytest.raises(ValueError):
        s.distance[0] = 1.0
