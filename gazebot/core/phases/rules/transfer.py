"""Reach -> transfer: the handovers in a recording and when each transfer starts.

A handover is a dip of the hands' distance at least ``min_approach`` deep (the recording's ends
count as high ground) that closes at least ``approach_fraction`` of the distance the hands
started from (a pause of a slow approach is no handover). Its minimum is the seed's "minimum
distance" (section 7.2.5), whatever it is: on real motion capture the hand frames sit on the
back of the hand or at the wrist and the object has size, so they never come closer than
0.3-0.5 m; no absolute contact distance is assumed. Within the dip, the seed's rule (within
``transfer_distance_margin`` of the minimum, relative speed under ``transfer_speed_max``)
gives the transfer's core; runs split by short blips under ``transfer_exit_speed``, by
tracking gaps, or by the pair turning with the object (under ``transfer_exit_speed`` with
their relative speed against their common motion under ``transfer_speed_max``, however long,
seen or across a tracking gap; between two runs of at least ``min_transfer``, faster too when
their relative motion runs mostly across their line and their common motion is under
``turning_common_max``: a careful carry, not a pass on the move) merge. The core is the
merged run holding the minimum distance, or the longest when that one is shorter than
``min_transfer`` (a marker glitch at the closest point), started at an earlier run the hands
never parted from (:func:`regrip`: a hand adjusting its grip between two holds); a core
younger than ``young_hold`` goes on into a later hold the same way (a bounce at the meeting).
An approach that stops in a tracking gap before the core is dated from the last sample before
the gap, once the hands are settled after it (under the settle speed, or turning together:
their speed against their common motion under it). The giver's hand must have moved
(``reach_onset_speed``) before the core: a receiver (robot) returning home near a resting giver
makes a dip too; the receiver may move more than the giver.

A dip with no such run at least ``min_transfer`` long is a handover on the move when the
hands pass the object without stopping (:func:`pass_core`): its core is the short stretch
under ``transfer_exit_speed`` at the closest, slowest point where the hands have closed in
(not the dip's top, where the distance turns), once the hands are seen parting.

The seed's 15 cm/s is crossed on the tail of the approach, before contact. The transfer starts
where the approach has stopped: the relative speed falls below ``settle_fraction`` of the
approach's own peak relative speed (scale-free: fast and slow approaches alike), or below
``settle_floor_factor`` times the hold's speed floor (marker noise and both hands carrying the
object keep the relative speed of a real hold at 3-7 cm/s), whichever is higher; a clean
approach's parabolic tail is then extrapolated down to the floor, at most twice the interval
it was fitted on (:func:`settle_time`). Where the pair moves the object together
(:func:`carried_together`), or where both hands still move over the approach's tail
(:func:`both_adjusting`), the transfer starts at most ``approach_tail_max`` after the seed's
15 cm/s: hands creeping closer while the pair turns, carries the object or adjusts to each
other already hold it; one hand still arriving at a still one (a robot's slow gripper) has
not reached it yet (:func:`transfer_start`). A dip whose closest distance is beyond
``max_hold_distance`` is no handover (a giver pausing with the object on the way).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import Signals, across_line, nanmax, vector_norm
from gazebot.core.phases.rules.onset import min_jerk_span

#: The most a clean approach's parabolic tail is extrapolated, in lengths of the interval it
#: was fitted on (:func:`settle_time`).
TAIL_RATIO = 2.0


@dataclass(frozen=True)
class TransferCore:
    """One handover's transfer core on the analysis grid.

    Attributes:
        lo: First grid index of the handover's dip.
        start: First grid index of the seed-rule core.
        end: Last grid index of the core.
        hi: Last grid index of the dip.
        t_start: Transfer start (s), or NaN when the approach has not yet settled in the data.
        piece: The transfer was under way at the recording's first sample (a window cut from
            inside a handover): its reach is not in the data.
    """

    lo: int
    start: int
    end: int
    hi: int
    t_start: float
    piece: bool = False


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges of the True runs of ``mask``."""
    if mask.size == 0:
        return []
    padded = np.zeros(mask.size + 2, dtype=bool)
    padded[1:-1] = mask
    bounds = (padded[1:] != padded[:-1]).nonzero()[0].tolist()
    return [(a, b - 1) for a, b in zip(bounds[::2], bounds[1::2], strict=True)]


