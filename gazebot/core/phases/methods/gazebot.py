"""``gazebot``: the robust default method, composed of the rules in
:mod:`gazebot.core.phases.rules`.

Per handover (a dip of the hands' distance): the transfer starts where the approach stopped
(:mod:`~gazebot.core.phases.rules.transfer`), ends at the back-dated release
(:mod:`~gazebot.core.phases.rules.release`); the reach starts at the giver's motion onset before it
(:mod:`~gazebot.core.phases.rules.reach`) and the retreat ends at rest, far away, at the next reach
or at the data end (:mod:`~gazebot.core.phases.rules.retreat`). A core that starts before the
last transfer's release is part of that transfer; the next reach may start where its dip does,
before the retreat looked finished (the retreat is clipped to it). A recording cut short ends in
the phase under way (``open``), with nothing invented after its last sample.

The robot's gripper and load-share columns are not used here; the online detector uses them
(they arrive before the motion shows).
"""

from __future__ import annotations

import math

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import SignalCache, Signals, compute_signals
from gazebot.core.phases.methods.base import OnlineTrigger, Segmenter
from gazebot.core.phases.methods.gazebot_trigger import GazebotTrigger
from gazebot.core.phases.rules.directed import directed_reach
from gazebot.core.phases.rules.reach import reach_start, trailing_reach
from gazebot.core.phases.rules.release import transfer_end
from gazebot.core.phases.rules.retreat import far_after, rest_after, retreat_done
from gazebot.core.phases.rules.sequential import sequential_reach
from gazebot.core.phases.rules.transfer import TransferCore, carried_together, find_cores
from gazebot.core.phases.segment import Segment
from gazebot.core.phases.trajectory import Trajectory
from gazebot.core.types import Phase


