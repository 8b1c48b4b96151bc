"""The fused signal pipeline (both hands at once, cached smoothing weights) equals, bit for bit,
the straightforward one hand at a time (tests/core/phases/signals_reference.py), on clean, noisy,
NaN, frozen, irregular and sparse input."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import compute_signals, gaussian_weights
from gazebot.core.phases.synthetic import SyntheticOptions, generate, synthetic_set
from gazebot.core.phases.trajectory import Trajectory
from tests.core.phases.signals_reference import reference_signals


def _assert_same(traj: Trajectory, config: PhaseConfig) -> None:
    ours = compute_signals(traj, config)
    ref = reference_signals(traj, config)
    for name in ref.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(ours, name), getattr(ref, name), err_msg=name)


def _damaged(traj: Trajectory, seed: int) -> Trajectory:
    """NaN rows and single NaN coordinates, frozen repeats while moving, a long gap, and one
    hand missing where the other is seen."""
    rng = np.random.default_rng(seed)
    g, r = traj.giver_hand.copy(), traj.receiver_hand.copy()
    n = g.shape[0]
    g[rng.choice(n, n // 15, replace=False)] = np.nan
    r[rng.choice(n, n // 25, replace=False), 2] = np.nan
    for k in rng.choice(n - 6, 6, replace=False):
        g[k + 1 : k + 5] = g[k]
        r[k + 2 : k + 4] = r[k + 1]
    g[n // 2 : n // 2 + n // 8] = np.nan
    return Trajectory(traj.t, g, r)


CASES = [
    SyntheticOptions(rate=120.0, posture="standing"),
    SyntheticOptions(rate=30.0, irregular=0.3, noise=0.004, dropouts_per_s=1.0, frozen_per_s=1.0),
    SyntheticOptions(rate=8.0, noise=0.004),
    SyntheticOptions(rate=240.0, handovers=2),
]


@pytest.mark.parametrize("options", CASES, ids=["120Hz", "30Hz-noisy", "8Hz", "240Hz"])
def test_fused_signals_equal_the_one_hand_pipeline(options: SyntheticOptions) -> None:
    traj = generate(seed=5, options=options).trajectory
    config = PhaseConfig()
    _assert_same(traj, config)
    _assert_same(_damaged(traj, 1), config)
    for n in (1, 2, 3, 7, 40):  # the first samples an online detector sees
        _assert_same(Trajectory(traj.t[:n], traj.giver_hand[:n], traj.receiver_hand[:n]), config)


def test_fused_signals_equal_on_the_synthetic_set() -> None:
    config = PhaseConfig()
    for i, h in enumerate(synthetic_set(8, seed=2)):
        traj, _, _ = h.trajectory.cleaned()
        _assert_same(traj, config)
        _assert_same(_damaged(traj, i), config)


def test_fused_signals_equal_with_narrow_smoothing_and_a_hand_never_seen() -> None:
    traj = generate(seed=1, options=CASES[1]).trajectory
    _assert_same(traj, PhaseConfig(smoothing=0.01, analysis_rate=240.0))
    blind = Trajectory(traj.t, traj.giver_hand, np.full_like(traj.receiver_hand, np.nan))
    _assert_same(blind, PhaseConfig())


def test_cached_weights_are_the_gaussian_filters_own() -> None:
    from scipy.ndimage import correlate1d, gaussian_filter1d

    x = np.random.default_rng(0).normal(size=(50, 2))
    w = gaussian_weights(4.7)
    assert not w.flags.writeable
    np.testing.assert_array_equal(
        correlate1d(x, w, axis=0, mode="nearest"),
        gaussian_filter1d(x, 4.7, axis=0, mode="nearest", truncate=3.0),
    )


def test_trigger_rows_hold_the_period_means_and_numpys_distances() -> None:
    """The gazebot trigger keeps per-period means, relative positions and distances in plain
    floats; they equal numpy's mean and ``np.linalg.norm`` of the same samples bit for bit (the
    summation order is the one numpy uses for 3-vectors)."""
    from gazebot.core.phases.methods.base import OnlineState
    from gazebot.core.phases.methods.gazebot_trigger import GazebotTrigger
    from gazebot.core.types import Phase

    traj = _damaged(generate(seed=4, options=CASES[1]).trajectory, 3)
    config = PhaseConfig()
    trig = GazebotTrigger(config)
    state = OnlineState(Phase.IDLE, float("nan"), -np.inf, True, False, -np.inf)
    period: list[tuple[np.ndarray, np.ndarray]] = []
    expected = []
    for t, g, r in zip(traj.t, traj.giver_hand, traj.receiver_hand, strict=True):
        g_ok, r_ok = bool(np.isfinite(g).all()), bool(np.isfinite(r).all())
        trig.add(g, g_ok, r, r_ok)
        period.append((g, r))
        if len(period) == 3:
            gs = [a for a, _ in period if np.isfinite(a).all()]
            rs = [b for _, b in period if np.isfinite(b).all()]
            gm = np.sum(gs, axis=0) / len(gs) if gs else np.full(3, np.nan)
            rm = np.sum(rs, axis=0) / len(rs) if rs else np.full(3, np.nan)
            expected.append(np.concatenate([[t], gm, rm, rm - gm, [0.0]]))
            trig.decide(float(t), state)
            period.clear()
    rows = trig.rows()
    want = np.array(expected)[-rows.shape[0] :]
    want[:, 10] = np.linalg.norm(want[:, 7:10], axis=1)  # as the trigger computed it before
    np.testing.assert_array_equal(rows[:, :11], want)
    assert np.isnan(rows[:, 10]).any() and np.isfinite(rows[:, 10]).any()
    # the giver's step over trigger_speed_baseline, as the retreat rule computed it before
    k = trig._k
    g = rows[:, 1:4]
    np.testing.assert_array_equal(rows[k:, 11], np.linalg.norm(g[k:] - g[:-k], axis=1))


def test_median_of_the_sample_steps_is_numpys() -> None:
    from gazebot.core.phases.filtering import median

    rng = np.random.default_rng(1)
    for n in (1, 2, 3, 4, 7, 10, 101):
        x = rng.uniform(0.004, 0.03, size=n)
        assert median(x) == float(np.median(x))
        x[n // 2] = np.nan
        assert np.isnan(median(x))


def test_quantile_is_numpys_linear_quantile() -> None:
    from gazebot.core.phases.filtering import quantile

    rng = np.random.default_rng(2)
    for n in (1, 2, 3, 5, 8, 33, 200):
        x = rng.gamma(2.0, 0.02, size=n)
        x[rng.random(n) < 0.1] = 0.05  # ties
        for q in (0.0, 0.1, 0.25, 0.3333, 0.5, 0.75, 0.9, 1.0, float(rng.random())):
            assert quantile(x, q) == float(np.quantile(x, q)), (n, q)


def test_vector_norm_is_numpys_norm_bit_for_bit() -> None:
    """The rules' single-vector norm equals ``np.linalg.norm`` exactly (numpy's dot may fuse
    the products, so a plain sum of squares would not), on rows, strided views, 2-D blocks,
    NaN, infinity and an empty vector."""
    from gazebot.core.phases.filtering import vector_norm

    rng = np.random.default_rng(4)
    x = rng.normal(size=(4000, 3)) * rng.choice([1e-4, 1.0, 1e3], size=(4000, 1))
    for v in [*x, *x.T[:, ::7], x[:5], np.array([np.nan, 1.0, 2.0]),
              np.array([np.inf, 0.0, 1.0]), np.zeros(0)]:
        want = float(np.linalg.norm(v))
        got = vector_norm(v)
        assert got == want or (np.isnan(got) and np.isnan(want))


def test_nanmax_and_nanmin_are_numpys() -> None:
    """The rules' NaN-skipping extrema equal ``np.nanmax`` / ``np.nanmin``, with and without
    ``initial``, on rows with NaN, all NaN and (with ``initial``) none."""
    import warnings

    from gazebot.core.phases.filtering import nanmax, nanmin

    rng = np.random.default_rng(5)
    for n in (0, 1, 2, 5, 40):
        x = rng.normal(size=n)
        x[rng.random(n) < 0.3] = np.nan
        for a in (x, np.full(n, np.nan)):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # numpy warns on all NaN
                for ours, theirs in ((nanmax, np.nanmax), (nanmin, np.nanmin)):
                    for init in (0.0, -np.inf):
                        kw = {"initial": init}
                        np.testing.assert_array_equal(ours(a, **kw), theirs(a, **kw))
                    if n:
                        np.testing.assert_array_equal(ours(a), theirs(a))


def test_nanargmax_is_numpys() -> None:
    """The rules' NaN-skipping argmax equals ``np.nanargmax`` (ties: the first; -inf values
    and NaN), and fails like it on all NaN and on nothing."""
    from gazebot.core.phases.filtering import nanargmax

    rng = np.random.default_rng(6)
    for n in (1, 2, 5, 40):
        for _ in range(50):
            x = rng.choice([-np.inf, -1.0, 0.0, 1.0, 2.0, np.nan], size=n)
            if not np.isnan(x).all():
                assert nanargmax(x) == int(np.nanargmax(x)), x
    for bad in (np.full(3, np.nan), np.zeros(0)):
        with pytest.raises(ValueError):
            np.nanargmax(bad)
        with pytest.raises(ValueError):
            nanargmax(bad)


def test_two_row_nanmean_is_numpys() -> None:
    import warnings

    from gazebot.core.phases.methods.gazebot_trigger import _nanmean2

    rng = np.random.default_rng(3)
    for _ in range(200):
        ab = rng.normal(size=(2, 3))
        ab[rng.random((2, 3)) < 0.3] = np.nan
        ab[rng.random((2, 3)) < 0.05] = -0.0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # numpy warns on an all-NaN column
            want = np.nanmean(ab, axis=0)
        np.testing.assert_array_equal(_nanmean2(ab[0], ab[1]), want)


def test_suffix_max_is_numpys_fmax_over_the_span() -> None:
    """The trigger's running maximum over [first row, newest row) equals ``np.fmax.reduce``
    of those rows while rows arrive, the first row moves forward (a sliding window), jumps
    ahead or back (a new phase), the buffer is compacted, and rows are NaN."""
    from gazebot.core.phases.methods.gazebot_trigger import _SuffixMax

    rng = np.random.default_rng(4)
    col = rng.normal(size=400)
    col[rng.random(400) < 0.15] = np.nan
    col[100:130] = np.nan  # a span of unknown rows only
    values = col.tolist()
    sm = _SuffixMax()
    first = 0
    base = 0
    for end in range(1, 400):
        r = rng.random()
        if r < 0.3:
            first = min(first + int(rng.integers(0, 3)), end - 1)  # slides
        elif r < 0.33:
            first = int(rng.integers(base, end))  # moves anywhere kept, back too
        if r > 0.97 and first > base:
            base = int(rng.integers(base, first + 1))  # compaction: rows before first dropped
        got = sm.update(values[base:], base, first - base, end - base)
        want = np.fmax.reduce(col[first:end])
        assert got == want or (np.isnan(got) and np.isnan(want)), (first, end)


def test_row_norms_are_numpys_row_norms() -> None:
    """``row_norms`` (the rules' per-row 3-vector norms, column by column) equals
    ``np.linalg.norm(x, axis=1)`` bit for bit, NaN and infinite entries and extreme scales too."""
    from gazebot.core.phases.filtering import row_norms

    rng = np.random.default_rng(5)
    for scale in (1e-160, 1e-3, 1.0, 1e3, 1e160):
        x = rng.normal(size=(20000, 3)) * scale
        x[rng.random(x.shape) < 0.01] = np.nan
        x[rng.random(x.shape) < 0.005] = np.inf
        with np.errstate(over="ignore"):  # (1e160 squared overflows in both)
            np.testing.assert_array_equal(row_norms(x), np.linalg.norm(x, axis=1))


def test_trigger_norm_bar_decides_as_numpys_norm() -> None:
    """The trigger's plain-float test ``|v| >= bar`` decides as ``vector_norm`` (numpy's dot)
    does, at near ties, NaN, infinite and zero vectors too."""
    from gazebot.core.phases.filtering import vector_norm
    from gazebot.core.phases.methods.gazebot_trigger import _norm_at_least

    rng = np.random.default_rng(7)
    vs = rng.normal(size=(20000, 3)) * rng.choice([1e-3, 1.0, 1e3], size=(20000, 1))
    vs[::50] = [0.0, 0.0, 0.0]
    vs[1::97, 1] = np.nan
    vs[2::89, 0] = np.inf
    for v in vs:
        norm = vector_norm(v)
        for bar in (0.0, 0.005, norm, np.nextafter(norm, 0.0), np.nextafter(norm, np.inf)):
            if np.isfinite(bar):
                assert _norm_at_least(v.tolist(), float(bar)) == (norm >= bar), (v, bar)


def test_trigger_dot_bar_decides_as_numpys_dot() -> None:
    """The trigger's plain-float test ``a . b / d >= bar`` (the giver's own share of the
    closing) decides as numpy's dot does, at near ties, cancellation, NaN and infinities."""
    from gazebot.core.phases.methods.gazebot_trigger import _dot_over_at_least

    rng = np.random.default_rng(8)
    ab = rng.normal(size=(20000, 2, 3)) * rng.choice([1e-3, 1.0, 1e3], size=(20000, 1, 1))
    ab[::7, 1] = ab[::7, 0] * [1.0, -1.0, 0.0]  # (products that cancel)
    ab[::14, 0, 1] = ab[::14, 0, 0]  # (... exactly)
    ab[1::97, 0, 1] = np.nan
    ab[2::89, 1, 0] = np.inf
    for (a, b), d in zip(ab, rng.uniform(1e-9, 2.0, size=20000), strict=True):
        own = float(np.dot(a, b)) / d
        for bar in (0.005, own, np.nextafter(own, -np.inf), np.nextafter(own, np.inf)):
            if np.isfinite(bar):
                got = _dot_over_at_least(a.tolist(), b.tolist(), float(d), float(bar))
                assert got == (own >= bar), (a, b, d, bar)