def _leg_end(v: np.ndarray, s: int, depth: float, down: bool) -> int:
    """The end of the leg of ``v`` starting at ``s``: going down, the first index after ``s``
    at least ``depth`` above the lowest sample from ``s`` before it (going up: ``depth``
    below the highest); -1 if none. Searched in windows from ``s`` that double in length, so
    a leg costs a few numpy calls and work proportional to its own length, whatever follows
    it (a whole recording's distance has hundreds of legs)."""
    m = v.shape[0]
    w = 64
    while True:
        e = min(s + w, m)
        if down:
            hit = v[s + 1 : e] >= np.minimum.accumulate(v[s : e - 1]) + depth
        else:
            hit = v[s + 1 : e] <= np.maximum.accumulate(v[s : e - 1]) - depth
        j = int(hit.argmax()) if hit.shape[0] else 0
        if hit.shape[0] and hit[j]:
            return s + 1 + j
        if e == m:
            return -1
        w *= 2


def dips(d: np.ndarray, depth: float) -> list[tuple[int, int, int]]:
    """Dips of ``d`` at least ``depth`` (> 0) deep on both sides, as ``(left, minimum, right)``
    index triples (left/right: the highest points between neighbouring dips). The recording's
    ends count as high ground, so a recording that starts or ends mid-handover keeps its dip.
    NaN samples are skipped.

    A zigzag with hysteresis ``depth``: going down, the lowest sample so far (the first of
    equal ones) is the minimum until a sample rises ``depth`` above it; going up, the highest
    so far until one falls ``depth`` below it. Each leg is found with running extrema
    (:func:`_leg_end`: a few numpy calls a leg, not a Python step per sample: the online
    analysis reads the dips of hundreds of samples every period); ``tests/core/phases`` pins it to
    the sample-by-sample form."""
    if not depth > 0:
        raise ValueError(f"dips: depth must be > 0, got {depth}")
    out: list[tuple[int, int, int]] = []
    if d.shape[0] == 0:
        return out
    if d.dtype.kind != "f" or d.dtype.itemsize < 8:
        # (a narrower or integer signal is compared in float64; a wider one keeps its
        # precision)
        d = d.astype(float)
    ok = np.isfinite(d)
    if ok.all():
        v, idx = d, None
    else:
        idx = ok.nonzero()[0]
        if idx.size == 0:
            return out
        v = d[idx]

    def at(i: int) -> int:  # index into d of the i-th finite sample
        return i if idx is None else int(idx[i])

    left = at(0)
    s = 0  # the down leg starts here
    while True:
        # (depth > 0: the sample ending a leg is never a new extreme of that leg)
        u = _leg_end(v, s, depth, down=True)  # the up leg starts here
        if u < 0:
            out.append((left, at(s + int(v[s:].argmin())), at(v.shape[0] - 1)))
            return out
        lo_i = s + int(v[s:u].argmin())
        s = _leg_end(v, u, depth, down=False)  # the next down leg starts here
        if s < 0:
            out.append((left, at(lo_i), at(u + int(v[u:].argmax()))))
            return out
        hi = at(u + int(v[u:s].argmax()))
        out.append((left, at(lo_i), hi))
        left = hi