class GazebotSegmenter(Segmenter):
    """The robust default method (see the module docstring)."""

    name = "gazebot"
    rules_after_contact = True

    def signals(
        self, trajectory: Trajectory, partial: bool = False, cache: SignalCache | None = None
    ) -> Signals | None:
        """The smoothed signals (cut ``edge_guard`` before the last sample when ``partial``;
        ``cache``: see :func:`~gazebot.core.phases.filtering.compute_signals`)."""
        if len(trajectory) < 3:
            return None
        if not (partial and self.config.edge_guard > 0):
            return compute_signals(trajectory, self.config, cache)
        # (the grid is sorted: the rows kept are a prefix, taken as views)
        cut = float(trajectory.t[-1]) - self.config.edge_guard + 1e-9
        s = compute_signals(trajectory, self.config, cache, until=cut)
        return s if s.t.shape[0] >= 3 else None

    # ---- online hooks
    def trigger(self) -> OnlineTrigger:
        """The cheap per-period trigger (:mod:`~gazebot.core.phases.methods.gazebot_trigger`)."""
        return GazebotTrigger(self.config)

    def online_signals(
        self, trajectory: Trajectory, cache: SignalCache | None = None
    ) -> Signals | None:
        """The signals cut ``edge_guard`` before the newest sample: the last stretch of the
        smoothed speed sags (one-sided window), so predictions read what the rules read."""
        return self.signals(trajectory, partial=True, cache=cache)

    def online_segments(
        self, trajectory: Trajectory, s: Signals, now: float, phase: Phase = Phase.IDLE
    ) -> list[Segment]:
        """The segments the signals show so far; with no phase under way at their end, a reach
        the raw samples predict before the signals can show it: the giver's hand accelerating
        toward the receiver (:mod:`~gazebot.core.phases.rules.directed`) where the sequential rule
        also confirms it with ``directed_support`` as its bar, or,
        if not, moving in a way no fidget does (:mod:`~gazebot.core.phases.rules.sequential`). In a
        reach (``phase``) the reach onsets are not dated (NaN starts): the detector reads none
        of them then."""
        segs = self.segment_signals(s, now, True, onsets=phase is not Phase.REACH)
        if segs and (segs[-1].open or segs[-1].phase is not Phase.RETREAT):
            return segs
        after = segs[-1].end if segs else -math.inf
        c = self.config
        onset = directed_reach(trajectory, c, after)
        vetoed = False
        if onset is not None and sequential_reach(trajectory, c, after, c.directed_support) is None:
            onset, vetoed = None, True
        # After a veto the sequential rule with a bar no lower than the support's cannot
        # confirm either (the same checks, a higher bar): skip it.
        if onset is None and not (vetoed and c.sequential_evidence >= c.directed_support):
            onset = sequential_reach(trajectory, c, after)
        if onset is not None:
            k = segs[-1].handover + 1 if segs else 0
            segs.append(Segment(Phase.REACH, min(onset, now), now, k, open=True))
        return segs

    def phase_end(
        self, s: Signals, phase: Phase, phase_start: float, joined_late: bool
    ) -> tuple[float, str] | None:
        """Once the hands are in contact, the release and retreat-end rules run from the
        phase's own start (so a phase adopted from elsewhere, or older than the online window,
        ends like any other); before, the whole method finds the next handover."""
        if phase is Phase.TRANSFER:
            n = s.t.shape[0]
            i0 = min(int(s.t.searchsorted(phase_start)), n - 1)
            core = TransferCore(0, i0, n - 1, n - 1, max(phase_start, float(s.t[0])))
            t_end, open_end = transfer_end(s, self.config, core)
            if open_end or t_end >= float(s.t[-1]):
                return None
            return t_end, "motion"
        if phase is Phase.RETREAT:
            return retreat_done(s, self.config, phase_start, joined_late)
        raise ValueError(f"phase_end is for a transfer or retreat, not {phase.value}")

    def segment_sorted(self, trajectory: Trajectory, partial: bool = False) -> list[Segment]:
        """Segments of a time-sorted trajectory by the default method's rules (see
        :meth:`Segmenter.segment_sorted`)."""
        s = self.signals(trajectory, partial)
        if s is None:
            return []
        return self.segment_signals(s, float(trajectory.t[-1]), partial)

    def segment_signals(
        self, s: Signals, t_last: float, partial: bool = False, onsets: bool = True
    ) -> list[Segment]:
        """Segments from precomputed signals (``t_last``: the last sample's time; ``onsets``
        False: the reach segments' starts are left NaN, their onset rule not run)."""
        c = self.config

        def onset_before(lo: int, hi: int) -> float:
            return reach_start(s, c, lo, hi) if onsets else math.nan

        grid_end = float(s.t[-1])
        if partial:
            t_last = grid_end

        def at_end(x: float) -> float:
            return t_last if x >= grid_end - 1e-9 else x

        cores = find_cores(s, c, pieces=not partial)
        out: list[Segment] = []
        prev_end_idx = 0
        if not partial and cores and not cores[0].piece:
            prev_end_idx = _after_leading_retreat(s, c, cores[0].start)
        n = s.t.shape[0]
        trailing_ok = True
        k = -1  # the handover's index
        released = -1  # grid index of the last transfer's end
        for i_core, core in enumerate(cores):
            if core.start <= released:
                continue  # (a hold the previous transfer's release rule found still held)
            k += 1
            if released >= 0:
                # The next reach may start where its dip does, before the retreat looked
                # finished (the retreat is clipped below).
                prev_end_idx = max(min(prev_end_idx, core.lo), released)
            t_start = core.t_start
            if partial and math.isfinite(t_start) and core.end >= n - 2:
                # Online: a transfer is confirmed once the hands have held for min_transfer
                # (the hold's floor, which dates the start, needs a few samples of it) without
                # closing further (a giver waiting for a slowly arriving receiver).
                recent = s.distance[int(s.t.searchsorted(grid_end - c.min_transfer)) :]
                recent = recent[np.isfinite(recent)]
                closing = float(recent[0] - recent.min()) if recent.size else 0.0
                if t_start > grid_end - c.min_transfer or closing > c.still_closing:
                    t_start = math.nan
            if not math.isfinite(t_start):
                if partial:
                    # The approach has not settled yet: still a reach.
                    onset = onset_before(prev_end_idx, core.start)
                    start = max(onset, out[-1].start) if out else onset
                    out.append(Segment(Phase.REACH, min(start, t_last), t_last, k, open=True))
                    trailing_ok = False
                    break
                t_start = float(s.t[core.start])
            t_start = min(t_start, t_last)
            i_start = int(s.t.searchsorted(t_start))
            onset = onset_before(prev_end_idx, max(i_start - 1, prev_end_idx))
            if out:
                onset = max(onset, out[-1].start)  # (out[-1]: the last retreat, from its release)
            if not core.piece:  # (a piece's reach is before the recording)
                out.append(Segment(Phase.REACH, min(onset, t_start), t_start, k))
            t_end, open_end = transfer_end(s, c, core)
            if not open_end and core.end < n - 1 and carried_together(s, c, core.start, core.end):
                # A pair moving the object together that parts slower than the seed's speed
                # for longer than release_tail_max still moves it together (a receiver slowly
                # taking a full pitcher's weight): released at most that long before the
                # hands part faster.
                t_end = max(t_end, float(s.t[core.end]) - c.release_tail_max)
            if open_end:
                out.append(Segment(Phase.TRANSFER, t_start, t_last, k, open=True))
                trailing_ok = False
                break
            if t_end - t_start < c.min_transfer and not partial:
                # A refinement that collapses a short transfer (fast giver, sparse samples):
                # the seed rule's own run stands.
                t_start, t_end = float(s.t[core.start]), float(s.t[core.end])
                if not core.piece:
                    out[-1] = Segment(Phase.REACH, out[-1].start, t_start, k)
            i_end = min(int(s.t.searchsorted(t_end)), n - 1)
            later = [x for x in cores[i_core + 1 :] if x.start > i_end]
            nxt = later[0].start if later else n - 1
            t_rest, seen = rest_after(s, c, i_end, max(nxt, i_end))
            t_far = far_after(s, c, i_end)
            if later:
                seen = True  # the next handover ends this one at the latest
            retreat_end = min(t_rest, t_far)
            seen = seen or math.isfinite(t_far)
            retreat_end = at_end(max(retreat_end, t_end))
            out.append(Segment(Phase.TRANSFER, t_start, t_end, k))
            out.append(Segment(Phase.RETREAT, t_end, retreat_end, k, open=not seen))
            prev_end_idx = int(s.t.searchsorted(retreat_end))
            released = i_end
        if trailing_ok and (not out or out[-1].phase is Phase.RETREAT):
            trailing_onset = trailing_reach(s, c, min(prev_end_idx, n - 1))
            if trailing_onset is not None:
                start = max(trailing_onset, out[-1].end) if out else trailing_onset
                k = out[-1].handover + 1 if out else 0
                out.append(Segment(Phase.REACH, min(start, t_last), t_last, k, open=True))
        # The next reach may begin before the retreat looked finished: clip the retreat.
        for i in range(len(out) - 1):
            ret, nxt_reach = out[i], out[i + 1]
            if ret.phase is Phase.RETREAT and ret.end > nxt_reach.start:
                fixed = max(nxt_reach.start, ret.start)
                out[i] = Segment(Phase.RETREAT, ret.start, fixed, ret.handover)
                if nxt_reach.start < fixed:
                    out[i + 1] = Segment(
                        Phase.REACH, fixed, nxt_reach.end, nxt_reach.handover, open=nxt_reach.open
                    )
        return out


def _after_leading_retreat(s: Signals, c: PhaseConfig, a: int) -> int:
    """Where the first reach may start before the first core at grid index ``a``: a recording
    that starts with the hands together and parting (cut from inside a previous handover, issue
    33) has that handover's retreat first; the hands are farthest apart before the next
    approach, ``min_approach`` above the first distance seen. 0 otherwise."""
    d = s.distance[: a + 1]
    seen = np.isfinite(d).nonzero()[0]
    if seen.size == 0:
        return 0
    top = int(seen[int(d[seen].argmax())])
    return top if d[top] - d[seen[0]] >= c.min_approach else 0
