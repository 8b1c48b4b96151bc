"""Online (causal) phase detection, one tracking frame at a time, at constant cost per sample.

Each hand goes through a critically damped alpha-beta filter (plain floats, the actual time
step, so 8-240 Hz and jittered sampling need no tuning); its velocity lags accelerations by
``L = 1 / (pi * filter_bandwidth)`` (64 ms by default), which the back-dating below undoes.

Online the minimum hand distance of a handover is unknown until it is over, so the seed's rule
(section 7.2.5: within 20 cm of the minimum distance, relative speed < 15 cm/s) is applied to the
*running* minimum of the current reach, and phase boundaries are back-dated with the
minimum-jerk profile of human motions.

**Noise floor.** While the giver's hand rests (idle, or 0.5 s after a handover ended, no reach
candidate open) the detector measures the RMS of its filtered speed (running mean over
``noise_tau``, samples above 4 RMS left out). 2-5 mm of tracking noise shows as 0.05-0.3 m/s of
filtered speed at 8-240 Hz, so every motion threshold below is at least ``noise_speed_factor``
x that RMS, and every distance threshold at least ``noise_distance_factor`` x the matching
position noise (about ``1.25 L / sqrt(3)`` x the RMS speed, from the filter's gains). The
thresholds use the measurement of one refresh (0.25 s) earlier, so the slow first samples of a
reach do not raise the bar that reach has to pass. Motion starts no reach until the noise is
known (~0.2 s and 4 samples after a start).

- **reach**: the giver's hand is faster than ``reach_onset_speed`` while the hands close (their
  closing speed >= ``approach_ratio`` x the hand speed: the receiver, often a robot gripper, may
  approach too); confirmed once the hands closed by ``reach_confirm_distance``. Or *early*, at
  ``early_fraction`` of both (above the noise floor) when the start looks like a minimum-jerk
  start: the filtered speed still rising (>= 95 % of its maximum since the candidate opened,
  seen on two samples above 20 Hz), at least half of the closing done by the giver's own hand
  (a robot moving past a resting giver closes the distance too), and the hand's speed *now*,
  ``3 x / a`` (x: displacement since rest, a: its age from the filtered speed), above
  ``early_speed_margin`` x ``reach_onset_speed``: a 1-2 cm fidget peaks near 0.12 m/s, a reach
  keeps accelerating. While the receiver moves, a confirmation needs two samples unless the
  giver's hand is clearly faster than the noise. No reach either before the hand came to rest
  after a predicted landing (below). Back-dated from the displacement x and speed v since rest:
  a minimum-jerk start covers ``x ~ a^3`` at ``v ~ 3 a^2`` (a: time since onset), corrected for
  the filter lag (``_motion_age``).
- **transfer**: the seed's rule on the running minimum (and hands closer than
  ``contact_distance_max``) opens a candidate; it becomes the transfer once the relative speed
  settles below ``settle_speed`` and ``min_transfer`` has passed (or after ``settle_timeout``
  without settling, provided the hands stopped closing: a giver waiting for a slow receiver is
  not a transfer). The candidate dies when the speed exceeds ``transfer_exit_speed``
  (hysteresis). The event is back-dated to the estimated stop of the approach: the two
  threshold crossings of the parabolic speed tail, extrapolated by ``stop_extrapolation``.
  Robot evidence (seed section 4.3) replaces it: a rising edge of "gripper closed" or of a
  load share above ``load_share_shared`` starts the transfer at once (and reports the reach if
  it was missed). Once the frames carry that evidence, hand motion alone no longer starts a
  transfer: hands resting close together while the robot has not grasped are a giver waiting.
- **retreat**: the hands' relative position leaves the held pose by ``release_distance`` at a
  relative speed above ``release_speed`` (both raised to the noise floor); or early, at
  ``early_fraction`` of both, when the relative velocity points along the separation (moving
  away from the held pose, not jitter about it), on two successive samples above 20 Hz.
  Back-dated like a reach onset; a release seen late (> 0.25 s back-dated, sparse samples)
  lets rest alone end the retreat, as the hand may be most of the way back. A load share above
  ``load_share_robot`` (the robot alone holds the object: the giver released) starts it at once.
- **done**: a *predicted landing*: after moving ``min_approach``, past its speed peak, the
  giver's hand has slowed below ``done_fraction`` of the peak (and below half of it). The
  bell-shaped (minimum-jerk) profile is then within a few percent of its end, and the filter's
  lag L makes this visible about when the motion ends; dated at the mirrored peak
  ``onset + 2 (t_peak - L - onset)`` (or now, if earlier), ``source = "landing"``. Under heavy
  noise the tail hides below the noise floor: then below the floor *and* past the mirrored end.
  Fallbacks: the hand at rest (smoothed velocity below ``rest_speed`` or the noise for
  ``rest_hold``; dated at the earlier of the settling and the mirrored peak),
  ``retreat_far_distance`` from the transfer point, or ``max_retreat`` passed. A new reach
  during the retreat ends the handover and starts the next one; a reach taken back before any
  transfer ends it as ``handover_done`` with ``source = "aborted"``.

``expected_phase_end``: in a reach and a retreat the hands follow roughly symmetric bell-shaped
(minimum-jerk) speed profiles, so once a speed peak has passed, that motion's end is predicted at
``onset + 2 (t_peak - L - onset)``; before the peak, onset + the typical duration
(``reach_duration``/``retreat_duration``). A reach ends at contact, so its prediction is the later
of the giver's and the receiver's (gripper's) predicted arrivals; a retreat uses the giver's
hand. During transfer: ``start + transfer_duration``. Never earlier than the current time; NaN in
``idle``/``done``. Halfway through a reach it predicts contact within 0.17 s (median) on the
synthetic set.

Events carry ``t`` (estimated phase time), ``detected_at`` (the frame time that revealed it) and
``info = {"handover": k, "source": "motion" | "gripper" | "load_share" | "landing" | "rest" |
...}``. One
:meth:`PhaseDetector.update` call returns at most one event; when a sample produces several
(e.g. ``handover_done`` then ``reach_started``, or a gripper closing that reveals a whole reach),
the rest are queued and returned by the next calls, oldest first (``pending`` tells how many
wait; :meth:`PhaseDetector.update_all` returns all at once).

Latency on the varied synthetic set (``synthetic_set(40, seed=11)``, 8-240 Hz, 0.5-3 mm noise,
dropouts; detected_at - truth, median / p90, share within 250 ms): reach 192 / 312 ms, 83 %;
transfer 3 / 153 ms, 98 %; release 224 / 315 ms, 69 %; done -14 / 43 ms, 100 %. The limits are
physical: a slow reach or retreat moves only 5-8 mm in its first 150-200 ms (a zero-lag,
noise-free 8 mm detector would need 146 / 175 ms for the reach and 199 / 287 ms for the
release), and an early reach cannot be told from a brisk fidget any sooner.

Bad samples: a frame with a non-finite time, or a time not after the last accepted one
(duplicate or out of order), is ignored and counted (``stats``). A missing point (NaN) is held at
its last estimate for up to ``max_gap_hold``; after that ``tracking_lost`` fires (``t`` = last
valid sample, ``info["missing"]`` names the points) and phase detection pauses until both hands
are seen again (``tracking_restored``; the filters restart there).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from gazebot.phases.config import PhaseConfig
from gazebot.phases.segment import Segment, segments_from_events
from gazebot.phases.trajectory import Trajectory
from gazebot.types import Event, EventKind, Phase, TrackingFrame

_PHASE_OF_EVENT = {
    EventKind.REACH_STARTED: Phase.REACH,
    EventKind.TRANSFER_STARTED: Phase.TRANSFER,
    EventKind.RETREAT_STARTED: Phase.RETREAT,
    EventKind.HANDOVER_DONE: Phase.DONE,
}


# Weight of the noise measurement (1 - exp(-T / noise_tau)) and samples it needs before motion
# may start a reach: the first ~0.2 s (and 4 samples) only learn the resting hand's noise.
_WARMUP = 0.18
_WARMUP_SAMPLES = 4
# Filtered position noise per axis / filtered 3D RMS speed noise, in units of the filter lag L
# (1.25 L per axis, over sqrt(3) axes).
_POS_PER_SPEED = 1.25 / math.sqrt(3.0)
# The noise thresholds are refreshed this often (s), from the measurement one refresh earlier.
_SNAPSHOT = 0.25


def _floats3(p: object) -> list[float]:
    """A point as three Python floats (NaNs if it is not a numeric 3-vector)."""
    if type(p) is np.ndarray and p.dtype == np.float64 and p.shape == (3,):
        return p.tolist()  # the usual case: no per-element checks needed
    try:
        v = [float(x) for x in np.asarray(p, dtype=float).reshape(-1)]
    except (TypeError, ValueError):
        return [math.nan, math.nan, math.nan]
    return v if len(v) == 3 else [math.nan, math.nan, math.nan]


class _Track:
    """Critically damped alpha-beta filter of one 3D point, in plain floats.

    Gains come from the discounted-least-squares (fading memory) form, ``theta = exp(-w dt)``,
    ``alpha = 1 - theta^2``, ``beta = (1 - theta)^2``: stable for any time step, so irregular
    sampling from 8 to 240 Hz needs no tuning.
    """

    __slots__ = (
        "omega",
        "hold",
        "x",
        "y",
        "z",
        "vx",
        "vy",
        "vz",
        "t_upd",
        "t_valid",
        "ready",
        "_dt",
        "_a",
        "_b",
    )

    def __init__(self, omega: float, hold: float) -> None:
        self.omega = omega
        self.hold = hold
        self.x = self.y = self.z = 0.0
        self.vx = self.vy = self.vz = 0.0
        self.t_upd = -math.inf
        self.t_valid = math.nan  # last valid sample (NaN: never seen)
        self.ready = False
        self._dt = self._a = self._b = math.nan  # gains of the last time step (reused)

    def update(self, t: float, p: list[float]) -> bool:
        x, y, z = p
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            return False
        dt = t - self.t_upd
        if not self.ready or dt > self.hold:
            # First sample or after a long gap: restart, the old velocity means nothing now.
            self.x, self.y, self.z = x, y, z
            self.vx = self.vy = self.vz = 0.0
            self.ready = True
        else:
            if dt == self._dt:  # regular sampling: same gains as last time
                a, b = self._a, self._b
            else:
                th = math.exp(-self.omega * dt)
                a = 1.0 - th * th
                b = (1.0 - th) * (1.0 - th) / dt
                self._dt, self._a, self._b = dt, a, b
            rx = x - (self.x + self.vx * dt)
            ry = y - (self.y + self.vy * dt)
            rz = z - (self.z + self.vz * dt)
            self.x += self.vx * dt + a * rx
            self.y += self.vy * dt + a * ry
            self.z += self.vz * dt + a * rz
            self.vx += b * rx
            self.vy += b * ry
            self.vz += b * rz
        self.t_upd = t
        self.t_valid = t
        return True


@dataclass
class DetectorStats:
    """Counts of samples the detector ignored or bridged."""

    samples: int = 0
    out_of_order: int = 0
    duplicates: int = 0
    bad_time: int = 0
    held: int = 0


class PhaseDetector:
    """Causal handover phase detector (see the module docstring for the criteria).

    Attributes:
        config: The thresholds.
        phase: Current phase (``idle`` -> ``reach`` -> ``transfer`` -> ``retreat`` -> ``done``,
            then ``reach`` again for a following handover).
        phase_start: Estimated start of the current phase (s; NaN in ``idle``).
        expected_phase_end: Predicted end of the current phase (s; NaN when unknown).
        handover: Index of the current (or last) handover, -1 before the first.
        tracking: False between ``tracking_lost`` and ``tracking_restored``.
        stats: Counts of ignored and bridged samples.
    """

    def __init__(self, config: PhaseConfig | None = None) -> None:
        self.config = config if config is not None else PhaseConfig()
        c = self.config
        omega = 2.0 * math.pi * c.filter_bandwidth
        self._g = _Track(omega, c.max_gap_hold)
        self._r = _Track(omega, c.max_gap_hold)
        self.phase = Phase.IDLE
        self.phase_start = math.nan
        self.expected_phase_end = math.nan
        self.handover = -1
        self.tracking = True
        self.stats = DetectorStats()
        self._queue: deque[Event] = deque()
        self._last_t = -math.inf
        self._t0 = math.nan  # first accepted time
        self._prev_evidence = False
        # Set once a frame carries the robot's gripper state or load share: from then on the
        # robot's own sensing, not hand motion, says when both hold the object.
        self._robot_reports = False
        self._source = "motion"
        self._lag = 1.0 / (math.pi * c.filter_bandwidth)  # velocity lag behind an acceleration
        self._tail_ratio = math.sqrt(c.transfer_speed_max / c.settle_speed) - 1.0
        self._rest_tau = 0.1  # s, smoothing of the velocity that decides "at rest"
        self._prev_rs = self._prev_t = math.nan
        # Receiver hand's own motion: rest anchor, onset, speed peak (for the reach's end).
        self._r_rx = self._r_ry = self._r_rz = math.nan
        self._r_on = self._r_tpeak = math.nan
        self._r_vpeak = self._r_speed = 0.0
        self._reset_phase_state()
        # Rest anchor of the giver's hand (where the last slow sample was).
        self._rest_t = -math.inf
        self._rest_x = self._rest_y = self._rest_z = math.nan
        self._rest_d = math.nan
        # Live noise floor of the resting giver's hand: a bias-corrected running mean of the
        # squared filtered speed (``_nv2 / _nw``) over ``_n_noise`` samples.
        self._nv2 = self._nw = 0.0
        self._n_noise = 0
        self._noise_dt = self._noise_k = math.nan
        self._snap_t = -math.inf
        self._rms_pending = math.nan
        self._pending_ok = False
        self._noise_ready = False  # the thresholds rest on a warm noise measurement
        self._done_at = -math.inf  # when the last handover_done was detected
        self._v_early = c.early_fraction * c.reach_onset_speed
        self._d_early = c.early_fraction * c.reach_confirm_distance
        self._rest_gate = c.rest_speed
        self._v_noise = self._d_noise = 0.0
        self._toward = 0.0
        self._came_to_rest = True

    # ----------------------------------------------------------------- public API
    @property
    def pending(self) -> int:
        """Number of queued events the next calls will return."""
        return len(self._queue)

    def update(self, frame: TrackingFrame) -> Event | None:
        """Feed one frame; return the oldest new (or queued) event, else ``None``."""
        self._step(frame)
        return self._queue.popleft() if self._queue else None

    def update_all(self, frame: TrackingFrame) -> list[Event]:
        """Feed one frame; return every new and queued event, oldest first."""
        self._step(frame)
        out = list(self._queue)
        self._queue.clear()
        return out

    def resync(self, event: Event) -> None:
        """Adopt a phase known from elsewhere (e.g. published before an engine restart).

        Phase events set the phase and its start to ``event.t``; ``robot_grasped`` counts as a
        transfer start when the detector is idle, done or in a reach. Tracking and other robot
        events are ignored. No event is emitted, and events still queued are dropped (they
        predate the adopted phase). A new handover is counted when a reach (or a transfer
        without a reach) follows ``idle``, ``done`` or ``retreat``, so replaying
        ``reach_started``, ``robot_grasped``, ``transfer_started`` counts one handover.
        Detection continues from the adopted phase; its reference distances are taken from the
        next valid sample.
        """
        kind = event.kind
        if kind is EventKind.ROBOT_GRASPED:
            if self.phase not in (Phase.IDLE, Phase.REACH, Phase.DONE):
                return
            phase = Phase.TRANSFER
        else:
            phase = _PHASE_OF_EVENT.get(kind)
            if phase is None:
                return
        between = self.phase in (Phase.IDLE, Phase.DONE, Phase.RETREAT)
        if between and phase in (Phase.REACH, Phase.TRANSFER):
            self.handover += 1
        self._enter(phase, event.t)
        self._moved_unknown = phase is Phase.RETREAT
        self._queue.clear()

    # ----------------------------------------------------------------- internals
    def _reset_phase_state(self) -> None:
        self._cand_t0 = math.nan  # candidate start (back-dated) of the next phase
        self._cand_seen = math.nan  # when the candidate was first seen
        self._cand_d0 = math.nan  # distance at rest (reach) / at the candidate (transfer)
        self._ref_d = math.nan  # reach: distance at start; transfer: transfer distance
        self._d_min = math.inf
        self._n_ref = 0
        # Transfer: held relative pose (giver -> receiver); retreat: giver hand at the release.
        self._anc_x = self._anc_y = self._anc_z = math.nan
        self._settled = False
        # A retreat adopted by resync started before this detector saw the hand: how far it
        # moved since the release is unknown, so rest alone ends it.
        self._moved_unknown = False
        self._v_peak = 0.0
        self._t_peak = math.nan
        self._slow_since = math.nan
        self._speed_avg = 0.0
        self._avx = self._avy = self._avz = 0.0
        self._speed_t = math.nan
        self._cand_vmax = 0.0
        self._early_seen = False

    def _enter(self, phase: Phase, t0: float) -> None:
        self.phase = phase
        self.phase_start = t0
        self._reset_phase_state()
        c = self.config
        if phase is Phase.REACH:
            self.expected_phase_end = t0 + c.reach_duration
        elif phase is Phase.TRANSFER:
            self.expected_phase_end = t0 + c.transfer_duration
        elif phase is Phase.RETREAT:
            self.expected_phase_end = t0 + c.retreat_duration
        else:
            self.expected_phase_end = math.nan

    def _emit(self, kind: EventKind, t0: float, now: float, source: str) -> None:
        info = {"handover": max(self.handover, 0), "source": source}
        self._queue.append(Event(kind, t0, now, info))

    def _start(self, phase: Phase, kind: EventKind, t0: float, now: float, source: str) -> None:
        t0 = min(t0, now)
        if math.isfinite(self.phase_start):
            t0 = max(t0, self.phase_start)  # phases never go back in time
        if kind is EventKind.REACH_STARTED:
            self.handover += 1
        self._emit(kind, t0, now, source)
        self._enter(phase, t0)

    def _step(self, frame: TrackingFrame) -> None:
        st = self.stats
        try:
            t = float(frame.t)
        except (TypeError, ValueError):
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
        if self._t0 != self._t0:
            self._t0 = t
        g, r = self._g, self._r
        g_ok = g.update(t, _floats3(frame.giver_hand))
        r_ok = r.update(t, _floats3(frame.receiver_hand))
        c = self.config

        # Tracking: bridge short gaps, report long ones once.
        if not (g_ok and r_ok):
            st.held += 1
            if self.tracking:
                g_last = g.t_valid if g.ready else self._t0
                r_last = r.t_valid if r.ready else self._t0
                last = min(g_last, r_last)
                if t - last > c.max_gap_hold:
                    self.tracking = False
                    pairs = (("giver_hand", g_ok), ("receiver_hand", r_ok))
                    missing = [n for n, ok in pairs if not ok]
                    info = {"handover": max(self.handover, 0), "missing": missing}
                    self._queue.append(Event(EventKind.TRACKING_LOST, last, t, info))
                    self._cand_t0 = math.nan
            if not self.tracking:
                return
        elif not self.tracking:
            self.tracking = True
            self._queue.append(
                Event(EventKind.TRACKING_RESTORED, t, t, {"handover": max(self.handover, 0)})
            )
            self._cand_t0 = math.nan
            self._slow_since = math.nan
        if not (g.ready and r.ready):
            return

        # Per-sample kinematics, plain floats (no numpy: a few microseconds per sample).
        qx, qy, qz = r.x - g.x, r.y - g.y, r.z - g.z  # giver -> receiver
        d = math.sqrt(qx * qx + qy * qy + qz * qz)
        wx, wy, wz = g.vx - r.vx, g.vy - r.vy, g.vz - r.vz
        rel_speed = math.sqrt(wx * wx + wy * wy + wz * wz)
        g_speed = math.sqrt(g.vx * g.vx + g.vy * g.vy + g.vz * g.vz)
        self._track_receiver(t, math.sqrt(r.vx * r.vx + r.vy * r.vy + r.vz * r.vz))
        # Closing speed of the hands (> 0: distance shrinking). The receiver (often a robot
        # gripper) may approach too; what counts is that the hands come together.
        toward = (wx * qx + wy * qy + wz * qz) / d if d > 1e-9 else 0.0
        # The giver's own hand heading for the receiver (a robot moving home near a resting
        # giver closes the distance too).
        self._toward = (g.vx * qx + g.vy * qy + g.vz * qz) / d if d > 1e-9 else 0.0
        # A reach needs a speed above the noise too (the early threshold is noise-aware).
        v_reach = c.reach_onset_speed if c.reach_onset_speed >= self._v_early else self._v_early
        reaching = g_speed > v_reach and toward >= c.approach_ratio * g_speed

        # Robot evidence (seed 4.3): a rising edge of "gripper closed or load shared" starts a
        # transfer; levels would re-trigger while the robot still carries the last object.
        grip = frame.gripper_closed is not None and bool(frame.gripper_closed)
        load = frame.load_share
        load_ok = load is not None and math.isfinite(load)
        evidence = grip or (load_ok and load > c.load_share_shared)
        if frame.gripper_closed is not None or load_ok:
            self._robot_reports = True
        shared = evidence and not self._prev_evidence
        self._prev_evidence = evidence
        self._source = "gripper" if grip else "load_share"
        released = load_ok and load > c.load_share_robot

        warm = self._nw >= _WARMUP and self._n_noise >= _WARMUP_SAMPLES
        if self._nw > 0.0 and (t - self._snap_t >= _SNAPSHOT or warm != self._noise_ready):
            # Early thresholds never sit inside the noise: 2-5 mm of tracking noise shows as
            # 0.05-0.3 m/s of filtered speed at 8-240 Hz. They use the noise as measured
            # 0.25-0.5 s ago: the slow first samples of a reach not yet aimed at the receiver
            # must not raise the bar it then has to pass.
            rms_now = math.sqrt(self._nv2 / self._nw)
            # (until the pending value rests on enough samples, the current one)
            rms_v = self._rms_pending if self._pending_ok else rms_now
            self._rms_pending, self._snap_t = rms_now, t
            self._noise_ready = self._pending_ok or warm
            self._pending_ok = warm
            self._v_noise = c.noise_speed_factor * rms_v
            # The filter's position noise is about 1.25 L times its speed noise per axis (8-240
            # Hz, from its steady-state gains); sway and motions of the giver do not enter.
            self._d_noise = c.noise_distance_factor * _POS_PER_SPEED * self._lag * rms_v
            f = c.early_fraction
            self._v_early = max(f * c.reach_onset_speed, self._v_noise)
            self._d_early = max(f * c.reach_confirm_distance, self._d_noise)
            self._rest_gate = max(c.rest_speed, 1.5 * rms_v)

        phase = self.phase
        self._step_phase(
            phase, t, d, qx, qy, qz, rel_speed, g_speed, toward, reaching, shared, released
        )
        self._prev_rs, self._prev_t = rel_speed, t

    def _step_phase(
        self,
        phase: Phase,
        t: float,
        d: float,
        qx: float,
        qy: float,
        qz: float,
        rel_speed: float,
        g_speed: float,
        toward: float,
        reaching: bool,
        shared: bool,
        released: bool,
    ) -> None:
        if phase is Phase.IDLE or phase is Phase.DONE:
            self._wait_reach(t, d, g_speed, reaching, shared)
        elif phase is Phase.REACH:
            self._in_reach(t, d, rel_speed, g_speed, toward, shared)
        elif phase is Phase.TRANSFER:
            self._in_transfer(t, qx, qy, qz, rel_speed, released)
        else:
            self._in_retreat(t, g_speed, reaching, d)

    def _measure_noise(self, t: float, g_speed: float) -> None:
        """Update the resting hand's speed noise; samples above 4 RMS are left out (a motion
        that is not aimed at the receiver, e.g. the start of a reach going up first)."""
        c = self.config
        if self._prev_t != self._prev_t:
            return  # no time step yet (the filter's first velocity is zero anyway)
        # One sample's weight (a pause in the measurement, e.g. a whole handover, must not let
        # the next sample replace what was learnt).
        dt = min(t - self._prev_t, c.max_gap_hold)
        if dt != self._noise_dt:  # regular sampling: same weight as last time
            self._noise_dt, self._noise_k = dt, 1.0 - math.exp(-dt / c.noise_tau)
        k = self._noise_k
        warm = self._n_noise >= _WARMUP_SAMPLES
        if warm and g_speed * g_speed > max(16.0 * self._nv2 / self._nw, 0.0025):
            return
        self._n_noise += 1
        self._nv2 += k * (g_speed * g_speed - self._nv2)
        self._nw += k * (1.0 - self._nw)

    def _wait_reach(self, t: float, d: float, g_speed: float, reaching: bool, shared: bool) -> None:
        c, g = self.config, self._g
        if self._cand_t0 != self._cand_t0 and t - self._done_at > 0.5:
            # Not while a motion may be under way, nor as the last retreat settles.
            self._measure_noise(t, g_speed)
        if g_speed < self._rest_gate:
            # Slowly averaged rest position: it still marks where the hand rested when the
            # (filter-lagged) speed crosses the onset threshold.
            if self._rest_x != self._rest_x or t - self._rest_t > 0.5:
                self._rest_x, self._rest_y, self._rest_z, self._rest_d = g.x, g.y, g.z, d
            else:
                k = 1.0 - math.exp(-(t - self._rest_t) / 0.2)
                self._rest_x += k * (g.x - self._rest_x)
                self._rest_y += k * (g.y - self._rest_y)
                self._rest_z += k * (g.z - self._rest_z)
                self._rest_d += k * (d - self._rest_d)
            self._rest_t = t
        # A reach: the hand speeds up toward the receiver. Confirmed after the full
        # ``reach_confirm_distance`` at ``reach_onset_speed``, or early (``early_fraction`` of
        # both, above the noise) while it still accelerates: a minimum-jerk start, not the
        # far side of a small fidget whose speed already peaked.
        aimed = reaching or (g_speed > self._v_early and self._toward >= c.approach_ratio * g_speed)
        if g_speed < self._rest_gate:
            self._came_to_rest = True
        if aimed and (not self._noise_ready or not self._came_to_rest):
            # The noise floor is not known yet (a fresh start), or the last retreat has not
            # settled (its landing was predicted): motion alone starts no reach.
            aimed = False
            self._cand_t0 = math.nan
        if aimed:
            fresh = self._cand_t0 != self._cand_t0
            if fresh:
                self._cand_t0 = self._backdate_onset(t, g_speed)
                self._cand_d0 = self._rest_d if self._rest_d == self._rest_d else d
                self._cand_vmax = 0.0
            # One noise spike is no reach: early needs the speed-up seen on two samples (below
            # 20 Hz one sample is evidence enough), and while the receiver (a robot) moves,
            # closing the distance on its own, both need two unless the giver's hand is clearly
            # faster than noise.
            robot_moves = self._r_speed > c.rest_speed and g_speed < 2.0 * self._v_early
            sparse = t - self._prev_t > 0.05 and not robot_moves
            accelerating = g_speed >= 0.95 * self._cand_vmax and (not fresh or sparse)
            fresh = fresh and robot_moves
            self._cand_vmax = max(self._cand_vmax, g_speed)
            closed = self._cand_d0 - d
            early = -math.inf
            if accelerating and self._rest_x == self._rest_x and d > 1e-9:
                # Early: half of the closing by the giver's own hand (a robot moving home past
                # a resting giver closes the distance too), and the hand's speed *now*, not the
                # filter's lagged one, above ``reach_onset_speed``: a minimum-jerk start at x
                # since rest and age a moves at 3 x / a. A fidget of a centimetre or two stays
                # slower than that.
                r = self._r
                ex, ey, ez = g.x - self._rest_x, g.y - self._rest_y, g.z - self._rest_z
                own = (ex * (r.x - g.x) + ey * (r.y - g.y) + ez * (r.z - g.z)) / d
                x = math.sqrt(ex * ex + ey * ey + ez * ez)
                age = self._motion_age(x, g_speed)
                v_now = max(c.reach_onset_speed, self._v_noise) * c.early_speed_margin
                if age > 0.0 and 3.0 * x >= age * v_now:
                    early = min(closed, 2.0 * own)
            full = max(c.reach_confirm_distance, self._d_early)
            if (reaching and closed >= full and not fresh) or (
                accelerating and early >= self._d_early
            ):
                t0 = self._cand_t0
                self._start(Phase.REACH, EventKind.REACH_STARTED, t0, t, "motion")
                self._ref_d = self._cand_d0
                self._d_min = d
        elif g_speed < 0.5 * self._v_early:
            self._cand_t0 = math.nan
        if shared and self.phase is not Phase.REACH:
            # The robot grasped although no reach was seen: report the reach it implies.
            t0 = self._cand_t0 if self._cand_t0 == self._cand_t0 else t
            self._start(Phase.REACH, EventKind.REACH_STARTED, t0, t, self._source)
            self._start(Phase.TRANSFER, EventKind.TRANSFER_STARTED, t, t, self._source)
            self._ref_d = d

    def _backdate_onset(self, t: float, speed: float) -> float:
        """Back-date the onset of the giver's motion from its rest position."""
        g = self._g
        if self._rest_x != self._rest_x or speed <= 0.0:
            return t - self._lag
        dx, dy, dz = g.x - self._rest_x, g.y - self._rest_y, g.z - self._rest_z
        return t - self._motion_age(math.sqrt(dx * dx + dy * dy + dz * dz), speed)

    def _motion_age(self, x: float, v: float) -> float:
        """Time since a minimum-jerk motion left rest, from its filtered displacement and speed.

        Near its start a minimum-jerk motion covers ``x = c a^3`` at speed ``v = 3 c a^2``, so
        ``a = 3 x / v``. The tracking filter sees the speed through a critically damped
        low-pass (delay ``L = 2 / w``): ``v_f = 3 c ((a - L)^2 + L^2 / 2)`` and
        ``x_f = c (a^3 - 1.5 L^2 a)``; with ``R = 3 x_f / v_f`` the age solves
        ``a^3 - R a^2 + (2 R L - 1.5 L^2) a - 1.5 R L^2 = 0`` (a few Newton steps from ``R``).
        """
        if v <= 0.0:
            return 0.0
        r = 3.0 * x / v
        lag = self._lag
        c1 = 2.0 * r * lag - 1.5 * lag * lag
        c0 = -1.5 * r * lag * lag
        a = r
        for _ in range(8):
            f = ((a - r) * a + c1) * a + c0
            df = (3.0 * a - 2.0 * r) * a + c1
            if df <= 1e-12:
                a = r - lag
                break
            step = f / df
            a -= step
            if abs(step) < 1e-5:
                break
        return min(max(a, 0.0), self.config.max_refine)

    def _track_peak(self, t: float, g_speed: float, nominal: float, with_receiver: bool) -> None:
        if g_speed > self._v_peak:
            self._v_peak, self._t_peak = g_speed, t
        start = self.phase_start
        onset = self.config.reach_onset_speed
        if self._v_peak > onset and g_speed < 0.8 * self._v_peak:
            # Past the peak of a bell-shaped speed profile: end mirrors the start.
            pred = start + 2.0 * max(self._t_peak - self._lag - start, 0.0)
        else:
            pred = start + nominal
        if with_receiver and self._r_on == self._r_on and self._r_on > start - nominal:
            # Contact needs the receiver (often a robot gripper) too: mirror its own profile.
            r_on = self._r_on
            if self._r_vpeak > onset and self._r_speed < 0.8 * self._r_vpeak:
                pred = max(pred, r_on + 2.0 * max(self._r_tpeak - self._lag - r_on, 0.0))
            elif self._r_speed > onset:
                pred = max(pred, r_on + nominal)
        self.expected_phase_end = max(pred, t)

    def _track_receiver(self, t: float, r_speed: float) -> None:
        """Onset and speed peak of the receiver hand's own motion (constant cost)."""
        r, c = self._r, self.config
        if r_speed < c.rest_speed:
            self._r_rx, self._r_ry, self._r_rz = r.x, r.y, r.z
        elif r_speed > c.reach_onset_speed and self._r_speed <= c.reach_onset_speed:
            if self._r_rx == self._r_rx:
                dx, dy, dz = r.x - self._r_rx, r.y - self._r_ry, r.z - self._r_rz
                self._r_on = t - self._motion_age(math.sqrt(dx * dx + dy * dy + dz * dz), r_speed)
            else:
                self._r_on = t - self._lag
            self._r_vpeak = 0.0
        if r_speed > self._r_vpeak:
            self._r_vpeak, self._r_tpeak = r_speed, t
        self._r_speed = r_speed

    def _crossing(self, t: float, v: float, threshold: float) -> float:
        """When the relative speed fell through ``threshold`` (linear between the last two
        samples: at 8 Hz a sample interval is 125 ms)."""
        pv, pt = self._prev_rs, self._prev_t
        if pv == pv and pv > threshold >= v and pv > v:
            return pt + (pv - threshold) / (pv - v) * (t - pt)
        return t

    def _in_reach(
        self, t: float, d: float, rel_speed: float, g_speed: float, toward: float, shared: bool
    ) -> None:
        c = self.config
        if self._ref_d != self._ref_d:  # adopted by resync: reference from this sample
            self._ref_d = d
        if d < self._d_min:
            self._d_min = d
        self._track_peak(t, g_speed, c.reach_duration, True)
        near = d <= self._d_min + c.transfer_distance_margin
        closed = d <= self._ref_d - c.reach_confirm_distance
        if shared:
            # The gripper closing (or the load being shared) is the transfer's start, exactly.
            self._start(Phase.TRANSFER, EventKind.TRANSFER_STARTED, t, t, self._source)
            return
        if self._robot_reports:
            # Hands at rest near each other are not yet a transfer while the robot says it has
            # not grasped (a giver waiting for a slow gripper); only the reach abort applies.
            self._cand_t0 = math.nan
        elif self._cand_t0 != self._cand_t0:
            if near and closed and rel_speed < c.transfer_speed_max and d <= c.contact_distance_max:
                self._cand_seen = self._crossing(t, rel_speed, c.transfer_speed_max)
                self._cand_t0 = self._cand_seen
                self._cand_d0 = d
                self._settled = False
        if self._cand_t0 == self._cand_t0:
            if rel_speed > c.transfer_exit_speed or not near:
                self._cand_t0 = math.nan
            else:
                if rel_speed < c.settle_speed and not self._settled:
                    # The minimum-jerk tail (speed ~ (t_stop - t)^2) crosses the seed's 15 cm/s
                    # well before contact; settling below ``settle_speed`` marks the stop, and
                    # rejects a giver waiting for a receiver that is still coming.
                    self._settled = True
                    self._cand_t0 = self._crossing(t, rel_speed, c.settle_speed)
                elif not self._settled and d < self._cand_d0 - c.release_distance:
                    # Still closing (a giver waiting for a slow receiver): not a transfer yet.
                    self._cand_seen = self._cand_t0 = t
                    self._cand_d0 = d
                waited = t - self._cand_seen
                if (self._settled and waited >= c.min_transfer) or waited >= c.settle_timeout:
                    t0 = self._cand_t0
                    if self._settled:
                        # Parabolic speed tail: the two crossings extrapolate to the stop; the
                        # filter delays both by about the lag.
                        t0 += c.stop_extrapolation * (t0 - self._cand_seen) / self._tail_ratio
                        t0 -= self._lag
                    self._start(Phase.TRANSFER, EventKind.TRANSFER_STARTED, t0, t, "motion")
                    return
        # Aborted reach: the giver takes the hand back before any transfer.
        if (
            d > self._d_min + c.transfer_distance_margin
            and g_speed > c.reach_onset_speed
            and toward < -c.approach_ratio * g_speed
        ):
            self._done(t, t, d, "aborted")

    def _in_transfer(
        self, t: float, qx: float, qy: float, qz: float, rel_speed: float, released: bool
    ) -> None:
        c, g, r = self.config, self._g, self._r
        first = self._n_ref < 1
        if first:
            self._n_ref = 1
            self._anc_x, self._anc_y, self._anc_z = qx, qy, qz
        if released:
            self._start(Phase.RETREAT, EventKind.RETREAT_STARTED, t, t, "load_share")
            # Released before the first sample this detector saw of the transfer (a restart):
            # the hand may be well on its way back, so rest alone ends the retreat.
            self._moved_unknown = first
            return
        # Separation from the held relative pose, not only the distance: a release often moves
        # the hand sideways or down first.
        dx, dy, dz = qx - self._anc_x, qy - self._anc_y, qz - self._anc_z
        sep = math.sqrt(dx * dx + dy * dy + dz * dz)
        # Early: a smaller separation, above the noise, moving away from the held pose (the
        # relative velocity points along the separation, not jitter about it).
        f = c.early_fraction
        v_early = max(f * c.release_speed, 0.5 * self._v_noise)
        d_early = max(f * c.release_distance, self._d_noise)
        # q = receiver - giver, so dq/dt = v_r - v_g; separating means along dq.
        away = (r.vx - g.vx) * dx + (r.vy - g.vy) * dy + (r.vz - g.vz) * dz
        early = rel_speed > v_early and sep > d_early and away > 0.7 * rel_speed * sep
        # Twice in a row when samples are dense: one noisy sample of a short, jittery hold is
        # not a release (at low rates a sample is already 1/8 s of evidence).
        twice = early and (self._early_seen or t - self._prev_t > 0.05)
        early, self._early_seen = twice, early
        full = rel_speed > max(c.release_speed, v_early) and sep > max(c.release_distance, d_early)
        if early or full:
            # The release started a minimum-jerk motion from the held pose: back-date it.
            back = self._motion_age(sep, rel_speed)
            self._start(Phase.RETREAT, EventKind.RETREAT_STARTED, t - back, t, "motion")
            # Seen late (sparse samples): the hand may be most of the way back already.
            self._moved_unknown = back > 0.25
            return
        if rel_speed < c.transfer_speed_max:
            # Running mean of the held relative pose: the release reference.
            n = self._n_ref = min(self._n_ref + 1, 50)
            self._anc_x += dx / n
            self._anc_y += dy / n
            self._anc_z += dz / n
        self.expected_phase_end = max(self.phase_start + c.transfer_duration, t)

    def _set_anchor(self) -> None:
        # _enter cleared the transfer point; keep it for the retreat's "far away" test.
        g = self._g
        self._anc_x, self._anc_y, self._anc_z = g.x, g.y, g.z

    def _in_retreat(self, t: float, g_speed: float, reaching: bool, d: float) -> None:
        c, g = self.config, self._g
        if self._anc_x != self._anc_x:
            self._set_anchor()
        self._track_peak(t, g_speed, c.retreat_duration, False)
        dx, dy, dz = g.x - self._anc_x, g.y - self._anc_y, g.z - self._anc_z
        moved = math.sqrt(dx * dx + dy * dy + dz * dz)
        # Rest is judged on a smoothed velocity (vector, so noise averages out instead of adding
        # up in the norm): the filtered speed of a resting hand flickers around ``rest_speed``.
        k = 1.0
        if self._speed_t == self._speed_t:
            k = 1.0 - math.exp(-(t - self._speed_t) / self._rest_tau)
        self._avx += k * (g.vx - self._avx)
        self._avy += k * (g.vy - self._avy)
        self._avz += k * (g.vz - self._avz)
        self._speed_t = t
        self._speed_avg = math.sqrt(self._avx**2 + self._avy**2 + self._avz**2)
        if self._speed_avg < self._rest_gate:
            if self._slow_since != self._slow_since:
                self._slow_since = t
        else:
            self._slow_since = math.nan
        at_rest = (
            self._slow_since == self._slow_since
            and t - self._slow_since >= c.rest_hold
            and (moved >= c.min_approach or self._moved_unknown)
        )
        mirrored = math.nan
        if self._v_peak > c.reach_onset_speed:
            start = self.phase_start
            mirrored = start + 2.0 * max(self._t_peak - self._lag - start, 0.0)
        # Almost at rest: the hand decelerates below a fraction of its (bell-shaped) peak
        # speed. The filtered speed lags by L, so this is seen about when the motion ends.
        landing = (
            mirrored == mirrored
            and (moved >= c.min_approach or self._moved_unknown)
            and (
                g_speed < c.done_fraction * self._v_peak
                # A noisy hand hides the tail: then below the noise and at the mirrored end.
                or (g_speed < self._v_early and t >= mirrored)
            )
            and g_speed < 0.5 * self._v_peak
            and t > self._t_peak
        )
        if landing:
            self._done(min(mirrored, t), t, d, "landing")
        elif at_rest:
            t_rest = self._slow_since - self._rest_tau
            if self._v_peak > c.reach_onset_speed:
                # The smoothed speed settles late; the mirrored speed peak often knows better.
                start = self.phase_start
                t_rest = min(t_rest, start + 2.0 * max(self._t_peak - self._lag - start, 0.0))
            self._done(t_rest, t, d, "rest")
        elif moved >= c.retreat_far_distance:
            self._done(t, t, d, "far")
        elif t - self.phase_start > c.max_retreat:
            self._done(t, t, d, "timeout")
        elif reaching and moved >= c.min_approach:
            # The hand turned back toward the receiver: a second handover begins.
            self._done(t, t, d, "next_reach")

    def _done(self, t0: float, now: float, d: float, source: str) -> None:
        self._emit(EventKind.HANDOVER_DONE, max(t0, self.phase_start), now, source)
        self._enter(Phase.DONE, max(t0, self.phase_start))
        self._came_to_rest = source != "landing"
        self._done_at = now
        g = self._g
        # The hand's position now is the rest the next reach starts from.
        self._rest_t = now
        self._rest_x, self._rest_y, self._rest_z = g.x, g.y, g.z
        self._rest_d = d


@dataclass
class OnlineResult:
    """What :func:`run_online` saw: every event, the resulting segments and the sample counts."""

    events: list[Event]
    segments: list[Segment]
    stats: DetectorStats


def run_online(trajectory: Trajectory, config: PhaseConfig | None = None) -> OnlineResult:
    """Replay a recording through a fresh :class:`PhaseDetector`, sample by sample, in the
    stored order (out-of-order samples are ignored as they would be live)."""
    det = PhaseDetector(config)
    events: list[Event] = []
    for frame in trajectory.iter_frames():
        events.extend(det.update_all(frame))
    t_end = float(np.nanmax(trajectory.t)) if len(trajectory) else math.nan
    return OnlineResult(events, segments_from_events(events, t_end), det.stats)