def find_cores(s: Signals, c: PhaseConfig, pieces: bool = False) -> list[TransferCore]:
    """Every handover's transfer core, in time order (see the module docstring).

    ``pieces``: a first dip that is a handover already under way at the first sample
    (:func:`is_leading_piece`) gives a core too, marked ``piece`` (offline: a recording cut
    from inside a handover; online the analysis window's start slides through holds)."""
    d = s.distance
    n = d.shape[0]
    if n < 3 or not np.isfinite(d).any():
        return []
    out: list[TransferCore] = []
    unknown = ~np.isfinite(s.rel_speed)
    rs = np.where(unknown, np.inf, s.rel_speed)
    min_len = max(1, int(round(c.min_transfer * c.analysis_rate)))
    # The pair turning carefully: relative motion mostly across their line, their common
    # motion under turning_common_max (not walking on together). The same for every dip.
    with np.errstate(invalid="ignore"):
        careful = s.common_speed < c.turning_common_max
    careful_turn = across_line(s.closing, s.rel_speed) & careful
    all_dips = dips(d, c.min_approach)
    for lo, p, hi in all_dips:
        near = np.zeros(n, dtype=bool)
        near[lo : hi + 1] = d[lo : hi + 1] <= d[p] + c.transfer_distance_margin
        rule_runs = runs(near & (rs < c.transfer_speed_max))
        if not any(b - a + 1 >= min_len for a, b in rule_runs):
            passed = pass_core(s, c, near, rs, lo, p, hi)
            if passed is not None and (not out or passed[0] > out[-1].end):
                out.append(TransferCore(lo, passed[0], passed[1], hi, float(s.t[passed[0]])))
            continue
        soft = near & (rs < c.transfer_exit_speed)
        # The pair turning with the object: their relative speed against their common motion
        # stays under the seed's speed (issue 33's careful carries swing the marker frames'
        # relative position at 0.15-0.2 m/s for longer than a blip).
        together = near & (np.nan_to_num(s.hold_speed, nan=np.inf) < c.transfer_speed_max)
        # ... and, faster than the exit speed, turning carefully (careful_turn, above).
        turning = together & careful_turn
        merged: list[list[int]] = [list(rule_runs[0])]
        for a, b in rule_runs[1:]:
            gap = slice(merged[-1][1] + 1, a)
            # A short blip under the exit speed, or a tracking gap with nothing but such
            # samples, does not end a transfer; nor does the pair turning together, seen or
            # not (only the samples of neither kind count toward the blip's length). Between
            # two holds the pair may turn faster than the exit speed (issue 33: a careful
            # carry seen at 30 Hz).
            ok = soft[gap] | unknown[gap]
            if merged[-1][1] - merged[-1][0] + 1 >= min_len and b - a + 1 >= min_len:
                ok |= turning[gap]
            blip = ~unknown[gap] & ~together[gap]
            if ok.all() and np.count_nonzero(blip) < min_len:
                merged[-1][1] = b
            else:
                merged.append([a, b])
        # The run holding the minimum distance, unless a glitch or a swing left it too short
        # to be a transfer: then the longest.
        long_runs = [m for m in merged if m[1] - m[0] + 1 >= min_len]
        if not long_runs:
            continue
        core = next((m for m in long_runs if m[0] <= p <= m[1]), None)
        if core is None:
            core = max(long_runs, key=lambda m: m[1] - m[0])
        # An earlier hold the hands never parted from (regrip) is the same transfer: its start.
        # A hold younger than young_hold that the hands leave by a regrip and hold again (a
        # bounce at the meeting) goes on into the next hold.
        k = m = merged.index(core)
        while k > 0 and regrip(s, c, core, merged[k - 1][1], core[0]):
            k -= 1
        while (
            m + 1 < len(merged)
            and s.t[merged[m][1]] - s.t[merged[k][0]] < c.young_hold
            and regrip(s, c, core, merged[m][1], merged[m + 1][0])
        ):
            m += 1
        a, b = merged[k][0], merged[m][1]
        if not is_handover_dip(s, c, lo, p, a):
            if pieces and not out:
                closest = min((float(d[q]) for _, q, _ in all_dips[1:]), default=math.inf)
                if is_leading_piece(s, c, a, b, p, hi, closest):
                    out.append(TransferCore(lo, a, b, hi, float(s.t[a]), piece=True))
            continue  # a pause far apart, or only the receiver moved: not a handover
        if out and a <= out[-1].end:
            continue  # the same transfer seen from a neighbouring dip
        out.append(TransferCore(lo, a, b, hi, transfer_start(s, c, lo, a, b)))
    return out


