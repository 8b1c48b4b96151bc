"""The reach rules' and the end prediction's cheaper forms give exactly (bit for bit) what the
straightforward numpy forms they replace give."""

from __future__ import annotations

import math

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.prediction import predict_end
from gazebot.core.phases.rules.directed import _Quadratic, _quadratic_at
from gazebot.core.phases.rules.sequential import _grids, reach_evidence
from gazebot.core.types import Phase


def _fit_reference(t: np.ndarray, x: np.ndarray, noise: float):
    """One fit with its own design, lstsq, inverse and einsum (the form the rules used)."""
    n = t.shape[0]
    m = np.stack([np.ones(n), t, t * t], axis=1)
    coef, _, rank, _ = np.linalg.lstsq(m, x, rcond=None)
    if rank < 3:
        return None
    res = x - m @ coef
    var = max(noise * noise, float(res @ res) / max(n - 3, 1))
    cov = var * np.linalg.inv(m.T @ m)
    lin = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0], [0.0, -t[0], -(t[0] ** 2)]])
    se = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", lin, cov, lin), 0.0))
    return lin @ coef, se


def test_a_shared_quadratic_design_fits_each_signal_as_its_own_fit_would():
    rng = np.random.default_rng(3)
    for _ in range(300):
        n = int(rng.integers(3, 40))
        t = np.sort(-rng.uniform(0.0, 0.3, n))
        t[-1] = 0.0
        if rng.random() < 0.05:
            t[:] = 0.0  # a singular design: no fit
        q = _Quadratic(t)
        noise = float(rng.choice([0.0, 1e-3]))
        for _ in range(3):  # several signals on one design (its inverse computed once)
            x = np.cumsum(rng.normal(0.0, 0.01, n))
            ref = _fit_reference(t, x, noise)
            coef = q.coefficients(x)
            assert (coef is None) == (ref is None)
            if ref is None:
                continue
            assert q.state(coef).tobytes() == ref[0].tobytes()
            assert q.errors(x, coef, noise).tobytes() == ref[1].tobytes()


def test_a_design_shared_between_calls_fits_each_signal_as_its_own_fit_would():
    """_quadratic_at hands the same design to windows with the same times (bit for bit), and
    its remembered fits (a signal fitted again, as the directed and sequential rules fit the
    gap) and inverse give each fit's own values: against the plain reference, with windows
    whose times repeat and signals that repeat, in any order."""
    rng = np.random.default_rng(13)
    times = [np.sort(-rng.uniform(0.0, 0.3, int(rng.integers(3, 30)))) for _ in range(5)]
    for t in times:
        t[-1] = 0.0
    times.append(np.zeros(4))  # a singular design: no fit, remembered as none
    signals = {id(t): [np.cumsum(rng.normal(0.0, 0.01, t.shape[0])) for _ in range(3)]
               for t in times}
    for _ in range(200):
        t = times[int(rng.integers(len(times)))]
        q = _quadratic_at(t.copy())  # (equal times in a new array: the same design)
        assert q is _quadratic_at(t)
        assert not q.m.flags.writeable
        x = signals[id(t)][int(rng.integers(3))].copy()
        noise = float(rng.choice([0.0, 1e-3]))
        ref = _fit_reference(t, x, noise)
        coef = q.coefficients(x)
        assert (coef is None) == (ref is None)
        if ref is None:
            continue
        assert not coef.flags.writeable
        assert q.state(coef).tobytes() == ref[0].tobytes()
        assert q.errors(x, coef, noise).tobytes() == ref[1].tobytes()
    # (a negative zero is other bits: another design, the same values)
    t0 = np.array([-0.2, -0.1, 0.0])
    assert _quadratic_at(t0) is not _quadratic_at(np.array([-0.2, -0.1, -0.0]))


def test_the_sequential_grids_are_the_configurations_and_cannot_be_changed():
    c = PhaseConfig()
    durations, lags = _grids(
        c.sequential_durations,
        c.sequential_duration_steps,
        c.sequential_onset_span,
        c.sequential_onset_step,
    )
    lo, hi = c.sequential_durations
    assert durations.tobytes() == np.geomspace(lo, hi, c.sequential_duration_steps).tobytes()
    assert (
        lags.tobytes() == np.arange(0.0, c.sequential_onset_span, c.sequential_onset_step).tobytes()
    )
    assert not durations.flags.writeable and not lags.flags.writeable
    # a test on samples leaves them as they were for the next
    t = np.arange(96) / 120.0
    x = np.cumsum(np.random.default_rng(5).normal(0.0, 0.003, (96, 3)), axis=0)
    a = reach_evidence(t, x, float(t[-1]), 1e-3, c)
    b = reach_evidence(t, x, float(t[-1]), 1e-3, c)
    assert a is not None and b is not None
    assert repr(a) == repr(b)


