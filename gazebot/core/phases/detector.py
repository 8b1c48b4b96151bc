"""Online (causal) phase detection, one tracking frame at a time.

The detector keeps the last ``online_window`` seconds of samples and, at most every
``online_period``, runs the configured method (:mod:`gazebot.core.phases.methods`) on the samples
seen so far (``partial``: a boundary the data do not show yet stays open, and the last
``edge_guard`` is not trusted). A method may offer a cheap trigger (the
:meth:`~gazebot.core.phases.methods.base.Segmenter.trigger` hook; ``gazebot``'s is
:mod:`~gazebot.core.phases.methods.gazebot_trigger`) that says per period whether its analysis
needs to run, and its own rules for when a transfer or retreat ends once the hands are in
contact (``rules_after_contact`` / ``phase_end``); the detector has no method-specific branch.
Each phase start the analysis shows beyond the current phase is emitted once, in order
(reach -> transfer -> retreat -> done), back-dated to where the analysis puts it (never before
the current phase's start). So online and offline share every rule; the online latency is what
the data need to show a boundary.

Robot evidence (seed section 4.3) comes first: a rising edge of "gripper closed" or of a load
share above ``load_share_shared`` starts the transfer at once (and reports the reach if it was
missed); a load share above ``load_share_robot`` starts the retreat. Once frames carry that
evidence, hand motion alone no longer starts a transfer (hands resting close together while the
robot has not grasped are a giver waiting). A frame without it (over the bus: a silence tick, a
sample assembled without its gripper part) is a gap, not an open gripper: the edge needs the
gripper seen open (or the load share low) before.

A reach the analysis no longer shows for ``online_period`` + ``max_refine``, with the hands
back about as far apart as when it started (taken back before any transfer), ends as
``handover_done`` with ``source = "aborted"`` (a reach replayed into the handover state
before the first sample, :meth:`PhaseDetector.resync`: once the hands are
``transfer_distance_margin`` farther apart than the closest seen). A reach that was an
earlier movement (the giver lifted the object, rested ``reach_stall`` or swayed with it while
the hands came no nearer, or took it back part of the way, then set off toward the receiver)
ends with ``source = "stalled"``
when the final approach shows, and that approach is the reach (a new ``reach_started``); a
retreat longer
than ``max_retreat`` ends with ``source = "timeout"``.

Bad samples: a frame with a non-finite time, or a time not after the last accepted one
(duplicate or out of order), is ignored and counted (``stats``). Missing points (NaN) and
frozen repeats are bridged for up to ``max_gap_hold``; after that ``tracking_lost`` fires
(``t`` = last valid sample, ``info["missing"]`` names the points) and phase detection pauses
until both hands are seen again (``tracking_restored``).

The phase is the handover state's (:class:`~gazebot.core.handover.HandoverState`): the detector
reads it through a :class:`~gazebot.core.handover.HandoverView` and reports each event to
whoever applies it to that state (the engine), then reads the state it moved.
:class:`OnlineDetector` pairs a detector with a state of its own (the phases the tracking alone
shows: replays, tools, tests).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gazebot.core.handover import HandoverState, HandoverView
from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.durations import REACH_S
from gazebot.core.phases.filtering import SignalCache, Signals, nanmax, nanmin
from gazebot.core.phases.methods import make_segmenter
from gazebot.core.phases.methods.base import OnlineState
from gazebot.core.phases.prediction import predict_end
from gazebot.core.phases.segment import Segment, segments_from_events
from gazebot.core.phases.trajectory import Trajectory
from gazebot.core.types import EVENT_OF_PHASE, Event, EventKind, Phase, TrackingFrame


def _point(p: object) -> np.ndarray:
    """A point as a float 3-vector (NaNs if it is not a numeric 3-vector)."""
    try:
        v = np.asarray(p, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        return np.full(3, np.nan)
    return v if v.shape == (3,) else np.full(3, np.nan)


_ROW = 7  # values of a kept sample: t, giver xyz, receiver xyz


class _Samples:
    """The samples kept (rows ``[t, giver xyz, receiver xyz]``) in one array that grows and is
    compacted in place: the analysis reads them as views, with no per-sample conversion. A new
    sample waits in a flat list until the rows are read (a list extend per sample; the new
    rows' values are copied into the block once per analysis). The rows are read through a
    read-only view of the block (made once per block, not per read: an analysis cannot write
    into the samples kept)."""

    def __init__(self) -> None:
        self._buf = np.empty((256, _ROW))
        self._flat, self._ro = self._views(self._buf)
        self._s0 = self._s1 = 0
        self._new: list[float] = []  # the newest rows' values, _ROW a row, not yet in _buf
        self._first_t = math.inf  # time of the first sample kept (a float: read every sample)

    def __len__(self) -> int:
        return self._s1 - self._s0 + len(self._new) // _ROW

    def append(self, row: tuple[float, ...], keep_from: float = -math.inf) -> None:
        """Queue a sample (``_ROW`` values; times increasing), then forget those older than
        ``keep_from`` (one call per sample: :meth:`drop_before` runs only when there is one to
        forget)."""
        t = row[0]
        if t < self._first_t:  # (only when none is kept, _first_t inf: the times increase)
            self._first_t = t
        self._new += row
        if self._first_t < keep_from:
            self.drop_before(keep_from)

    def drop_before(self, t0: float) -> None:
        """Forget the samples older than ``t0``."""
        if self._first_t >= t0:
            return
        buf, i, end = self._buf, self._s0, self._s1
        while i < end and buf[i, 0] < t0:
            i += 1
        self._s0 = i
        if i < end:
            self._first_t = float(buf[i, 0])
            return
        new = self._new  # (every row in the array is gone: the new rows next)
        k = 0
        while k < len(new) and new[k] < t0:
            k += _ROW
        del new[:k]
        self._first_t = new[0] if new else math.inf

    def time(self, i: int) -> float:
        """Time of the ``i``-th sample kept."""
        m = self._s1 - self._s0
        return float(self._buf[self._s0 + i, 0]) if i < m else self._new[(i - m) * _ROW]

    @staticmethod
    def _views(buf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The block's values as one flat writable view, and the block as a read-only view."""
        ro = buf.view()
        ro.flags.writeable = False
        return buf.reshape(-1), ro

    def rows(self) -> np.ndarray:
        """The samples kept (a read-only view of the buffer: valid until the next call that
        grows or compacts it; :meth:`append` only queues)."""
        new = self._new
        if new:
            k, buf = len(new) // _ROW, self._buf
            if self._s1 + k > buf.shape[0]:
                m = self._s1 - self._s0
                cap = buf.shape[0]
                while 2 * (m + k) > cap:
                    cap *= 2
                if cap != buf.shape[0]:
                    self._buf = np.empty((cap, _ROW))
                    self._flat, self._ro = self._views(self._buf)
                self._buf[:m] = buf[self._s0 : self._s1]
                self._s0, self._s1 = 0, m
            s1 = self._s1
            # (the new rows' block, row by row, through the flat view)
            self._flat[s1 * _ROW : (s1 + k) * _ROW] = new
            self._s1 = s1 + k
            new.clear()
        return self._ro[self._s0 : self._s1]


@dataclass
class DetectorStats:
    """Counts of samples the detector ignored or bridged, and analyses it ran."""

    samples: int = 0
    out_of_order: int = 0
    duplicates: int = 0
    bad_time: int = 0
    held: int = 0
    analyses: int = 0
    skipped: int = 0


class PhaseDetector:
    """Causal handover phase evidence from the tracked hands, running ``config.method`` (see the
    module docstring).

    The detector keeps no phase: it reads the one handover state through a read-only
    :class:`~gazebot.core.handover.HandoverView` and reports the boundaries the tracking shows
    beyond the state's phase; whoever owns the state applies them (the engine, or
    :class:`OnlineDetector`). What it keeps is the evidence of the phase under way (where the
    next boundary may start, the hands' distance when a reach began, the end estimate),
    rebuilt whenever the state enters a phase the tracking follows (:attr:`HandoverView.entry`).

    Attributes:
        config: The settings.
        tracking: False between ``tracking_lost`` and ``tracking_restored``.
        stats: Counts of ignored and bridged samples.
    """

    def __init__(self, config: PhaseConfig | None = None) -> None:
        self.config = config if config is not None else PhaseConfig()
        self.segmenter = make_segmenter(self.config)
        self.tracking = True
        self.stats = DetectorStats()
        self._view: HandoverView | None = None  # the state read (set by each update)
        self._report: Callable[[Event], object] = _nowhere
        self._entry = -1  # the state's phase entry the evidence below belongs to (-1: none)
        self._rejoined = False  # resync(): the next phase entry joins a phase under way
        self._expected_end = math.nan
        self._samples = _Samples()
        self._last_t = -math.inf
        self._last_analysis = -math.inf
        self._seen_g = self._seen_r = math.nan  # last valid sample of each hand
        # Robot evidence at the previous frame; None: not known (after a resync the first frame
        # sets it, so a gripper already closed is no rising edge).
        self._prev_evidence: bool | None = False
        self._robot_reports = False
        self._signals: Signals | None = None
        self._finite_of: Signals | None = None  # the signals self._finite indexes
        self._finite = np.empty(0, dtype=np.intp)
        # The last analysis's signals, so the next one (on the same window, a few samples
        # longer) computes only the rows the new samples change. (append_only: the windows
        # are cut from the samples kept, which only grow at their end.)
        self._signal_cache = SignalCache(append_only=True)
        self._unknown = np.empty((0, 5))  # (see _unknown_block)
        # The method's cheap trigger, if it has one: the full analysis runs only when the next
        # boundary may have passed.
        self._trigger = self.segmenter.trigger()
        self._last_full = -math.inf
        self._reach_missing_since = math.nan
        # The current phase began before this detector saw the hands move (resync, restart).
        self._joined_late = False
        # The hands' distance when the current reach began, as last read while the analysis
        # window still held that moment (a reach can outlast the window); NaN: never read.
        self._reach_d0 = math.nan
        self._reach_g0 = np.full(3, np.nan)  # the giver's hand then (the same window)

    # ----------------------------------------------------------------- public API
    def update(
        self, frame: TrackingFrame, view: HandoverView, report: Callable[[Event], object]
    ) -> None:
        """Feed one frame. Every event it reveals (phase boundaries, ``tracking_lost`` /
        ``tracking_restored``) goes to ``report``, oldest first; ``report`` applies it to the
        handover state ``view`` reads before the detector looks further (a gripper closing can
        reveal a reach and a transfer: the transfer is the one after the reach the state
        took)."""
        self._view, self._report = view, report
        self._sync()
        self._step(frame)

    def expected_end(self, view: HandoverView) -> float:
        """The tracking's estimate of the end of ``view``'s phase (s; NaN when unknown: idle,
        done, or a reach only the robot has started)."""
        self._view = view
        self._sync()
        return self._expected_end

    def resync(self) -> None:
        """The handover state was replayed (e.g. after an engine restart): the phase under way
        began before this detector saw the hands move, and the robot evidence of the next frame
        is a baseline, not an edge (a gripper still closed after a finished handover starts no
        new one)."""
        self._rejoined = True
        self._joined_late = True
        self._prev_evidence = None

    # ----------------------------------------------------------------- the state's phase
    @property
    def _phase(self) -> Phase:
        """The state's phase as far as the tracking follows it: a reach only the robot has
        started is not yet one (the giver's own reach start is still to be reported: the
        first reach wins), so it reads as the idle or done before it."""
        view = self._state()
        if view.phase is Phase.REACH and not view.reach_tracked:
            return Phase.DONE if view.handover_t0 > -math.inf else Phase.IDLE
        return view.phase

    @property
    def _phase_start(self) -> float:
        """The start of :attr:`_phase` (s; NaN in idle)."""
        view = self._state()
        phase = self._phase
        if phase is Phase.IDLE:
            return math.nan
        return view.phase_start if phase is view.phase else view.handover_t0

    @property
    def _floor(self) -> float:
        """The next phase never starts before this (s): the current phase's start."""
        start = self._phase_start
        return -math.inf if math.isnan(start) else start

    def _state(self) -> HandoverView:
        if self._view is None:
            raise RuntimeError("the phase detector reads a handover state only while updated")
        return self._view

    def _sync(self) -> None:
        """Rebuild the phase's evidence when the state entered a phase since it was built."""
        entry = self._state().entry
        if entry != self._entry:
            self._entry = entry
            self._enter(self._phase, self._phase_start)
            if self._rejoined:
                self._joined_late = True
        self._rejoined = False

    def _emit(self, event: Event) -> None:
        """Report ``event``, then follow the state it moved."""
        self._report(event)
        self._sync()

    # ----------------------------------------------------------------- internals
    def _enter(self, phase: Phase, t0: float) -> None:
        # Joined late: fewer than two samples seen before the phase's start.
        self._joined_late = len(self._samples) < 3 or self._samples.time(1) >= t0
        self._reach_missing_since = math.nan
        self._reach_d0, self._reach_g0 = math.nan, np.full(3, np.nan)
        self._expected_end = predict_end(phase, t0, self._signals, t0, self.config)

    def _handover(self, phase: Phase) -> int:
        """The index of the handover a ``phase`` start reported now belongs to: the state's
        next one when it is between handovers (the state counts it so), else its current."""
        view = self._state()
        new = phase is not Phase.DONE and view.phase in (Phase.IDLE, Phase.DONE)
        return max(view.handover + (1 if new else 0), 0)

    def _start(self, phase: Phase, t0: float, now: float, source: str) -> None:
        t0 = min(t0, now)
        start = self._phase_start
        if math.isfinite(start):
            t0 = max(t0, start)  # phases never go back in time
        info = {"handover": self._handover(phase), "source": source}
        self._emit(Event(EVENT_OF_PHASE[phase], t0, now, info))

    def _step(self, frame: TrackingFrame) -> None:
        st = self.stats
        try:
            t = float(frame.t)
        except (TypeError, ValueError, OverflowError):
            t = math.nan
        if not math.isfinite(t):
            st.bad_time += 1
            return
        if t <= self._last_t:
            if t == self._last_t:
                st.duplicates += 1
            else:
                st.out_of_order += 1
            return
        self._last_t = t
        st.samples += 1
        c = self.config
        g = _point(frame.giver_hand).tolist()
        r = _point(frame.receiver_hand).tolist()
        gx, gy, gz = g
        rx, ry, rz = r
        g_ok = math.isfinite(gx) and math.isfinite(gy) and math.isfinite(gz)
        r_ok = math.isfinite(rx) and math.isfinite(ry) and math.isfinite(rz)
        samples = self._samples
        samples.append((t, gx, gy, gz, rx, ry, rz), t - c.online_window)
        if g_ok:
            self._seen_g = t
        if r_ok:
            self._seen_r = t
        if self._trigger is not None:
            self._trigger.add(g, g_ok, r, r_ok)
        if not (g_ok and r_ok):
            st.held += 1
            if self.tracking:
                first = samples.time(0)
                last_g = first if math.isnan(self._seen_g) else self._seen_g
                last_r = first if math.isnan(self._seen_r) else self._seen_r
                last = min(last_g, last_r)
                if t - last > c.max_gap_hold:
                    self.tracking = False
                    missing = [
                        n for n, ok in (("giver_hand", g_ok), ("receiver_hand", r_ok)) if not ok
                    ]
                    info = {"handover": max(self._state().handover, 0), "missing": missing}
                    self._emit(Event(EventKind.TRACKING_LOST, last, t, info))
            if not self.tracking:
                return
        elif not self.tracking:
            self.tracking = True
            info = {"handover": max(self._state().handover, 0)}
            self._emit(Event(EventKind.TRACKING_RESTORED, t, t, info))

        has_evidence = frame.gripper_closed is not None or frame.load_share is not None
        if has_evidence and self._robot_evidence(frame, t):
            return
        if t - self._last_analysis >= c.online_period - 1e-9:
            # On a fixed grid of online_period (the first sample at or after each tick), not
            # online_period after the last analysed sample: that waits up to twice the period
            # when samples come just faster than it (60 Hz: 33 ms, 100 Hz: 30 ms by rounding),
            # so more samples would confirm later.
            since = t - self._last_analysis
            if c.online_period > 0 and since < 4.0 * c.online_period:
                self._last_analysis += c.online_period * math.floor(since / c.online_period + 1e-6)
            else:
                self._last_analysis = t  # the first sample, or after a pause: a new grid
            mode = "full"
            if self._trigger is not None:
                mode = self._trigger.decide(t, self._online_state())
            if mode != "skip":
                self._last_full = t
                self._analyse(t, predict_only=mode == "refresh")
                return
            self.stats.skipped += 1
            if self._phase is Phase.RETREAT and t - self._phase_start > c.max_retreat:
                self._done(t, t, "timeout")
        if math.isfinite(self._expected_end) and t > self._expected_end:
            self._expected_end = t  # an estimate already passed: the phase ends no earlier

    def _online_state(self) -> OnlineState:
        """What the trigger reads of the detector and the state's phase."""
        return OnlineState(
            phase=self._phase,
            phase_start=self._phase_start,
            floor=self._floor,
            tracking=self.tracking,
            joined_late=self._joined_late,
            last_full=self._last_full,
        )

    def _robot_evidence(self, frame: TrackingFrame, t: float) -> bool:
        """Gripper / load-share evidence of a frame; True if it started a phase on this frame.

        A frame that carries neither (tracking alone; over the bus also a silence tick, or a
        sample assembled without its gripper part) says nothing of the gripper: it keeps the
        baseline the last frame with evidence set, so a gripper that stayed closed through
        the gap is no grasp when it is seen again (issue 30's phantom handover)."""
        c = self.config
        load = frame.load_share
        load_ok = load is not None and math.isfinite(load)
        if frame.gripper_closed is None and not load_ok:
            return False
        self._robot_reports = True
        grip = frame.gripper_closed is not None and bool(frame.gripper_closed)
        evidence = grip or (load_ok and load > c.load_share_shared)  # type: ignore[operator]
        rising = evidence and self._prev_evidence is False
        self._prev_evidence = evidence
        source = "gripper" if grip else "load_share"
        if rising and self._phase in (Phase.IDLE, Phase.DONE, Phase.REACH):
            if self._phase is not Phase.REACH:
                self._start(Phase.REACH, t, t, source)
            self._start(Phase.TRANSFER, t, t, source)
            return True
        if self._phase is Phase.TRANSFER and load_ok and load > c.load_share_robot:  # type: ignore[operator]
            self._start(Phase.RETREAT, t, t, "load_share")
            return True
        return False

    def _analyse(self, now: float, predict_only: bool = False) -> None:
        """Run the method on the samples kept (``predict_only``: only refresh the end-of-phase
        prediction from the signals)."""
        c = self.config
        self.stats.analyses += 1
        n = len(self._samples)
        if n < 3:
            return
        rows = self._samples.rows()
        t = rows[:, 0]
        i0 = 0
        if self._phase is not Phase.IDLE and math.isfinite(self._phase_start):
            # After contact the rules need the hold and what follows, a reach (or, once done,
            # the next reach) its rest before and what follows, not the whole window (the cost
            # grows with the samples; after a handover, re-analysing it is wasted).
            look = c.reach_lookback if self._phase in (Phase.REACH, Phase.DONE) else 1.0
            back = REACH_S * look
            i0 = int(t.searchsorted(self._phase_start - back))
            if n - i0 < 3:
                i0 = 0
        window = rows[i0:]  # (read-only: a method writing into it would change the samples kept)
        # (the rows are float64 of known shapes: no conversion or check needed; read-only
        # views, not copies: only this analysis reads them)
        traj = Trajectory.of_hands(
            window[:, 0], window[:, 1:4], window[:, 4:], self._unknown_block(window.shape[0])
        )
        s = self.segmenter.online_signals(traj, cache=self._signal_cache)
        self._signals = s
        if s is not None and self._phase is Phase.REACH:
            # Keep the reach's start distance while the window holds it (a reach can outlast
            # the window; the taken-back checks compare with it).
            self._reach_start_distance(s, self._finite_distances(s))
            restart = self._reach_restart()
            if restart is not None:
                # The reach was an earlier movement (the giver lifted the object, waited, and
                # only now approaches): it ends, and the approach is the reach.
                self._done(restart, now, "stalled")
                self._start(Phase.REACH, restart, now, "motion")
        if s is not None and not predict_only:
            if not self.segmenter.rules_after_contact:
                self._advance(self.segmenter.online_segments(traj, s, now, self._phase), now)
            elif not self._rules_after_contact(s, now):
                # Once the hands are in contact the method's own end rules run from the
                # phase's start; before, the whole method finds the next handover.
                segs = self.segmenter.online_segments(traj, s, now, self._phase)
                self._advance(segs, now, True)
                self._rules_after_contact(s, now)
        self._expected_end = predict_end(self._phase, self._phase_start, self._signals, now, c)

    def _unknown_block(self, n: int) -> np.ndarray:
        """An all-NaN ``(n, 5)`` block (read-only) for an analysis window's face, gripper and
        load share (unknown online): one kept and grown, not one allocated per analysis."""
        block = self._unknown
        if block.shape[0] < n:
            block = np.full((max(2 * n, 256), 5), np.nan)
            block.flags.writeable = False
            self._unknown = block
        return block[:n]

    def _rules_after_contact(self, s: Signals, now: float) -> bool:
        """In a transfer or retreat, apply the method's
        :meth:`~gazebot.core.phases.methods.base.Segmenter.phase_end` rule from the current
        phase's start. True if the phase is one of these two."""
        c = self.config
        for _ in range(2):
            if self._phase not in (Phase.TRANSFER, Phase.RETREAT):
                return False
            end = self.segmenter.phase_end(s, self._phase, self._phase_start, self._joined_late)
            if end is None:
                if self._phase is Phase.RETREAT and now - self._phase_start > c.max_retreat:
                    self._done(now, now, "timeout")
                return True
            t_end, source = end
            if self._phase is Phase.TRANSFER:
                self._start(Phase.RETREAT, t_end, now, source)
                continue
            self._done(t_end, now, source)
            return True
        return True

    def _find(self, segs: list[Segment], phase: Phase, after: float) -> Segment | None:
        for seg in segs:
            if seg.phase is phase and seg.start >= after - self.config.online_slack:
                return seg
        return None

    def _advance(self, segs: list[Segment], now: float, stop_at_contact: bool = False) -> None:
        """Emit the phase starts ``segs`` show after the current phase (at most one handover);
        ``stop_at_contact``: stop once in a transfer (the caller's rules take over)."""
        c = self.config
        for _ in range(4):  # at most one full handover per analysis
            ph = self._phase
            if ph in (Phase.IDLE, Phase.DONE):
                reach = self._find(segs, Phase.REACH, self._floor)
                if reach is not None:
                    self._start(Phase.REACH, reach.start, now, "motion")
                    continue
                if not self._robot_reports:
                    tr = self._find(segs, Phase.TRANSFER, self._floor)
                    if tr is not None:
                        self._start(Phase.REACH, tr.start, now, "motion")
                        continue
                return
            if ph is Phase.REACH:
                tr = None if self._robot_reports else self._find(segs, Phase.TRANSFER, self._floor)
                if tr is not None:
                    self._start(Phase.TRANSFER, tr.start, now, "motion")
                    continue
                if self._taken_back():
                    # The hands are farther apart than when the reach began: whatever moved
                    # was not the approach (the receiver stepped back); the next one is.
                    self._done(now, now, "aborted")
                    return
                alive = any(
                    sg.phase in (Phase.REACH, Phase.TRANSFER)
                    and sg.end >= self._floor - c.online_slack
                    for sg in segs
                )
                if alive:
                    self._reach_missing_since = math.nan
                elif math.isnan(self._reach_missing_since):
                    self._reach_missing_since = now
                elif (
                    now - self._reach_missing_since > c.online_period + c.max_refine
                    and self._hands_back_apart()
                ):
                    self._done(now, now, "aborted")
                return
            if ph is Phase.TRANSFER:
                if stop_at_contact:
                    return
                ret = self._find(segs, Phase.RETREAT, self._floor)
                if ret is not None:
                    self._start(Phase.RETREAT, ret.start, now, "motion")
                    continue
                return
            # Retreat: done when its end is seen, or a next reach began.
            ret = self._find(segs, Phase.RETREAT, self._floor)
            nxt = self._find(segs, Phase.REACH, self._floor + c.online_slack * 2)
            if ret is not None and not ret.open:
                self._done(ret.end, now, "motion")
                continue
            if nxt is not None:
                self._done(nxt.start, now, "next_reach")
                continue
            if now - self._phase_start > c.max_retreat:
                self._done(now, now, "timeout")
            return

    def _reach_restart(self) -> float | None:
        """When the final approach began, if the reach under way was an earlier movement (it
        stalled, :meth:`_approach_after_stall`, or was taken back part of the way,
        :meth:`_approach_after_takeback`; with both, the later approach), else ``None``."""
        s = self._signals
        if s is None or s.t.shape[0] < 3:
            return None
        i_start = int(s.t.searchsorted(self._phase_start))
        found = [self._approach_after_stall(s, i_start), self._approach_after_takeback(s, i_start)]
        return max((t for t in found if t is not None), default=None)

    def _approach_after_stall(self, s: Signals, i_start: int) -> float | None:
        """The end of the reach's last stall, if the hands, less than ``stall_fraction`` of
        their distance nearer than where the reach started (grid index ``i_start``), stalled
        for ``reach_stall`` (the giver's hand rested under ``rest_speed``, or, holding a heavy
        object that sways, moved slower than ``reach_onset_speed`` while the hands closed
        slower than that: no progress of this reach), then moved again
        (``reach_onset_speed``) and the hands have closed ``reach_confirm_distance`` since.
        ``None`` otherwise (a giver holding the object out for a slow robot stalls too, but
        has closed more, and does not set off again)."""
        c = self.config
        v = s.giver_speed[i_start:]
        need = int(round(c.reach_stall / max(s.dt, 1e-9)))
        if need < 1 or v.shape[0] <= need:
            return None  # (a reach younger than reach_stall: no rest that long in it)
        with np.errstate(invalid="ignore"):
            # Swaying with a heavy object: the hand slower than a reach and the hands closing
            # slower than a reach does (a receiver approaching meanwhile is progress).
            no_progress = (v < c.reach_onset_speed) & (s.closing[i_start:] < c.reach_onset_speed)
        rest = np.isfinite(v) & ((v < c.rest_speed) | no_progress)
        if np.count_nonzero(rest) < need:
            return None  # (no run of need rest samples without need of them in all)
        # the last sample of the last rest at least reach_stall long
        edges = np.diff(np.concatenate([[0], rest.astype(int), [0]])).nonzero()[0]
        bounds = edges.tolist()  # (plain ints: iterating the array would box each element)
        runs = [(a, b - 1) for a, b in zip(bounds[::2], bounds[1::2], strict=True)]
        runs = [(a, b) for a, b in runs if b - a + 1 >= need and b < rest.size - 1]
        if not runs:
            return None
        a, b = runs[-1]
        i_a, i_b = i_start + a, i_start + b
        if not np.isfinite(s.giver[[i_start, i_a]]).all():
            return None
        d0 = float(s.distance[i_start])
        if not d0 - float(s.distance[i_a]) < c.stall_fraction * d0:
            return None  # the hand was held out at the handover place: the reach goes on
        after = s.giver_speed[i_b + 1 :]
        d = s.distance[i_b:]
        if not nanmax(after, initial=0.0) >= c.reach_onset_speed:
            return None
        if not float(d[0]) - float(nanmin(d)) >= c.reach_confirm_distance:
            return None
        return float(s.t[i_b])

    def _approach_after_takeback(self, s: Signals, i_start: int) -> float | None:
        """Where the hands were last farthest apart, if since the reach started (grid index
        ``i_start``) they had closed ``reach_confirm_distance`` and come that much apart
        again (the giver took the object back part of the way, or the receiver stepped back)
        and the reach then made no progress for ``reach_stall`` (the hands no nearer than
        their closest before), with the pair not walking on together (their common motion
        under ``turning_common_max``: a walking pair's distance rises and falls with the
        gait), and the hands, still less than ``stall_fraction`` of their distance nearer
        than where the reach started, have closed ``reach_confirm_distance`` from there with
        the giver's hand moving at a reach's speed (``reach_onset_speed``): that approach is
        the reach. ``None`` otherwise (a reach taken back past its start aborts instead).
        When the robot reports its gripper or load, the receiver's hand is the robot's own:
        only a take-back the giver's hand made at least half of counts (the robot backing off
        while the giver comes on is no new reach of the giver's)."""
        c = self.config
        ok = i_start + np.isfinite(s.distance[i_start:]).nonzero()[0]
        if ok.size < 3:
            return None
        d = s.distance[ok]
        # a dip: nearer than both the farthest before it and the farthest after it
        farthest_on = np.maximum.accumulate(d[::-1])[::-1]
        dip = np.minimum(np.maximum.accumulate(d), farthest_on) - d
        nearer = (dip >= c.reach_confirm_distance).nonzero()[0]
        if nearer.size == 0:
            return None
        k = int(nearer[-1])
        j = k + int(np.argmax(d[k:]))  # where the hands were last farthest apart
        b = int(np.argmin(d[:j]))  # the reach's closest before
        if not float(d[j]) - float(d[-1]) >= c.reach_confirm_distance:
            return None
        if not d[0] - d[j] < c.stall_fraction * d[0]:
            return None  # the hands had come to the handover place: the reach goes on
        i, k = ok[b], ok[j]
        if self._robot_reports and not _giver_made_half(
            s.giver[i], float(s.distance[i]), s.giver[k], s.receiver[k]
        ):
            return None  # the robot's hand backed off: the giver's reach goes on
        back = (d[j:] <= d[b]).nonzero()[0]  # nearer than that closest again
        i_end = ok[j + int(back[0])] if back.size else ok[-1]
        if not s.t[i_end] - s.t[ok[b]] >= c.reach_stall:
            return None
        common = s.common_speed[ok[b] : ok[j] + 1]
        common = common[np.isfinite(common)]  # (unknown next to tracking gaps)
        if not (common.size and float(np.median(common)) < c.turning_common_max):
            return None  # walking on together, or not known not to be
        if not nanmax(s.giver_speed[ok[j] :], initial=0.0) >= c.reach_onset_speed:
            return None
        return float(s.t[ok[j]])

    def _finite_distances(self, s: Signals) -> np.ndarray:
        """Grid indices of the finite distances of ``s`` (found once per analysis's signals:
        the reach's checks read them several times)."""
        if self._finite_of is not s:
            self._finite_of, self._finite = s, np.isfinite(s.distance).nonzero()[0]
        return self._finite

    def _reach_start_distance(self, s: Signals, ok: np.ndarray) -> float:
        """The hands' distance when the current reach began (``ok``: the finite samples of
        ``s.distance``): read from ``s`` while its window still holds that moment (and kept),
        else the value kept from the last window that held it; NaN if none did."""
        if s.t.shape[0] and s.t[0] <= self._phase_start:
            i0 = int(s.t.searchsorted(self._phase_start))
            k = int(ok.searchsorted(i0, side="right"))  # (ok increases: those <= i0)
            self._reach_d0 = float(s.distance[ok[k - 1]]) if k else math.nan
            self._reach_g0 = s.giver[ok[k - 1]].copy() if k else np.full(3, np.nan)
        return self._reach_d0

    def _taken_back(self) -> bool:
        """The hands are ``reach_confirm_distance`` farther apart than when the current reach
        started (known only if this detector saw that start), and, when the robot reports its
        gripper or load (the receiver's hand is its own), the giver's hand made at least half
        of that."""
        s = self._signals
        if s is None or self._joined_late:
            return False
        ok = self._finite_distances(s)
        d0 = self._reach_start_distance(s, ok)
        if not ok.size or math.isnan(d0):
            return False
        if not float(s.distance[ok[-1]]) >= d0 + self.config.reach_confirm_distance:
            return False
        # (the robot's own hand backing off is no taking back of the giver's reach)
        return not self._robot_reports or _giver_made_half(
            self._reach_g0, d0, s.giver[ok[-1]], s.receiver[ok[-1]]
        )

    def _hands_back_apart(self) -> bool:
        """The hands are (almost) as far apart as when the current reach started: the reach
        was taken back, not merely paused (a reach that pauses is still a reach)."""
        s = self._signals
        if s is None or s.t.shape[0] == 0:
            return True
        d = s.distance
        ok = self._finite_distances(s)
        if ok.size == 0:
            return True
        if self._joined_late and not (ok.size and s.t[ok[0]] < self._phase_start):
            # The reach began before the first sample seen (a resync): its start distance is
            # unknown, so taken back means the hands left the region around the closest seen.
            near = float(np.min(d[ok]))
            return float(d[ok[-1]]) >= near + self.config.transfer_distance_margin
        d0 = self._reach_start_distance(s, ok)
        if math.isnan(d0):  # the start was never seen with a finite distance: the first one seen
            d0 = float(d[ok[0]])
        return float(d[ok[-1]]) >= d0 - self.config.reach_confirm_distance

    def _done(self, t0: float, now: float, source: str) -> None:
        t0 = max(min(t0, now), self._phase_start)
        info = {"handover": self._handover(Phase.DONE), "source": source}
        self._emit(Event(EventKind.HANDOVER_DONE, t0, now, info))


def _nowhere(event: Event) -> None:
    """The report of a detector not yet updated (never called: updates pass their own)."""


class OnlineDetector:
    """A :class:`PhaseDetector` with a handover state of its own: the phase stream the tracking
    alone shows (replays, tools, tests; the engine's detector follows the engine's state).

    Attributes:
        detector: The evidence source.
        state: The handover state its events move.
    """

    def __init__(self, config: PhaseConfig | None = None) -> None:
        self.detector = PhaseDetector(config)
        self.state = HandoverState()
        self._queue: deque[Event] = deque()

    @property
    def config(self) -> PhaseConfig:
        """The detector's settings."""
        return self.detector.config

    @property
    def stats(self) -> DetectorStats:
        """The detector's sample counts."""
        return self.detector.stats

    @property
    def tracking(self) -> bool:
        """False between ``tracking_lost`` and ``tracking_restored``."""
        return self.detector.tracking

    @property
    def phase(self) -> Phase:
        """The state's phase."""
        return self.state.phase

    @property
    def phase_start(self) -> float:
        """The state's phase start (s; NaN in idle)."""
        return self.state.phase_start if self.state.phase is not Phase.IDLE else math.nan

    @property
    def handover(self) -> int:
        """Index of the current (or last) handover, -1 before the first."""
        return self.state.handover

    @property
    def expected_phase_end(self) -> float:
        """The tracking's estimate of the phase's end (s; NaN when unknown)."""
        return self.detector.expected_end(self.state)

    @property
    def pending(self) -> int:
        """Number of events the next :meth:`update` calls will return."""
        return len(self._queue)

    def update_all(self, frame: TrackingFrame) -> list[Event]:
        """Feed one frame; every event the detector reported (queued ones first)."""
        self.detector.update(frame, self.state, self._take)
        out = list(self._queue)
        self._queue.clear()
        return out

    def update(self, frame: TrackingFrame) -> Event | None:
        """Feed one frame; the oldest event not yet returned, else ``None``."""
        self.detector.update(frame, self.state, self._take)
        return self._queue.popleft() if self._queue else None

    def resync(self, event: Event) -> None:
        """Replay an event published before a restart into the state (no event is returned;
        events not yet returned are dropped)."""
        self.state.apply(event)
        self.detector.resync()
        self._queue.clear()

    def _take(self, event: Event) -> None:
        self.state.apply(event)
        self._queue.append(event)


@dataclass
class OnlineResult:
    """What :func:`run_online` saw: every event, the resulting segments and the sample counts."""

    events: list[Event]
    segments: list[Segment]
    stats: DetectorStats


def _giver_made_half(g0: np.ndarray, d0: float, g1: np.ndarray, r1: np.ndarray) -> bool:
    """Whether the giver's hand, moving from ``g0`` (the hands ``d0`` apart) to ``g1`` (the
    receiver's hand at ``r1``), made at least half of the hands' moving apart: its own motion
    along the line from the receiver's hand. False if a position is unknown."""
    away = g1 - r1
    d1 = float(np.linalg.norm(away))
    own = float((g1 - g0) @ away) / d1 if d1 > 0 else math.nan
    return own >= 0.5 * (d1 - d0)


def run_online(trajectory: Trajectory, config: PhaseConfig | None = None) -> OnlineResult:
    """Replay a recording through a fresh :class:`OnlineDetector`, sample by sample, in the
    stored order (out-of-order samples are ignored as they would be live)."""
    det = OnlineDetector(config)
    events: list[Event] = []
    for frame in trajectory.iter_frames():
        events.extend(det.update_all(frame))
    t_end = float(np.nanmax(trajectory.t)) if len(trajectory) else math.nan
    return OnlineResult(events, segments_from_events(events, t_end), det.stats)


def make_detector(config: PhaseConfig | None = None) -> PhaseDetector:
    """The online detector of ``config.method`` (the engine's entry point)."""
    return PhaseDetector(config)