def both_seen(s: Signals, a: int, b: int) -> np.ndarray:
    """Grid indices in ``[a, b]`` where both hands are seen (their relative position known)."""
    return np.isfinite(s.rel[a : b + 1]).all(axis=1).nonzero()[0] + a


def pair_travel(s: Signals, a: int, b: int) -> float:
    """How far (m) the hands' midpoint moved from grid index ``a`` to ``b`` (first and last seen
    samples between them): the object carried by the pair, net of marker noise."""
    seen = both_seen(s, a, b)
    if seen.size < 2:
        return 0.0
    i, j = int(seen[0]), int(seen[-1])
    return vector_norm(s.giver[j] + s.receiver[j] - s.giver[i] - s.receiver[i]) / 2.0


def distance_band(c: PhaseConfig, deviation: np.ndarray) -> float:
    """How far (m) the hands' distance or relative position must leave a held value to count
    as parting, given the samples' ``deviation`` from it: ``release_distance``, or
    ``release_noise_factor`` times their RMS if larger (NaN samples ignored)."""
    dev = deviation[np.isfinite(deviation)]
    return jitter_band(c, float(np.sqrt(np.mean(dev**2))) if dev.size else 0.0)


def jitter_band(c: PhaseConfig, jitter: float) -> float:
    """The band (m) of a held distance or pose whose samples jitter by ``jitter`` (m, RMS or a
    robust equivalent): ``release_distance``, or ``release_noise_factor`` times the jitter if
    larger."""
    return max(c.release_distance, c.release_noise_factor * jitter)


def regrip(s: Signals, c: PhaseConfig, hold: list[int], i: int, j: int) -> bool:
    """The hands did not part between grid indices ``i`` and ``j`` (the end of one hold and
    the start of the next, one of them the core ``hold``): their distance stays within twice
    the band of ``hold`` (:func:`distance_band`), as a coupled hold's does (issue 33: one hand
    adjusting its grip, the pair turning or pressing the object in, faster than the seed's
    speed for a moment), their common motion careful (under ``turning_common_max``, as for a
    turn). An approach that paused short of contact moves the distance by more."""
    d = s.distance[i : j + 1]
    d = d[np.isfinite(d)]
    if d.size == 0 or not nanmax(s.common_speed[i : j + 1], initial=0.0) < c.turning_common_max:
        return False  # (hands passing the object on the move hold no careful grip)
    held = s.distance[hold[0] : hold[1] + 1]
    band = distance_band(c, held - np.nanmedian(held))
    return float(d.max() - d.min()) <= 2.0 * band


def is_handover_dip(s: Signals, c: PhaseConfig, lo: int, p: int, a: int) -> bool:
    """The dip ``[lo .. p]`` closes ``approach_fraction`` of where the hands started, to within
    ``max_hold_distance``, and the giver's hand moved (``reach_onset_speed``) before grid
    index ``a``."""
    d = s.distance
    if not d[p] <= c.max_hold_distance:
        return False  # too far apart to hold one object: a pause on the way
    top = float(nanmax(d[lo : p + 1]))
    if top - d[p] < c.approach_fraction * top:
        return False  # the hands paused while still far apart (relative to where they started)
    return bool(nanmax(s.giver_speed[lo : a + 1], initial=0.0) >= c.reach_onset_speed)


