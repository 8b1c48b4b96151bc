"""Transfer -> retreat: when the giver lets go.

The hands are still together while their relative speed *against their common motion*
(``Signals.hold_speed``) stays within ``settle_floor_factor`` times the hold's floor: hands
carrying an object together turn with it, so the marker frames behind the hands swing at a
constant distance (issue 20: 0.02-0.10 m/s of relative motion through a 1 s joint carry), and
judged against stillness that hold would end at its first turn. The held pose is the median
relative position (receiver - giver) over the last samples still together; its RMS jitter
there measures the tracking noise. The release is not before that last still sample. It is seen
once the relative position has left the held pose by ``release_distance``, or
``release_noise_factor`` times that jitter if larger, and is back-dated with the minimum-jerk
start (:func:`~gazebot.core.phases.rules.onset.min_jerk_span`, at most ``max_refine``). A release
hidden in a tracking gap is dated from the separation seen before the gap, else from the
giver's own motion onset after it (not a motion mostly toward the receiver: with the receiver
unseen, that is the pair moving the object). If the hands never part before the data end,
the transfer is still open.

Hands that move the object together through the hold (their common motion's median speed over
it at least ``coupled_speed``: a full pitcher carried carefully, issue 33) may turn with it:
the marker frames, 0.3 m apart behind the hands, then swing their relative position by
centimetres at a constant distance. For such a coupled hold the release is the hands'
*distance* leaving the held distance by ``release_distance`` (or ``release_noise_factor``
times its jitter over the whole hold), or one hand moving against the other faster than the
seed's ``transfer_speed_max`` beyond their common motion (``hold_speed``: a hand withdrawn
sideways) once the distance has left half that band; a turn of the pair, a fidget or a pause
of one hand within the band is no release, nor a sample or two of marker noise at 30 Hz. When
the giver leads that parting (its hand has moved farther than the receiver's since the
back-dated release: letting go and withdrawing, not pulled by the receiver), the back-dated
release stands even before the last sample still together by the hold speed, and is not after
the giver's last speed minimum before the parting (at most ``max_refine`` earlier and after
the transfer's start, rises within the hold's speed floor ignored): the pair's common motion
slows into the release, and the first centimetres of a retreat may run across the hands'
line, their distance unchanged. That lead counts only from the hands' distance's last minimum
on: hands still closing in have not let go, so a release back-dated before it is not before
the last sample still together, and the giver's departure is not before it (a pair carrying
a pitcher on at 0.28 m/s while the receiver slowed and the distance shrank 1 cm more was
released 0.05 s before its closest point; at 30 Hz with noise and a marker offset, the
giver's last speed minimum put a release 0.3-0.4 s early).

No hold ends with the hands pressing the object in (the distance shrinking below the held
one), and hands that carried the object together into a tracking gap that lasts to the newest
sample are not released by the giver's motion: it is the pair's. Hands that were moving the
object together (a coupled hold, or carrying it at the last still sample), or that have held
for less than ``young_hold``, have parted only if they are no nearer the held pose a smoothing
window later; when that falls in a tracking gap, a smoothing window after the gap, and for a
pair moving the object together by their distance (they may have turned it in the gap). Back
together there, the hold goes on across the gap and is judged again over all of it.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import ALONG_LINE_SHARE, Signals, across_line, vector_norm
from gazebot.core.phases.rules.onset import min_jerk_span
from gazebot.core.phases.rules.transfer import (
    TransferCore,
    both_seen,
    carried_together,
    distance_band,
    hold_floor,
    jitter_band,
)

MAD_TO_SIGMA = 1.4826  # median absolute deviation -> standard deviation of a normal


def release_threshold(s: Signals, c: PhaseConfig, held_idx: np.ndarray, held: np.ndarray) -> float:
    """Separation from the held pose (a relative position, or a distance for a coupled hold)
    that marks the release (m)."""
    if held.ndim == 0:
        return distance_band(c, s.distance[held_idx] - held)
    return distance_band(c, np.linalg.norm(s.rel[held_idx] - held, axis=1))


def last_in_band(s: Signals, c: PhaseConfig, a: int, b: int) -> int:
    """The last grid index in ``[a, b]`` (a hold) whose distance is within the hold's band of
    its median (:func:`~gazebot.core.phases.rules.transfer.jitter_band`, the jitter from the
    median absolute deviation: robust to the hold's own trailing samples, where the hands may
    already part). ``a`` if none is seen."""
    d = s.distance[a : b + 1]
    seen = np.isfinite(d)
    if not seen.any():
        return a
    dev = np.abs(d - np.median(d[seen]))
    band = jitter_band(c, MAD_TO_SIGMA * float(np.median(dev[seen])))
    inside = (seen & (dev < band)).nonzero()[0]
    return a + int(inside[-1]) if inside.size else a


def transfer_end(s: Signals, c: PhaseConfig, core: TransferCore) -> tuple[float, bool]:
    """``(t_end, open_end)``: the release time, and whether the data end before it.

    The held pose is taken at the end of the hold (the last samples still together, judged by
    ``hold_speed``): both hands carry the object during a transfer, and may turn with it, so
    the relative pose drifts, and a pose from the start of the hold would date the release
    early.
    """
    a, b = core.start, core.end
    t_start = core.t_start if math.isfinite(core.t_start) else float(s.t[a])
    # The hands were still together (within the hold's own noise) up to i_h: the release is
    # not before it.
    v_still = c.settle_floor_factor * hold_floor(s, c, a, b)
    i0 = min(max(a, int(s.t.searchsorted(t_start))), b)
    still = (s.hold_speed[i0 : b + 1] <= v_still).nonzero()[0] + i0
    # ... not counting the core's last samples out of the hold's distance band: a retreat
    # starts slowly, inside the seed-rule core, and under marker noise its relative speed
    # dips under v_still there by chance (5 mm at 30 Hz: a release 0.26 s late).
    still = still[still <= last_in_band(s, c, i0, b)]
    i_h = int(still[-1]) if still.size else i0
    window = max(2, int(round(c.smoothing * c.analysis_rate)))
    idx = np.arange(max(i0, i_h - window), i_h + 1)
    dists = s.distance[idx]
    dists = dists[np.isfinite(dists)]
    held_d = np.asarray(np.median(dists) if dists.size else np.nan)
    # The distance's jitter over the whole hold, not only its last window: a dozen smoothed
    # samples under-rate 5 mm marker noise at 30 Hz, and a coupled hold's distance holds.
    band = release_threshold(s, c, np.arange(i0, i_h + 1), held_d)
    # Coupled: the pair moved the object together (a median common speed of coupled_speed,
    # or their midpoint carried coupled_travel: a pair slowing into the release has a lower
    # median) through a hold of at least min_transfer, their distance held (within twice its
    # band: the approach is over).
    hold_d = s.distance[i0 : i_h + 1]
    hold_d = hold_d[np.isfinite(hold_d)]
    held_for = float(s.t[i_h] - s.t[i0])
    coupled = (
        carried_together(s, c, i0, i_h)
        and held_for >= c.min_transfer
        and float(hold_d.max() - hold_d.min()) <= 2.0 * band
    )
    if coupled:
        held, sep_min = held_d, band
    else:
        rows = s.rel[idx]
        rows = rows[np.isfinite(rows).all(axis=1)]
        held = np.median(rows, axis=0) if rows.size else np.full(3, np.nan)
        sep_min = release_threshold(s, c, idx, held)
    n = s.t.shape[0]

    def separation(i: int) -> float:
        if coupled:
            return abs(float(s.distance[i] - held))
        return vector_norm(s.rel[i] - held)

    def swing(i: int) -> bool:
        # Relative motion mostly across the hands' line (less than half of it along) with
        # their distance in its band: the pair turning with the object (about either hand, so
        # one may stay put).
        return bool(across_line(s.closing[i], s.rel_speed[i])
                    and abs(s.distance[i] - held_d) < band)

    def carried(i: int) -> bool:
        # Both hands moving the object (their common motion at least coupled_speed), neither
        # against the other faster than the seed's speed.
        return bool(s.common_speed[i] >= c.coupled_speed
                    and s.hold_speed[i] < c.transfer_speed_max)

    def moving_apart(i: int) -> bool:
        # At least half of the relative motion apart, or the distance out of its band: not the
        # pair turning (swing) nor pressing the object together (the distance shrinking).
        return bool(-s.closing[i] >= ALONG_LINE_SHARE * s.rel_speed[i]
                    or not abs(s.distance[i] - held_d) < band)

    def parted(i: int) -> bool:
        # A hand moving against the other faster than the seed's speed: in a coupled hold, once
        # the distance has left half its band too (marker noise at 30 Hz alone reaches that
        # speed for a sample or two).
        if s.closing[i] > 0.0 and s.distance[i] < held_d - 0.5 * band:
            return False  # pressing the object in: the distance shrinks below the held one
        fast = s.hold_speed[i] >= c.transfer_speed_max
        if fast and separation(i) >= (0.5 if coupled else 1.0) * sep_min:
            return True
        if not separation(i) >= sep_min:
            return False
        # (a hand withdrawn faster than the seed's speed was judged above)
        return coupled or moving_apart(i)

    # Hands that were moving the object together (a coupled hold, or carrying it at the last
    # still sample), or that have held for less than young_hold, have parted only if they are
    # no nearer the held pose a smoothing window later: a marker that lags or freezes as the
    # pair sets off parts them for a few samples, and online the newest samples are smoothed
    # from one side only, so the first samples of a hold just confirmed may read as a parting.
    # (Other holds are not kept waiting: a robot reacts to their release a window sooner.)
    moving_together = coupled or carried(i_h)
    confirm = moving_together or held_for < c.young_hold

    def after_gap(g: int) -> tuple[int, int]:
        # The sample a smoothing window after the tracking gap at grid index g (its edge is
        # smoothed one-sided), -1 if not seen yet, and how many samples are seen after it.
        seen = np.isfinite(s.rel_speed[g:]).nonzero()[0] + g
        return (int(seen[window]) if seen.size > window else -1), int(seen.size)

    def persists(i: int) -> bool:
        if not parted(i):
            return False
        if not confirm:
            return True
        k = i + window
        if k >= n:
            return False
        if not np.isfinite(s.rel_speed[k]):
            # A window later falls in a tracking gap: judged a window after it, as a gap in
            # the hold is. With nothing seen after the gap, the parting stands, as it would
            # unchecked (online, a robot reacts to a release hidden in a gap at once), if the
            # hands move apart or the giver leads (withdrawing in any direction): a receiver
            # moving across the hands' line is carrying the object with a giver whose marker
            # lags into the gap.
            k, seen = after_gap(k)
            if seen == 0:
                return moving_apart(i) or bool(s.giver_speed[i] >= s.receiver_speed[i])
            if k < 0:
                return False  # too little seen after the gap yet
            if moving_together:
                # (the pair may have turned the object in the gap: their distance tells)
                return not abs(s.distance[k] - held_d) < band
        return not separation(k) < separation(i)

    j = i_h
    while j + 1 < n and not persists(j):
        if not np.isfinite(s.rel_speed[j + 1]):
            # Seen still together a smoothing window after the gap: the giver's motion in it
            # was the pair's.
            k, seen = after_gap(j + 1)
            if k >= 0 and not parted(k):
                if moving_together and k > b and s.hold_speed[k] <= v_still:
                    # The pair carried the object across the gap and still holds it: the hold
                    # goes on to the end of that still run, judged again over all of it (held
                    # pose, coupling, last still sample). The core only grows: this ends.
                    e = k
                    while e + 1 < n and s.hold_speed[e + 1] <= v_still:
                        e += 1
                    return transfer_end(s, c, replace(core, end=e))
                j = k
                continue
            if k < 0 and seen > 0:
                return float(s.t[-1]), True  # too little seen after the gap yet
            if k < 0 and (coupled or swing(j) or carried(j)):
                # The hands moved together into a gap that lasts to the data end: the
                # giver's motion is the pair's, a hand unseen (a frozen or lost marker) no
                # release.
                return float(s.t[-1]), True
            sep = separation(j)
            # (a gap to the data end: only the giver's own motion tells, below)
            if k >= 0 and sep >= 0.5 * sep_min and s.rel_speed[j] > 1e-6:
                back = min_jerk_span(sep, float(s.rel_speed[j]), c.max_refine)
                return max(float(s.t[j]) - back, t_start), False
            onset = giver_onset_after(s, c, j)
            if onset is None and not np.isfinite(s.rel_speed[j + 1 :]).any():
                return float(s.t[-1]), True  # tracking lost until the end, nothing moved
            return max(float(s.t[j]) if onset is None else onset, t_start), False
        j += 1
    if j == n - 1 and not persists(j):
        return float(s.t[-1]), True
    if coupled:
        sep = max(separation(j), vector_norm(s.rel[j] - s.rel[i_h]))
    else:
        sep = separation(j)
    back = min_jerk_span(sep, float(s.rel_speed[j]), c.max_refine)
    t_end = float(s.t[j]) - back
    # The release is not before the last sample still together, unless the giver leads the
    # parting of a coupled hold: a giver who lets go and withdraws starts slowly (minimum
    # jerk), under the hold's speed bar for a while after the release, so the back-dating
    # alone tells; a receiver pulling the object takes it only once the giver feels the pull
    # (the KTH sample's force truth: the giver lets go 0.05-0.08 s after the distance starts
    # to grow).
    if coupled:
        # (Hands still closing in have not let go: the lead counts from the distance's last
        # minimum.)
        t_closest = closest_before(s, i0, j)
        if t_end >= t_closest and giver_leads(s, t_end, j):
            # The giver's own departure began where its speed last bottomed out before the
            # parting: the pair's common motion slows into the release, and the first
            # centimetres of a retreat may run across the hands' line, leaving their distance
            # unchanged.
            t_min = max(t_end - c.max_refine, t_start)
            departure = giver_departure(s, j, t_min, hold_floor(s, c, i0, i_h), t_closest)
            if departure is not None:
                t_end = min(t_end, departure)
            return max(t_end, t_closest, t_start), False
    return max(t_end, float(s.t[i_h]), t_start), False


def closest_before(s: Signals, a: int, j: int) -> float:
    """Time (s) of the hands' smallest distance over grid indices ``[a, j]`` (the last one if
    it recurs); ``s.t[a]`` if none is seen."""
    d = s.distance[a : j + 1]
    if not np.isfinite(d).any():
        return float(s.t[a])
    k = d.shape[0] - 1 - int(np.nanargmin(d[::-1]))
    return float(s.t[a + k])


def giver_leads(s: Signals, t_from: float, j: int) -> bool:
    """Whether the giver's hand has moved farther than the receiver's from ``t_from`` (s; the
    nearest seen grid sample) to grid index ``j``: who set off first in a parting."""
    rows = both_seen(s, 0, j)
    if rows.size == 0:
        return False
    b = int(rows[np.argmin(np.abs(s.t[rows] - t_from))])
    return vector_norm(s.giver[j] - s.giver[b]) >= vector_norm(s.receiver[j] - s.receiver[b])


def giver_departure(
    s: Signals, j: int, t_min: float, tol: float, t_met: float = -math.inf
) -> float | None:
    """Time (s) of the giver's last speed minimum before grid index ``j``: going back from
    ``j`` while its speed keeps falling, or rises by less than ``tol`` (m/s: the hold's noise),
    to a rise or a tracking gap, not before ``t_min`` (s). ``None`` when the speed still falls
    there (the giver was slowing all along) or when that minimum is before ``t_met`` (s, when
    the hands were last nearest: they still closed in there, and the giver's speed rose with
    the pair carrying the object on): no pause to depart from."""
    v = s.giver_speed
    k = best = j
    rose = False
    while k > 0 and s.t[k - 1] >= t_min:
        if not np.isfinite(v[k - 1]) or v[k - 1] >= v[best] + tol:
            rose = True  # (a tracking gap: the departure began in it at the latest)
            break
        k -= 1
        if v[k] <= v[best]:
            best = k
    if not rose and best <= k:
        return None  # still falling at t_min
    return float(s.t[best]) if s.t[best] >= t_met else None


def giver_onset_after(s: Signals, c: PhaseConfig, j: int) -> float | None:
    """Start of the giver's first motion after grid index ``j`` that is not mostly toward
    the receiver's hand as last seen at ``j`` (``None`` if none is seen): with the receiver
    unseen, a giver moving toward it is moving the object with it (or pressing it in), not
    withdrawing."""
    v = s.giver_speed[j:]
    rel = s.rel[j]
    line = rel / vector_norm(rel) if vector_norm(rel) > 0.0 else np.zeros(3)
    toward = s.giver_v[j:] @ line >= ALONG_LINE_SHARE * v
    fast = ((v >= c.reach_onset_speed) & ~toward).nonzero()[0]
    if fast.size == 0:
        return None
    i = j + int(fast[0])
    x = vector_norm(s.giver[i] - s.giver[j])
    # Across a tracking gap the motion may have started anywhere in it.
    unseen = float(np.count_nonzero(~np.isfinite(v[: fast[0]]))) / c.analysis_rate
    back = min_jerk_span(x, float(v[fast[0]]), c.max_refine + unseen)
    return max(float(s.t[i]) - back, float(s.t[j]))
