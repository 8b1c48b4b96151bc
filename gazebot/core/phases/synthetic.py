"""Synthetic human-to-robot handovers with known phase times, for tests and benchmarks.

A giver reaches from rest to a handover location with a minimum-jerk profile (slightly curved),
holds the object while a robot gripper (moving from home to the handover pose, also
minimum-jerk) grasps it, releases it, and retracts to rest; the gripper carries the object to a
drop-off pose and returns home. Durations are drawn around the seed's human-human means
(section 6.2 annotations: reach ~0.8-1.0 s, transfer ~0.6 s (0.25-1.75), retreat ~1.1 s), scaled
for slow or fast givers; heights follow a standing or sitting giver. The recording gets motion
capture noise, sway at rest, short dropouts, irregular sampling from 8 to 240 Hz, and the robot's
gripper state and load share (seed section 4.3).

Ground truth per handover (:class:`HandoverTruth`): reach starts at the giver's motion onset;
transfer starts when both hands touch the object (the later of the two arrivals) and ends at the
giver's release; the retreat ends when the giver's hand is back at rest.

The hold (``SyntheticOptions.hold``) is one of the kinds seen on real handovers (issue 20):

- ``pull``: both hands hold the object and drift up to 3 cm toward the robot (the default);
- ``carry``: a heavy full container: the hands meet, then move *together* for about 1 s (common
  speed 0.1-0.3 m/s) while their relative position wobbles (relative speed 0.02-0.10 m/s,
  distance within +-1 cm) before they separate;
- ``still``: a full cup: both hands steady (relative speed under 0.03 m/s) for about 1.3 s;
- ``coupled``: a careful handover of a full pitcher or cup (issue 33): the hands meet 0.31-0.37
  m apart (segment origins of a mocap suit, the object between) and for 1.1-1.5 s move the
  object together (common speed 0.06-0.21 m/s, in two legs of different directions, so the
  common motion slows and turns mid-hold) while the pair turns, so their relative position
  swings at 0.04-0.10 m/s with the distance held within 1 cm; then the receiver pulls away.

:func:`case_set` makes those and the quick light-cup handover (30 Hz, 5 mm noise);
:func:`early_lift_set` makes givers who lift the object early and wait before the final approach;
:func:`rest_recording` makes recordings with no handover at all (a resting or fidgeting giver
under marker noise) for the no-false-event checks.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from gazebot.core.minimum_jerk import minimum_jerk
from gazebot.core.phases.segment import Segment
from gazebot.core.phases.trajectory import Trajectory
from gazebot.core.types import Phase

Posture = Literal["standing", "sitting"]
Hold = Literal["pull", "carry", "still", "coupled"]
CaseKind = Literal["carry", "still", "quick30", "quick_noisy", "coupled", "coupled30"]


def _bump(s: np.ndarray) -> np.ndarray:
    """Smooth 0 -> 1 -> 0 bump (zero velocity and acceleration at both ends)."""
    s = np.clip(s, 0.0, 1.0)
    return 64.0 * s**3 * (1.0 - s) ** 3


@dataclass
class _Path:
    """A point that rests, then makes minimum-jerk moves (each optionally curved)."""

    start: np.ndarray
    moves: list[tuple[float, float, np.ndarray, np.ndarray]] = field(default_factory=list)

    @property
    def end(self) -> np.ndarray:
        return self.moves[-1][2] if self.moves else self.start

    def move(self, t0: float, duration: float, to: np.ndarray, bump: np.ndarray | None = None):
        bump = np.zeros(3) if bump is None else bump
        self.moves.append((t0, duration, np.asarray(to, float), bump))

    def at(self, t: np.ndarray) -> np.ndarray:
        out = np.repeat(self.start[None, :], t.shape[0], axis=0)
        prev = self.start
        for t0, dur, to, bump in self.moves:
            s = (t - t0) / dur
            out += minimum_jerk(s)[:, None] * (to - prev) + _bump(s)[:, None] * bump
            prev = to
        return out


@dataclass(frozen=True)
class HandoverTruth:
    """Known phase times of one synthetic handover (s)."""

    reach_start: float
    transfer_start: float
    transfer_end: float
    retreat_end: float
    grasp: float = float("nan")  # the gripper closes (robot evidence), after the contact

    def segments(self, handover: int = 0) -> list[Segment]:
        """The true reach, transfer and retreat segments, numbered ``handover``."""
        return [
            Segment(Phase.REACH, self.reach_start, self.transfer_start, handover),
            Segment(Phase.TRANSFER, self.transfer_start, self.transfer_end, handover),
            Segment(Phase.RETREAT, self.transfer_end, self.retreat_end, handover),
        ]


@dataclass(frozen=True)
class SyntheticOptions:
    """How a synthetic recording is made.

    Attributes:
        rate: Mean sampling rate (Hz), 8..240.
        irregular: Relative jitter of the sampling intervals (0 = regular, 0.3 = +-30 %).
        noise: Motion-capture noise of the human points (m, standard deviation).
        gripper_noise: Noise of the gripper position (m).
        dropouts_per_s: Rate of short dropouts of a human point (each 20-200 ms).
        posture: ``standing`` or ``sitting`` giver; ``None`` draws one.
        speed: Giver speed factor (>1 fast, <1 slow); durations scale with ``1 / speed``.
        handovers: Number of consecutive handovers in the recording.
        robot_evidence: Whether the recording has the gripper state and load share.
        marker_offset: Distance (m) between the tracked hand frames at contact, as on real
            motion capture (markers on the back of the hand or the wrist, an object between):
            each frame sits half of it behind the contact point, along the giver-robot line.
        frozen_per_s: Rate of frozen stretches (the tracker repeats its last sample for 2-8
            samples with new times) per point.
        glitches_per_s: Rate of one-sample glitches per hand: the sample jumps 1.5-7 cm in a
            random direction and is back at the next one (a marker swapped for a frame).
        robot_lead: When > 0, the robot sets off this long (s) *before* the giver (a
            robot-initiated handover, seed 6.3: the receiver's hand moves first); 0: the robot
            reacts to the giver 0.05-0.4 s after its onset.
        hold: What the hands do while both hold the object: ``pull``, ``carry``, ``still`` or
            ``coupled`` (see the module docstring).
        hold_time: ``(low, high)`` range the hold's duration is drawn from (s, before the
            ``speed`` scaling); ``None``: the hold kind's own (pull 0.3-1.2, carry 0.9-1.1,
            still 1.2-1.4, coupled 1.1-1.5).
        early_lift: When > 0, before each reach the giver lifts the object (10-15 cm up, a
            few cm toward the robot) and waits this long (s) before the final approach, which
            is the reach (issue 20: a giver who lifted the cup early, then waited).
        robot_delay: The robot sets off this much later (s) than it would: the giver holds
            the object out at the handover place and waits.
    """

    rate: float = 100.0
    irregular: float = 0.0
    noise: float = 0.001
    gripper_noise: float = 0.0003
    dropouts_per_s: float = 0.0
    posture: Posture | None = None
    speed: float = 1.0
    handovers: int = 1
    robot_evidence: bool = False
    marker_offset: float = 0.0
    frozen_per_s: float = 0.0
    glitches_per_s: float = 0.0
    robot_lead: float = 0.0
    hold: Hold = "pull"
    hold_time: tuple[float, float] | None = None
    early_lift: float = 0.0
    robot_delay: float = 0.0

    def __post_init__(self) -> None:
        if not 1.0 <= self.rate <= 2000.0:
            raise ValueError(f"rate must be 1..2000 Hz, got {self.rate}")
        if not 0.0 <= self.irregular < 0.9:
            raise ValueError(f"irregular must be 0..0.9, got {self.irregular}")
        if self.handovers < 1 or self.speed <= 0:
            raise ValueError("handovers must be >= 1 and speed > 0")
        if not 0.0 <= self.robot_lead <= 3.0:
            raise ValueError(f"robot_lead must be 0..3 s, got {self.robot_lead}")
        if self.hold not in _HOLD_TIME:
            raise ValueError(f"hold must be one of {sorted(_HOLD_TIME)}, got {self.hold!r}")
        if self.hold_time is not None and not 0.1 <= self.hold_time[0] <= self.hold_time[1]:
            raise ValueError(
                f"hold_time must be (low, high) with 0.1 <= low <= high s, got {self.hold_time}"
            )


# Hold durations per hold kind (s, before the speed scaling): the seed's 0.25-1.75 s transfers,
# about 1 s of joint carrying and about 1.3 s of a still hold (issue 20's held-out recordings).
_HOLD_TIME = {"pull": (0.3, 1.2), "carry": (0.9, 1.1), "still": (1.2, 1.4), "coupled": (1.1, 1.5)}


@dataclass
class SyntheticHandover:
    """A generated recording and its ground truth.

    ``giver_motion``: the giver's hand at the recording's sample times as the generator moved
    it (m, N x 3), before sway, marker noise, carrying wobble, marker offsets and dropouts:
    what an ideal observer would have to tell apart from a fidget
    (``benchmarks/bench_phases.py``'s reach onset bound)."""

    trajectory: Trajectory
    truth: list[HandoverTruth]
    options: SyntheticOptions
    seed: int
    giver_motion: np.ndarray

    def truth_segments(self) -> list[Segment]:
        """The true segments of every handover in the recording, in order."""
        return [s for i, h in enumerate(self.truth) for s in h.segments(i)]


def _sample_times(rng: np.random.Generator, t_end: float, opts: SyntheticOptions) -> np.ndarray:
    dt = 1.0 / opts.rate
    n = int(t_end / dt) + 2
    steps = dt * (1.0 + rng.uniform(-opts.irregular, opts.irregular, n))
    t = np.concatenate([[0.0], np.cumsum(steps)])
    return t[t <= t_end]


def generate(seed: int = 0, options: SyntheticOptions | None = None) -> SyntheticHandover:
    """Generate one recording (reproducible for a seed)."""
    opts = options or SyntheticOptions()
    rng = np.random.default_rng(seed)
    posture: Posture = opts.posture or ("standing" if rng.random() < 0.5 else "sitting")
    u = rng.uniform
    giver = np.array([u(0.95, 1.3), u(-0.15, 0.15), 0.0])
    if posture == "standing":
        face = giver + [0.0, 0.0, u(0.55, 0.75)]
        rest = giver + [u(-0.2, -0.1), u(-0.25, -0.15), u(-0.1, 0.0)]
        hand_z = (0.05, 0.3)
    else:
        face = giver + [0.05, 0.0, u(0.25, 0.4)]
        rest = giver + [u(-0.3, -0.2), u(-0.2, -0.1), u(-0.25, -0.15)]
        hand_z = (-0.1, 0.12)
    home = np.array([u(0.3, 0.4), u(-0.35, -0.25), u(0.2, 0.3)])
    dropoff = np.array([u(0.25, 0.35), u(-0.55, -0.45), u(0.15, 0.25)])

    hand = _Path(rest.copy())
    grip = _Path(home.copy())
    lean = _Path(np.zeros(3))
    grip_events: list[tuple[float, float, float]] = []  # (t_close, t_release, t_open)
    # carried holds: (t0, duration, cycles, giver wobble amplitude m, turn amplitude rad)
    wobbles: list[tuple[float, float, int, np.ndarray, float]] = []
    truth: list[HandoverTruth] = []
    t = u(0.4, 1.2) + opts.robot_lead
    for _ in range(opts.handovers):
        if opts.early_lift > 0:
            # The giver lifts the object early (10-15 cm up, 3-6 cm toward the robot, 0.6 s)
            # and waits before the final approach: the reach is the final approach.
            lifted = rest + np.array([-u(0.03, 0.06), u(-0.02, 0.02), u(0.10, 0.15)])
            hand.move(t, 0.6, lifted)
            rest = lifted
            t += 0.6 + opts.early_lift
        onset = t
        reach = float(np.clip(u(0.7, 1.25) / opts.speed, 0.4, 2.5))
        target = np.array([giver[0] - u(0.3, 0.5), giver[1] + u(-0.12, 0.12), u(*hand_z)])
        hand.move(onset, reach, target, bump=np.array([0.0, u(-0.04, 0.04), u(0.0, 0.05)]))
        lean.move(onset, reach, np.array([-u(0.0, 0.05), 0.0, 0.0]))
        # The robot reacts to the giver and aims at the handover pose with a small error;
        # its fingers meet the object half a size in front of the hand.
        lag = u(0.05, 0.4)
        if opts.robot_lead > 0:
            lag = -opts.robot_lead
        lag += opts.robot_delay
        g_dur = u(0.8, 1.5)
        offset = np.array([-u(0.04, 0.15), u(-0.01, 0.01), u(-0.01, 0.01)])
        if opts.hold == "coupled":
            # The receiver's hand frame meets the object's other side: with the marker
            # offset of a mocap suit's segment origins, 0.31-0.37 m apart in all.
            offset[0] = -u(0.06, 0.10)
        grip.move(onset + lag, g_dur, target + offset)
        contact = max(onset + reach, onset + lag + g_dur)
        t_close = contact + u(0.05, 0.25)
        lo_hold, hi_hold = opts.hold_time or _HOLD_TIME[opts.hold]
        hold = float(np.clip(u(lo_hold, hi_hold) / opts.speed, 0.2, 1.75))
        release = max(contact + hold, t_close + 0.1)
        pull_t0 = contact + 0.05
        if opts.hold == "pull":
            # Both hold the object: a small common pull toward the robot.
            pull = np.array([-u(0.0, 0.03), 0.0, u(-0.01, 0.01)])
        elif opts.hold == "carry":
            # Both carry it together: mean common speed 0.1-0.3 m/s along a random direction.
            way = rng.normal(size=3) * [1.0, 1.0, 0.5]
            pull = u(0.1, 0.3) * (release - pull_t0) * way / np.linalg.norm(way)
            # ... while the pair turns back and forth about the vertical (by 0.03-0.09 rad):
            # the marker frames, behind the hands, turn with it, so their relative position
            # swings at 0.02-0.10 m/s (offset x turn rate) at a constant distance, and the
            # giver's hand wobbles by +-0.3-0.6 cm against the receiver's.
            cycles = max(1, round(u(0.8, 1.3) * (release - pull_t0)))
            axis = rng.normal(size=3)
            wobble = u(0.003, 0.006) * axis / np.linalg.norm(axis)
            wobbles.append((pull_t0, release - pull_t0, cycles, wobble, u(0.03, 0.09)))
        elif opts.hold == "coupled":
            # Both move it together in two legs (mean common speed 0.06-0.21 m/s each, a new
            # direction each), the pair turning so the relative position swings at 0.04-0.10
            # m/s (marker offset x turn rate; mean |turn rate| = 2 A cycles / duration).
            half_t = 0.5 * (release - pull_t0)
            legs = []
            for _ in range(2):
                way = rng.normal(size=3) * [1.0, 1.0, 0.5]
                legs.append(u(0.06, 0.21) * half_t * way / np.linalg.norm(way))
            for k, leg in enumerate(legs):
                to = target + legs[0] + (leg if k else 0.0)
                hand.move(pull_t0 + k * half_t, half_t, to)
                grip.move(pull_t0 + k * half_t, half_t, to + offset)
            pull = legs[0] + legs[1]
            cycles = max(1, round(u(0.8, 1.3) * (release - pull_t0)))
            arm = max(opts.marker_offset, 0.05)
            turn_amp = u(0.04, 0.10) * (release - pull_t0) / (2.0 * arm * cycles)
            axis = rng.normal(size=3)
            wobble = 0.002 * axis / np.linalg.norm(axis)
            wobbles.append((pull_t0, release - pull_t0, cycles, wobble, turn_amp))
        else:
            pull = np.zeros(3)  # still: both hands steady
        if release - pull_t0 > 0.1 and opts.hold not in ("still", "coupled"):
            hand.move(pull_t0, release - pull_t0, target + pull)
            grip.move(pull_t0, release - pull_t0, target + offset + pull)
        back = rest + np.array([u(-0.03, 0.03), u(-0.03, 0.03), u(-0.02, 0.02)])
        retreat = float(np.clip(u(0.7, 1.5) / opts.speed, 0.5, 2.5))
        giver_out = release + u(0.0, 0.05)
        hand.move(giver_out, retreat, back, bump=np.array([0.0, 0.0, u(0.0, 0.04)]))
        lean.move(giver_out, retreat, np.zeros(3))
        robot_out = release + u(0.15, 0.4)
        carry = u(1.0, 1.5)
        grip.move(robot_out, carry, dropoff)
        t_open = robot_out + carry + 0.2
        grip.move(t_open + 0.1, u(0.9, 1.2), home)
        grip_events.append((t_close, release, t_open))
        truth.append(HandoverTruth(onset, contact, release, giver_out + retreat, t_close))
        rest = back
        # Next handover: after the hand rests and the robot is home again.
        t = max(giver_out + retreat, t_open + 1.3) + u(0.3, 1.0)
    t_end = t + u(0.0, 0.5)

    ts = _sample_times(rng, t_end, opts)
    n = ts.shape[0]
    sway = 0.004 * np.sin(2 * np.pi * u(0.2, 0.4) * ts + u(0, 6))[:, None] * np.array([1, 0.5, 0.3])
    motion = hand.at(ts)
    gh = motion + sway + rng.normal(0.0, opts.noise, (n, 3))
    turn = np.zeros(n)  # the pair's turn about the vertical while carrying (rad)
    for t0, dur, cycles, amp, turn_amp in wobbles:
        wave = np.sin(np.pi * cycles * np.clip((ts - t0) / dur, 0.0, 1.0))
        gh += wave[:, None] * amp
        turn += turn_amp * wave
    rh = grip.at(ts) + rng.normal(0.0, opts.gripper_noise, (n, 3))
    gf = face + lean.at(ts) + 0.5 * sway + rng.normal(0.0, opts.noise, (n, 3))
    if opts.marker_offset > 0:
        half = 0.5 * opts.marker_offset * np.stack([np.cos(turn), np.sin(turn), 0 * turn], 1)
        gh = gh + half  # the giver stands at +x, the robot at -x
        rh = rh - half
    if opts.frozen_per_s > 0:
        for arr in (gh, rh):
            for t0 in rng.uniform(0, t_end, rng.poisson(opts.frozen_per_s * t_end)):
                i = int(np.searchsorted(ts, t0))
                k = int(rng.integers(2, 9))
                if 0 < i < n - k:
                    arr[i : i + k] = arr[i - 1]
    if opts.glitches_per_s > 0:
        for arr in (gh, rh):
            for t0 in rng.uniform(0, t_end, rng.poisson(opts.glitches_per_s * t_end)):
                i = int(np.searchsorted(ts, t0))
                if i < n:
                    way = rng.normal(size=3)
                    arr[i] = arr[i] + u(0.015, 0.07) * way / np.linalg.norm(way)
    if opts.dropouts_per_s > 0:
        for arr in (gh, gf, rh):
            k = rng.poisson(opts.dropouts_per_s * t_end * (0.3 if arr is rh else 1.0))
            for t0 in rng.uniform(0, t_end, k):
                arr[(ts >= t0) & (ts < t0 + u(0.02, 0.2))] = np.nan

    closed = np.full(n, np.nan)
    load = np.full(n, np.nan)
    if opts.robot_evidence:
        closed[:] = 0.0
        load[:] = 0.0
        for t_close, release, t_open in grip_events:
            closed[(ts >= t_close) & (ts < t_open)] = 1.0
            holding = (ts >= t_close) & (ts < release)
            load[holding] = 0.15 + 0.7 * (ts[holding] - t_close) / (release - t_close)
            after = (ts >= release) & (ts < t_open)
            load[after] = np.minimum(1.0, 0.85 + 3.0 * (ts[after] - release))
    traj = Trajectory(ts, gh, rh, gf, closed, load)
    return SyntheticHandover(traj, truth, replace(opts, posture=posture), seed, motion)


def synthetic_set(n: int = 40, seed: int = 0, **overrides: object) -> list[SyntheticHandover]:
    """A varied set of recordings: rates 8-240 Hz, regular and irregular sampling, noise 0.5-3
    mm, dropouts, both postures, slow and fast givers, single and double handovers.

    ``overrides`` fix any :class:`SyntheticOptions` field for the whole set.
    """
    rng = np.random.default_rng(seed)
    rates = (8.0, 15.0, 30.0, 60.0, 100.0, 120.0, 240.0)
    out = []
    for i in range(n):
        opts = SyntheticOptions(
            rate=float(rates[i % len(rates)]),
            irregular=float(rng.choice([0.0, 0.0, 0.2, 0.4])),
            noise=float(rng.uniform(0.0005, 0.003)),
            dropouts_per_s=float(rng.choice([0.0, 0.0, 0.3, 1.0])),
            posture="standing" if i % 2 == 0 else "sitting",
            speed=float(rng.choice([0.7, 1.0, 1.0, 1.4])),
            handovers=2 if i % 5 == 4 else 1,
        )
        if overrides:
            opts = replace(opts, **overrides)  # type: ignore[arg-type]
        out.append(generate(int(rng.integers(2**31)), opts))
    return out


# The issue-20 cases: (hold kind, rate Hz, noise m, speed factor, hold_time, marker offset m),
# and issue 33's careful coupled handovers with a mocap suit's artefacts.
_CASES: dict[str, tuple[Hold, float, float, float, tuple[float, float] | None, float]] = {
    # A heavy full container carried together; hand frames 0.3-0.4 m apart at contact.
    "carry": ("carry", 120.0, 0.0015, 1.0, None, 0.25),
    # A full cup held still for ~1.3 s.
    "still": ("still", 120.0, 0.0015, 1.0, None, 0.25),
    # A quick handover of a light cup (short hold, fast giver) at 30 Hz ...
    "quick30": ("pull", 30.0, 0.0015, 1.5, (0.25, 0.4), 0.3),
    # ... and at 120 Hz with 5 mm of marker noise.
    "quick_noisy": ("pull", 120.0, 0.005, 1.5, (0.25, 0.4), 0.3),
    # A full pitcher moved together for 1.1-1.5 s at 120 Hz ...
    "coupled": ("coupled", 120.0, 0.0015, 1.0, None, 0.26),
    # ... and at 30 Hz with 5 mm of marker noise.
    "coupled30": ("coupled", 30.0, 0.005, 1.0, None, 0.26),
}
CASE_KINDS: tuple[str, ...] = tuple(k for k in _CASES if not k.startswith("coupled"))
COUPLED_KINDS: tuple[str, ...] = ("coupled", "coupled30")
# The mocap suit's artefacts in the coupled cases (per hand, per s): frozen stretches (the
# tracker repeating its last sample) and one-sample glitches of 1.5-7 cm.
_COUPLED_FROZEN_PER_S = 0.5
_COUPLED_GLITCHES_PER_S = 0.3


def case_set(kind: CaseKind, n: int = 12, seed: int = 0) -> list[SyntheticHandover]:
    """``n`` recordings of one of issue 20's failing cases (:data:`CASE_KINDS`): ``carry``,
    ``still``, ``quick30`` or ``quick_noisy``, or of issue 33's (:data:`COUPLED_KINDS`):
    ``coupled`` (120 Hz) or ``coupled30`` (30 Hz, 5 mm noise), these with frozen samples and
    one-sample glitches (see the module docstring); both postures, with the marker offsets of
    real motion capture."""
    if kind not in _CASES:
        raise ValueError(f"kind must be one of {list(_CASES)}, got {kind!r}")
    hold, rate, noise, speed, hold_time, offset = _CASES[kind]
    coupled = kind in COUPLED_KINDS
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        opts = SyntheticOptions(
            rate=rate,
            irregular=0.1,
            noise=noise,
            posture="standing" if i % 2 == 0 else "sitting",
            speed=speed * float(rng.uniform(0.9, 1.1)),
            hold=hold,
            hold_time=hold_time,
            marker_offset=offset + float(rng.uniform(-0.03, 0.03)) * (0.3 if coupled else 1.0),
            # (issue 33's receivers are people in the same mocap suit: the same marker noise)
            gripper_noise=noise if coupled else SyntheticOptions.gripper_noise,
            frozen_per_s=_COUPLED_FROZEN_PER_S if coupled else 0.0,
            glitches_per_s=_COUPLED_GLITCHES_PER_S if coupled else 0.0,
        )
        out.append(generate(int(rng.integers(2**31)), opts))
    return out


# A resting giver's fidgets (rest_recording): minimum-jerk adjustments of this size (m) and
# duration (s), in any direction, half of them toward the receiver.
FIDGET_AMPLITUDE = (0.008, 0.02)
FIDGET_DURATION = (0.25, 0.6)


def rest_recording(
    rate: float,
    noise: float,
    seconds: float = 20.0,
    seed: int = 0,
    jitter: float = 0.3,
    fidget: bool = False,
) -> Trajectory:
    """A recording with no handover: the giver's hand at rest (0.4 cm of sway) under ``noise``
    (m) at ``rate`` (Hz, ``jitter`` relative sampling jitter), the robot's gripper at home.

    ``fidget``: small adjustments at rest, 0.8-2 cm (:data:`FIDGET_AMPLITUDE`) in 0.25-0.6 s
    (:data:`FIDGET_DURATION`; peak speed up to 0.15 m/s),
    in any direction, half of them toward the receiver; a handover detector must report
    nothing on either kind."""
    rng = np.random.default_rng(seed)
    n = int(seconds * rate)
    t = np.cumsum((1.0 / rate) * (1.0 + rng.uniform(-jitter, jitter, n)))
    sway = 0.004 * np.sin(2 * np.pi * 0.3 * t)[:, None] * np.array([1.0, 0.5, 0.3])
    g = np.array([1.05, -0.2, 0.9]) + sway + rng.normal(0.0, noise, (n, 3))
    if fidget:
        t0 = 1.0
        while t0 < seconds - 2.0:
            dur = rng.uniform(*FIDGET_DURATION)
            way = rng.normal(size=3)
            if rng.random() < 0.5:
                way[0] = -abs(way[0])  # toward the receiver (at -x)
            g += minimum_jerk((t - t0) / dur)[:, None] * (
                rng.uniform(*FIDGET_AMPLITUDE) * way / np.linalg.norm(way)
            )
            t0 += dur + rng.uniform(0.2, 1.0)
    r = np.array([0.35, -0.3, 0.25]) + rng.normal(0.0, 0.0003, (n, 3))
    return Trajectory(t, g, r)


def early_lift_set(n: int = 12, seed: int = 0) -> list[SyntheticHandover]:
    """``n`` recordings of issue 20's early movement: the giver lifts the object 1.5-2.5 s
    before the final approach and waits (120 Hz, 1.5 mm noise, marker offsets); the truth's
    reach is the final approach."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        opts = SyntheticOptions(
            rate=120.0,
            noise=0.0015,
            posture="standing" if i % 2 else "sitting",
            early_lift=float(rng.uniform(1.5, 2.5)),
            marker_offset=0.3,
        )
        out.append(generate(int(rng.integers(2**31)), opts))
    return out