def is_leading_piece(
    s: Signals, c: PhaseConfig, a: int, b: int, p: int, hi: int, closest: float = math.inf
) -> bool:
    """The seed-rule core ``[a, b]`` of the recording's first dip is a handover already under
    way at the first sample (a window cut from inside one, issue 33): the core starts at the
    first sample seen, the hands are seen parting after it (``min_approach``), and they are
    within the seed's ``transfer_distance_margin`` of ``closest``, the closest the hands come
    in the recording's later dips (hands at rest a metre apart, whose distance noise or a
    step raises by ``min_approach``, hand nothing over: 5 mm of noise on the KTH sample made
    such a piece in five of 40 degraded copies)."""
    seen = np.isfinite(s.distance).nonzero()[0]
    if seen.size == 0 or a > int(seen[0]) + 1:
        return False
    if s.distance[p] > closest + c.transfer_distance_margin:
        return False
    return bool(nanmax(s.distance[b : hi + 1], initial=-np.inf) >= s.distance[p] + c.min_approach)


def pass_core(
    s: Signals, c: PhaseConfig, near: np.ndarray, rs: np.ndarray, lo: int, p: int, hi: int
) -> tuple[int, int] | None:
    """A handover without a hold (a quick or on-the-move pass: the hands never slow under the
    seed's 15 cm/s for ``min_transfer``): the object changes hands where they are closest and
    slowest. The core is the run under ``transfer_exit_speed`` around the slowest sample of
    the near run holding the minimum ``p``, where the hands have closed half ``min_approach``
    from the dip's top (at least ``pass_min_samples`` grid samples), only once the hands are
    seen parting after it (the dip's far side rises ``min_approach``)."""
    n = s.t.shape[0]
    d = s.distance
    # Where the hands have closed in: half min_approach below the dip's top (on the move, the
    # relative speed dips at the top too, where the distance turns).
    with np.errstate(invalid="ignore"):
        low = near & (d <= float(nanmax(d[lo : p + 1])) - 0.5 * c.min_approach)
    a = p
    while a > lo and low[a - 1]:
        a -= 1
    b = p
    while b < hi and low[b + 1]:
        b += 1
    if b >= n - 1 or not nanmax(d[p:], initial=-np.inf) >= d[p] + c.min_approach:
        return None  # not yet seen parting
    k = a + int(rs[a : b + 1].argmin())
    if not rs[k] < c.transfer_exit_speed:
        return None
    i, j = k, k
    while i > a and rs[i - 1] < c.transfer_exit_speed:
        i -= 1
    while j < b and rs[j + 1] < c.transfer_exit_speed:
        j += 1
    if j - i + 1 < c.pass_min_samples or not is_handover_dip(s, c, lo, p, i):
        return None
    return i, j


def hold_floor(s: Signals, c: PhaseConfig, a: int, b: int) -> float:
    """The relative speed floor of the hold ``[a, b]`` (m/s): marker noise and both hands
    carrying the object, the ``hold_floor_quantile`` of its relative speed."""
    hold = s.rel_speed[a : b + 1]
    hold = hold[np.isfinite(hold)]
    return float(np.quantile(hold, c.hold_floor_quantile)) if hold.size else 0.0


def v_settle_fraction(s: Signals, c: PhaseConfig, lo: int, a: int) -> float:
    """``settle_fraction`` of the approach's peak relative speed (m/s)."""
    return c.settle_fraction * float(nanmax(s.rel_speed[lo : a + 1], initial=0.0))


def settle_speed(s: Signals, c: PhaseConfig, lo: int, a: int, b: int) -> float:
    """The relative speed below which the approach of the core ``[a, b]`` has stopped (m/s)."""
    peak = float(nanmax(s.rel_speed[lo : a + 1], initial=0.0))
    floor = c.settle_floor_factor * hold_floor(s, c, a, b)
    return min(max(c.settle_fraction * peak, floor), c.transfer_speed_max)


def _crossing(s: Signals, i: int, level: float) -> float:
    """Time the relative speed fell through ``level`` between grid points ``i - 1`` and ``i``."""
    if i > 0 and np.isfinite(s.rel_speed[i - 1]):
        v0, v1 = float(s.rel_speed[i - 1]), float(s.rel_speed[i])
        if v0 > level >= v1 and v0 > v1:
            return float(s.t[i - 1]) + (v0 - level) / (v0 - v1) * s.dt
    return float(s.t[i])


