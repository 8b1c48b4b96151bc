"""The simulated giver: reaches toward the handover location with a minimum-jerk, bell-shaped hand
motion, offers the object until the robot grasps it, shares it for the transfer, lets go and
retreats (seed sections 2.3.2 and 6.2). Durations are drawn from the seed's human-human phase
durations (``GiverConfig``), so every seed gives a slightly different, human-like handover."""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import Enum

import numpy as np

from gazebot.apps.sim.motion import MinJerkSegment
from gazebot.apps.sim.scene_config import GiverConfig


class GiverState(str, Enum):
    IDLE = "idle"
    REACH = "reach"
    OFFER = "offer"  # at the handover location, waiting for the robot's grasp
    SHARE = "share"  # both hold the object (transfer)
    RETREAT = "retreat"  # has let go, moving back
    DONE = "done"


@dataclass(frozen=True)
class GiverPlan:
    """The giver's timing for one handover, drawn once from the scene's distributions."""

    start_t: float
    reach_s: float
    transfer_s: float
    retreat_s: float

    @classmethod
    def draw(cls, cfg: GiverConfig, rng: np.random.Generator) -> GiverPlan:
        jitter = rng.uniform(-cfg.start_jitter_s, cfg.start_jitter_s) if cfg.start_jitter_s else 0.0
        return cls(
            start_t=max(0.0, cfg.start_delay_s + jitter),
            reach_s=cfg.reach.sample(rng),
            transfer_s=cfg.transfer.sample(rng),
            retreat_s=cfg.retreat.sample(rng),
        )


class GiverCues:
    """What the simulation asks of any giver, simulated or replayed: answer a robot-initiated
    handover, let go early, tell whether it still holds the object. Subclasses keep ``state``,
    ``plan``, ``_cued`` and ``_share_end``."""

    state: GiverState
    plan: GiverPlan
    _cued: bool
    _share_end: float

    def respond_at(self, t: float) -> None:
        """Start the reach at ``t`` (s) if it has not started: the giver answering a
        robot-initiated handover (a ``cued`` giver waits for this call)."""
        if self.state is GiverState.IDLE:
            self.plan = replace(self.plan, start_t=float(t))
            self._cued = False

    def let_go(self, t: float) -> None:
        """End the transfer now (the robot pulls the object away right after grasping it)."""
        if self.state is GiverState.SHARE:
            self._share_end = min(self._share_end, float(t))

    @property
    def holds_object(self) -> bool:
        """True until the giver lets go (at the end of the transfer)."""
        return self.state not in (GiverState.RETREAT, GiverState.DONE)


class SimulatedGiver(GiverCues):
    """Moves the giver's hand between ``rest`` and ``offer`` (base frame, m).

    Args:
        rest: Hand position holding the object before and after the handover.
        offer: Hand position when offering the object at the handover location.
        plan: Timing of this handover.
        cued: Wait for :meth:`respond_at` instead of starting at ``plan.start_t``
            (robot-initiated handovers).
    """

    def __init__(
        self, rest: np.ndarray, offer: np.ndarray, plan: GiverPlan, cued: bool = False
    ) -> None:
        self.rest = np.asarray(rest, float)
        self.offer = np.asarray(offer, float)
        self.plan = plan
        self.state = GiverState.IDLE
        self._segment: MinJerkSegment | None = None
        self._share_end = np.inf
        self.hand = self.rest.copy()
        self.released_at: float | None = None
        self.reach_started_at: float | None = None
        self._cued = cued

    def update(self, t: float, robot_grasped: bool) -> None:
        """Advance to time ``t`` (s); ``robot_grasped`` is whether the robot holds the object."""
        p = self.plan
        if self.state is GiverState.IDLE and not self._cued and t >= p.start_t:
            self._segment = MinJerkSegment(self.rest, self.offer, p.start_t, p.reach_s)
            self.state = GiverState.REACH
            self.reach_started_at = p.start_t
        if self.state is GiverState.REACH and self._segment is not None and self._segment.done(t):
            self.state = GiverState.OFFER
        if self.state is GiverState.OFFER and robot_grasped:
            self._share_end = t + p.transfer_s
            self.state = GiverState.SHARE
        if self.state is GiverState.SHARE and t >= self._share_end:
            self.released_at = t
            self._segment = MinJerkSegment(self.hand.copy(), self.rest, t, p.retreat_s)
            self.state = GiverState.RETREAT
        if self.state is GiverState.RETREAT and self._segment is not None and self._segment.done(t):
            self.state = GiverState.DONE
        if self._segment is not None:
            self.hand = self._segment.position(t)

    def hand_velocity(self, t: float) -> np.ndarray:
        """The hand's velocity at ``t`` (m/s) along the current motion."""
        if self._segment is None or self.state in (GiverState.OFFER, GiverState.SHARE):
            return np.zeros(3)
        return self._segment.velocity(t)