def test_the_subtractions_standing_for_np_diff_give_its_bits() -> None:
    """``x[1:] - x[:-1]`` (filtering, the reach rules' steps) and the difference of the
    differences (the noise floor's) are np.diff's values, n=1 and n=2, on a strided column,
    NaN and inf included; the max and median read from them are then the same too."""
    from gazebot.core.phases.filtering import median
    from gazebot.core.phases.rules.directed import noise_floor

    rng = np.random.default_rng(8)
    rows = rng.normal(size=(50, 7))
    rows[rng.random((50, 7)) < 0.04] = np.nan
    rows[3, 2] = np.inf
    t = rows[:, 0]  # (strided, as the detector's window columns are)
    np.testing.assert_array_equal((t[1:] - t[:-1]).view(np.int64), np.diff(t).view(np.int64))
    x = rows[:, 1:4]
    d1 = x[1:] - x[:-1]
    np.testing.assert_array_equal(
        (d1[1:] - d1[:-1]).view(np.int64), np.diff(x, n=2, axis=0).view(np.int64)
    )
    clean = np.cumsum(rng.uniform(0.005, 0.01, 60))
    assert float((clean[1:] - clean[:-1]).max()) == float(np.max(np.diff(clean)))
    assert median(clean[1:] - clean[:-1]) == float(np.median(np.diff(clean)))
    hand = rng.normal(size=(40, 3)) * 0.002
    d2 = np.diff(hand, n=2, axis=0).reshape(-1)
    want = 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(6.0)
    assert noise_floor(hand) == want