def speed_fell_for_good(s: Signals, a: int, b: int, level: float, band: float) -> float:
    """When the relative speed fell through ``level`` for good in grid indices ``[a, b)`` (s):
    its last fall through ``level`` before it first went under ``band`` x ``level`` (a Schmitt
    trigger); ``a``'s crossing if it never rose over ``level`` again. An approach that hovers
    at the seed's 15 cm/s dips under it for a sample or two before it slows for good (a careful
    pitcher at 15.3 cm/s for 0.3 s: at 30 Hz or with 5 mm of noise a dip at 4.1 s became the
    crossing, 0.28 s before the clean recording's 4.38 s); a second push after the speed had
    clearly fallen does not move it."""
    seg = s.rel_speed[a:b]
    low = (np.isfinite(seg) & (seg < band * level)).nonzero()[0]
    seg = seg[: int(low[0])] if low.size else seg
    over = (np.isfinite(seg) & (seg >= level)).nonzero()[0]
    return _crossing(s, a + int(over[-1]) + 1, level) if over.size else _crossing(s, a, level)


def carried_together(s: Signals, c: PhaseConfig, a: int, b: int) -> bool:
    """Whether the pair moved the object together over grid indices ``[a, b]``: a median
    common speed of at least ``coupled_speed``, or their midpoint carried ``coupled_travel``."""
    common = s.common_speed[a : b + 1]
    common = common[np.isfinite(common)]
    return bool(common.size) and (
        float(np.median(common)) >= c.coupled_speed or pair_travel(s, a, b) >= c.coupled_travel
    )


def transfer_start(s: Signals, c: PhaseConfig, lo: int, a: int, b: int) -> float:
    """When the approach into the core ``[a, b]`` stopped (s); NaN if not yet seen to settle:
    :func:`settle_time`; in a hold where the pair moves the object together
    (:func:`carried_together`), or where both hands move over the tail up to that time
    (:func:`both_adjusting`), at most ``approach_tail_max`` after the relative speed fell
    under the seed's ``transfer_speed_max`` for good (:func:`speed_fell_for_good`): there the
    hands creeping closer at a few cm/s while the pair turns, carries the object or adjusts to
    each other already hold it
    (careful real handovers of a full pitcher or cup: 0.25-1.0 s of such creep after the
    seed's crossing, the slower hand at 0.33-0.83 of the faster's speed; a synthetic robot
    gripper still arriving at a still hand: 0.01-0.34, and bounding one at 0.16 would date its
    start 0.28 s early)."""
    t = settle_time(s, c, lo, a, b)
    if math.isnan(t):
        return t
    i_s = int(np.searchsorted(s.t, t, side="right"))
    fell = speed_fell_for_good(s, a, i_s, c.transfer_speed_max, c.approach_fall_band)
    bound = fell + c.approach_tail_max
    if t <= bound:
        return t  # settled within the bound: nothing to cap
    if carried_together(s, c, a, b) or both_adjusting(s, c, a, i_s):
        return bound
    return t


def both_adjusting(s: Signals, c: PhaseConfig, a: int, b: int) -> bool:
    """Whether both hands moved over grid indices ``[a, b)``: the slower hand's speed at least
    ``creep_balance`` of the faster's (median over the samples). Hands still closing in
    while both move hold the object and adjust to each other; one hand still arriving at a
    still one has not reached it yet."""
    g, r = s.giver_speed[a:b], s.receiver_speed[a:b]
    with np.errstate(invalid="ignore", divide="ignore"):
        balance = np.minimum(g, r) / np.maximum(g, r)
    balance = balance[np.isfinite(balance)]
    return bool(balance.size) and float(np.median(balance)) >= c.creep_balance