def test_a_reach_ends_no_earlier_than_the_receivers_first_fast_sample_predicts():
    """The receiver's own onset is its first sample at ``reach_onset_speed`` or faster (none:
    the giver's prediction alone), however the speeds are missing."""
    from types import SimpleNamespace

    from gazebot.core.phases.durations import REACH_S
    from gazebot.core.phases.prediction import _mirrored

    def reference(start, s, now, c):
        pred = _mirrored(
            s.t[np.searchsorted(s.t, start) :],
            s.giver_speed[np.searchsorted(s.t, start) :],
            start,
            REACH_S,
            now,
            c,
        )
        j0 = int(np.searchsorted(s.t, start - REACH_S))
        moving = np.flatnonzero(s.receiver_speed[j0:] >= c.reach_onset_speed)
        if moving.size:
            k0 = j0 + int(moving[0])
            pred = max(
                pred, _mirrored(s.t[k0:], s.receiver_speed[k0:], float(s.t[k0]), REACH_S, now, c)
            )
        return max(pred, now)

    c = PhaseConfig()
    rng = np.random.default_rng(6)
    for _ in range(1000):
        n = int(rng.integers(1, 50))
        t = np.arange(n) / 60.0
        gv, rv = np.abs(rng.normal(0.3, 0.4, n)), np.abs(rng.normal(0.05, 0.2, n))
        rv[rng.random(n) < 0.2] = np.nan
        gv[rng.random(n) < 0.1] = np.nan
        s = SimpleNamespace(t=t, giver_speed=gv, receiver_speed=rv)
        start = float(rng.uniform(-0.5, float(t[-1]) + 0.1))
        now = float(t[-1]) + float(rng.uniform(0.0, 0.1))
        got = predict_end(Phase.REACH, start, s, now, c)
        want = reference(start, s, now, c)
        assert got == want or (math.isnan(got) and math.isnan(want))


def _directed_reference(traj, c, after):
    """The constant-acceleration rule in its straightforward form: every sample read, every
    fit with its errors (the form the rule had before it skipped work)."""
    from gazebot.core.phases.filtering import vector_norm
    from gazebot.core.phases.rules.directed import noise_floor
    from gazebot.core.phases.rules.onset import min_jerk_span

    t_all = traj.t
    if t_all.shape[0] < c.predict_min_samples + 2:
        return None
    g, r = traj.giver_hand, traj.receiver_hand
    now = float(t_all[-1])
    ok = np.isfinite(g).all(axis=1) & np.isfinite(r).all(axis=1) & (t_all > after)
    idx = np.flatnonzero(ok)
    if idx.size < c.predict_min_samples + 2 or not ok[-1]:
        return None
    tv = t_all[idx]
    w0 = min(now - c.predict_window, float(tv[-c.predict_min_samples]))
    fit = idx[tv >= w0 - 1e-9]
    rest = idx[(tv < w0 - 1e-9) & (tv >= w0 - c.predict_rest_window)]
    if fit.size < c.predict_min_samples or rest.size == 0:
        return None
    steps = np.diff(t_all[fit])
    if float(steps.max()) > c.predict_gap_factor * float(np.median(steps)):
        return None
    g_rest = g[rest].mean(axis=0)
    line = r[-1] - g_rest
    gap = vector_norm(line)
    if gap <= 1e-6:
        return None
    u = line / gap
    hist = idx[(tv < w0 - 1e-9) & (tv >= w0 - c.predict_noise_window)]
    noise = noise_floor(g[hist])
    tf = t_all[fit] - now
    along = _fit_reference(tf, (g[fit] - g_rest) @ u, noise)
    if along is None:
        return None
    (_, v, a, x), (_, sv, sa, sx) = along
    k = c.predict_sigmas
    if not (x >= max(c.predict_distance, k * sx) and v >= max(c.reach_onset_speed, k * sv)):
        return None
    if not a >= k * sa:
        return None
    gap_fit = _fit_reference(tf, -np.linalg.norm(r[fit] - g[fit], axis=1), noise)
    if gap_fit is None or not gap_fit[0][1] >= max(c.reach_onset_speed, k * gap_fit[1][1]):
        return None
    (minus_d, v_c, a_c, closed), _ = gap_fit
    h = c.predict_horizon
    ahead = closed + v_c * h + 0.5 * max(a_c, 0.0) * h * h
    if not ahead >= c.predict_gap_share * (closed - minus_d):
        return None
    across = [_fit_reference(tf, g[fit, j], noise) for j in range(3)]
    if any(f is None for f in across):
        return None
    vel = np.array([f[0][1] for f in across if f is not None])
    speed = vector_norm(vel)
    if not speed > 0 or v / speed < c.predict_cos:
        return None
    onset = now - min_jerk_span(x, v, c.max_refine)
    return max(onset, float(tv[0]), after) if math.isfinite(onset) else None


def test_the_directed_rule_reads_as_its_straightforward_form_on_every_prefix():
    """Skipping the samples before its windows (all read when a low rate or a dropout widens
    the fit window past them) and the errors of fits short of the bars' floors changes no
    onset, on reaches, fidgets, dropouts and sparse samples."""
    from gazebot.core.phases.rules.directed import directed_reach
    from gazebot.core.phases.synthetic import SyntheticOptions, generate, rest_recording

    sparse = SyntheticOptions(
        rate=30.0, irregular=0.3, noise=0.004, dropouts_per_s=1.0, frozen_per_s=1.0, handovers=2
    )
    recordings = [
        generate(seed=3, options=SyntheticOptions(rate=120.0)).trajectory,
        generate(seed=1, options=sparse).trajectory,
        generate(seed=2, options=SyntheticOptions(rate=12.0, noise=0.003)).trajectory,
        rest_recording(60.0, 0.002, seconds=6.0, seed=2, fidget=True),
    ]
    c = PhaseConfig()
    onsets = 0
    for traj in recordings:
        for i in range(8, len(traj) + 1, 2):
            sub = traj.take(np.arange(max(0, i - 600), i))
            for after in (-math.inf, float(sub.t[0]) + 0.5):
                got, want = directed_reach(sub, c, after), _directed_reference(sub, c, after)
                assert repr(got) == repr(want)
                onsets += want is not None
    assert onsets > 10  # reaches were confirmed, not only rejected
