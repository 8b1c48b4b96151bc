"""A recorded giver in the simulator: real human hand (and face) motion, retargeted to the scene.

The recording is split into phases with the default phase method; its first handover drives
the replay. The recorded hand is mapped into the robot's base frame by a yaw rotation, a uniform
scale and a translation chosen so that the recorded hand at rest (reach start) lands on the
scene's ``rest`` and the recorded hand at the transfer start lands on the robot's handover
location (``offer``); what the similarity map leaves over (the height difference) is blended in
along the reach by its progress, so both ends are met exactly. The retreat is mapped the same
way back toward ``rest``. The recorded face's motion since the reach start, rotated like the
hand (not scaled: a head keeps its size), moves the scene's face (:attr:`face_offset`), so the
tracked face stays on the rendered person.

Timing follows the recording, with the robot in the loop as :class:`SimulatedGiver` does: the
reach replays from ``plan.start_t`` (or :meth:`respond_at` when cued); the hand then holds at the
handover location until the robot grasps; the recorded transfer replays (``let_go`` cuts it
short), then the recorded retreat. Same interface as
:class:`~gazebot.apps.sim.giver.SimulatedGiver`, plus :attr:`face_offset`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gazebot.apps.sim.giver import GiverCues, GiverPlan, GiverState
from gazebot.core.phases import PhaseConfig, Trajectory, segment
from gazebot.core.types import Phase


class GiverMotionError(ValueError):
    """A recording that cannot drive the simulated giver (names the file and the problem)."""


@dataclass(frozen=True)
class RecordedHandover:
    """The part of a recording the replay uses (recording times, s; positions, m).

    Attributes:
        t: Sample times of the valid giver-hand samples.
        hand: Giver hand positions (N, 3).
        face: Giver face positions (N, 3), NaN rows when untracked.
        reach_start, transfer_start, transfer_end, retreat_end: The first handover's phases.
    """

    t: np.ndarray
    hand: np.ndarray
    face: np.ndarray
    reach_start: float
    transfer_start: float
    transfer_end: float
    retreat_end: float

    @classmethod
    def from_trajectory(
        cls, trajectory: Trajectory, source: str = "recording", config: PhaseConfig | None = None
    ) -> RecordedHandover:
        """The first handover of ``trajectory``.

        Raises:
            GiverMotionError: No complete reach -> transfer -> retreat in the recording.
        """
        traj, _, _ = trajectory.cleaned()
        segs = segment(traj, config or PhaseConfig())
        first = [s for s in segs if s.handover == (segs[0].handover if segs else 0)]
        phases = [s.phase for s in first]
        if phases != [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]:
            found = " -> ".join(p.value for p in phases) or "no handover"
            raise GiverMotionError(
                f"{source}: needs a whole handover (reach -> transfer -> retreat), found {found}"
            )
        ok = np.isfinite(traj.giver_hand).all(axis=1)
        if np.count_nonzero(ok) < 4:
            raise GiverMotionError(f"{source}: fewer than 4 giver-hand samples")
        return cls(
            t=traj.t[ok],
            hand=traj.giver_hand[ok],
            face=traj.giver_face[ok],
            reach_start=first[0].start,
            transfer_start=first[1].start,
            transfer_end=first[1].end,
            retreat_end=first[2].end,
        )

    def hand_at(self, t: float) -> np.ndarray:
        """The recorded hand at recording time ``t`` (linear between samples, held at the ends)."""
        return np.array([np.interp(t, self.t, self.hand[:, k]) for k in range(3)])

    def face_at(self, t: float) -> np.ndarray | None:
        """The recorded face at ``t``, or ``None`` when the recording has no face."""
        ok = np.isfinite(self.face).all(axis=1)
        if np.count_nonzero(ok) < 2:
            return None
        return np.array([np.interp(t, self.t[ok], self.face[ok, k]) for k in range(3)])


def _yaw(v: np.ndarray) -> float:
    return math.atan2(float(v[1]), float(v[0]))


class _Retarget:
    """Recorded frame -> robot base frame for one motion from ``a_rec`` to ``b_rec`` that must
    go from ``a`` to ``b`` (see the module docstring)."""

    def __init__(self, a_rec: np.ndarray, b_rec: np.ndarray, a: np.ndarray, b: np.ndarray):
        d_rec, d = b_rec - a_rec, b - a
        horiz = np.hypot(d_rec[0], d_rec[1]) > 1e-6 and np.hypot(d[0], d[1]) > 1e-6
        psi = _yaw(d) - _yaw(d_rec) if horiz else 0.0
        c, s = math.cos(psi), math.sin(psi)
        self.rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        n_rec = float(np.linalg.norm(d_rec))
        self.scale = float(np.linalg.norm(d)) / n_rec if n_rec > 1e-6 else 1.0
        self.a_rec, self.a, self.b_rec = a_rec, a, b_rec
        self.residual = b - self.map(b_rec, blend=False)
        self.length = max(n_rec, 1e-6)

    def map(self, p: np.ndarray, blend: bool = True) -> np.ndarray:
        out = self.a + self.scale * (self.rot @ (p - self.a_rec))
        if blend:
            w = min(max(float(np.linalg.norm(p - self.a_rec)) / self.length, 0.0), 1.0)
            out = out + w * self.residual
        return out

    def face_motion(self, f: np.ndarray, f0: np.ndarray) -> np.ndarray:
        """The face's displacement from ``f0``, rotated into the base frame (m)."""
        return self.rot @ (f - f0)