def settle_time(s: Signals, c: PhaseConfig, lo: int, a: int, b: int) -> float:
    """When the approach into the core ``[a, b]`` settled (s); NaN if not yet seen to.

    The relative speed's crossing of the settle speed ``v_s``; when that lies above the hold's
    floor ``v_f`` (``settle_floor_factor`` x floor: a clean approach), the approach's tail,
    parabolic near its end (``v ~ (t_stop - t)^2``), is extrapolated from the crossings of
    the seed's ``transfer_speed_max`` (t_a) and ``v_s`` (t_s) to where it meets ``v_f``:
    ``t_s + stop_extrapolation (t_s - t_a) (sqrt(v_s) - sqrt(v_f)) / (sqrt(v_a) - sqrt(v_s))``
    (at most ``max_refine``). Only the tail seen before the first tracking gap counts. An
    approach that stopped inside a tracking gap is dated from the last sample seen before it
    (:func:`stop_in_gap_before`).
    """
    v_settle = settle_speed(s, c, lo, a, b)
    hidden = stop_in_gap_before(s, a, v_settle)
    if hidden is not None:
        return hidden
    seg = s.rel_speed[a : b + 1]
    gaps = (~np.isfinite(seg)).nonzero()[0]
    seen = seg[: int(gaps[0])] if gaps.size else seg
    below = (seen < v_settle).nonzero()[0]
    if below.size == 0:
        if gaps.size:
            return float(s.t[a + int(seen.argmin())]) if seen.size else float(s.t[a])
        return math.nan
    i = a + int(below[0])
    v_frac = v_settle_fraction(s, c, lo, a)
    # The core's first part is the approach's tail: once the crossing is known, the hold's
    # floor is measured on the samples after it (a short, early hold otherwise reads high).
    for _ in range(2):
        v_f = c.settle_floor_factor * hold_floor(s, c, i, b)
        v_new = min(max(v_f, v_frac), c.transfer_speed_max)
        below = (seen < v_new).nonzero()[0]
        if v_new >= v_settle or below.size == 0:
            break
        v_settle, i = v_new, a + int(below[0])
    t_s = _crossing(s, i, v_settle)
    t_a = _crossing(s, a, c.transfer_speed_max)
    v_a = c.transfer_speed_max
    if v_f < v_settle < v_a and t_s > t_a:
        # (A parabola fitted on the crossings' interval is extrapolated at most TAIL_RATIO times
        # its length: a settle speed near the seed's, from an approach whose peak a marker swap
        # inflated, leaves an interval of a sample or two that the ratio would blow up.)
        ratio = (math.sqrt(v_settle) - math.sqrt(v_f)) / (math.sqrt(v_a) - math.sqrt(v_settle))
        ext = (t_s - t_a) * min(ratio, TAIL_RATIO)
        t_s += min(c.stop_extrapolation * ext, c.max_refine)
    return t_s


def stop_in_gap_before(s: Signals, a: int, v_settle: float) -> float | None:
    """The approach's stop when it hides in a tracking gap ending at grid index ``a``.

    ``None`` if ``a`` follows a seen sample, or the hands have not settled at ``a``. Else, from
    the last sample seen before the gap, approaching at speed ``v`` with ``x`` left to go, the
    minimum-jerk tail (``x ~ (t_stop - t)^3``) stops ``3 x / v`` later; at the latest when the
    gap ends."""
    # (Settled: the relative speed under v_settle, or the pair turning together, their
    # speed against their common motion under it.)
    if a == 0 or np.isfinite(s.rel_speed[a - 1]):
        return None
    if not min(s.rel_speed[a], s.hold_speed[a]) < v_settle:
        return None
    seen = np.isfinite(s.rel_speed[:a]).nonzero()[0]
    t_a = float(s.t[a])
    if seen.size == 0:
        return None
    i = int(seen[-1])
    x = vector_norm(s.rel[a] - s.rel[i])
    v = float(s.rel_speed[i])
    if not (math.isfinite(x) and v > 1e-6):
        return t_a
    return min(float(s.t[i]) + min_jerk_span(x, v), t_a)