class ReplayedGiver(GiverCues):
    """A recorded giver's hand (and face) in the simulator (see the module docstring).

    Args:
        recording: The recorded handover.
        rest: Scene hand position before and after the handover (m, base frame).
        offer: The robot's handover location (m, base frame).
        plan: Start time of the reach (``plan.start_t``); durations come from the recording.
        cued: Wait for :meth:`respond_at` (robot-initiated handovers).
    """

    def __init__(
        self,
        recording: RecordedHandover,
        rest: np.ndarray,
        offer: np.ndarray,
        plan: GiverPlan,
        cued: bool = False,
    ) -> None:
        r = recording
        self.rec = r
        self.rest = np.asarray(rest, float)
        self.offer = np.asarray(offer, float)
        self.plan = plan
        self.state = GiverState.IDLE
        self.hand = self.rest.copy()
        self.released_at: float | None = None
        self.reach_started_at: float | None = None
        self._cued = cued
        rest_rec = r.hand_at(r.reach_start)
        offer_rec = r.hand_at(r.transfer_start)
        release_rec = r.hand_at(r.transfer_end)
        back_rec = r.hand_at(r.retreat_end)
        self._reach = _Retarget(rest_rec, offer_rec, self.rest, self.offer)
        # The retreat starts where the transfer left the hand and ends back at rest.
        self._retreat = _Retarget(back_rec, release_rec, self.rest, self.offer)
        self._offset = math.nan  # sim time - recording time, for the current stretch
        self._share_end = math.inf
        self._prev: tuple[float, np.ndarray] | None = None
        self._vel = np.zeros(3)
        self._face0 = r.face_at(r.reach_start)
        # The face's displacement from where it was at the reach start (m, base frame); the
        # simulation adds it to the scene's face. Zero when the recording has no face.
        self.face_offset = np.zeros(3)

    def update(self, t: float, robot_grasped: bool) -> None:
        """Advance to time ``t`` (s); ``robot_grasped`` is whether the robot holds the object."""
        r = self.rec
        if self.state is GiverState.IDLE and not self._cued and t >= self.plan.start_t:
            self.state = GiverState.REACH
            self.reach_started_at = self.plan.start_t
            self._offset = self.plan.start_t - r.reach_start
        if self.state is GiverState.REACH and t - self._offset >= r.transfer_start:
            self.state = GiverState.OFFER
        if self.state is GiverState.OFFER and robot_grasped:
            self.state = GiverState.SHARE
            self._offset = t - r.transfer_start
            self._share_end = t + (r.transfer_end - r.transfer_start)
        if self.state is GiverState.SHARE and t >= self._share_end:
            self.state = GiverState.RETREAT
            self.released_at = t
            self._offset = t - r.transfer_end
        if self.state is GiverState.RETREAT and t - self._offset >= r.retreat_end:
            self.state = GiverState.DONE
        hand, face = self._pose(t)
        if self._prev is not None and t > self._prev[0]:
            self._vel = (hand - self._prev[1]) / (t - self._prev[0])
        self._prev = (t, hand)
        self.hand = hand
        if face is not None and self._face0 is not None:
            self.face_offset = self._reach.face_motion(face, self._face0)

    def _pose(self, t: float) -> tuple[np.ndarray, np.ndarray | None]:
        """Hand (base frame) and recorded face (recording frame, ``None``: keep) at ``t``."""
        r = self.rec
        st = self.state
        if st is GiverState.IDLE:
            return self.rest.copy(), None
        if st is GiverState.OFFER:
            return self.offer.copy(), None
        tr = t - self._offset
        if st is GiverState.REACH:
            return self._reach.map(r.hand_at(tr)), r.face_at(tr)
        if st is GiverState.SHARE:
            # Both hold the object: the recorded hand's drift during the hold, about the offer.
            drift = r.hand_at(tr) - r.hand_at(r.transfer_start)
            return self.offer + self._reach.rot @ drift, r.face_at(tr)
        tr = min(tr, r.retreat_end)
        return self._retreat.map(r.hand_at(tr)), r.face_at(tr)

    def hand_velocity(self, t: float) -> np.ndarray:
        """The hand's velocity (m/s), from the last two updates."""
        if self.state in (GiverState.IDLE, GiverState.OFFER, GiverState.DONE):
            return np.zeros(3)
        return self._vel.copy()


GiverFactory = Callable[[np.ndarray, np.ndarray, GiverPlan, bool], ReplayedGiver]


def replay_factory(recording: RecordedHandover) -> GiverFactory:
    """A ``giver_factory`` for :class:`~gazebot.apps.sim.simulation.HandoverSimulation`."""

    def make(rest: np.ndarray, offer: np.ndarray, plan: GiverPlan, cued: bool) -> ReplayedGiver:
        return ReplayedGiver(recording, rest, offer, plan, cued=cued)

    return make


def load_giver_motion(
    path: str,
    giver_hand: str | None = None,
    receiver_hand: str | None = None,
    giver_face: str | None = None,
    unit: str | None = None,
    rate: float | None = None,
) -> GiverFactory:
    """Read a recording (any format of :mod:`gazebot.io.recordings`) and return the factory that
    replays its first handover.

    Raises:
        RecordingError: The file cannot be read or a name is wrong.
        GiverMotionError: The recording holds no whole handover.
    """
    from gazebot.io.recordings import PointNames, RecordingError, load_recording

    rec = load_recording(path, PointNames(giver_hand, receiver_hand, giver_face), unit, rate)
    try:
        handover = RecordedHandover.from_trajectory(rec.trajectory, rec.source)
    except GiverMotionError as exc:
        raise RecordingError(path, str(exc).split(": ", 1)[-1]) from None
    return replay_factory(handover)
