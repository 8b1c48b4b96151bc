"""The simulated human receiver of a robot-to-human handover (the seed's chapter 3 task: the robot
hands the object over, the person takes it). The hand reaches to the handover location with a
minimum-jerk motion, waits there for the object, takes it when the robot brings it close, holds
it while the robot lets go, and retreats with it. Durations are drawn like the giver's
(:class:`~gazebot.apps.sim.giver.GiverPlan`); ``transfer_s`` is how long the person holds the object
at the handover location after the robot has let go, before retreating."""

from __future__ import annotations

from dataclasses import replace
from enum import Enum

import numpy as np

from gazebot.apps.sim.giver import GiverPlan
from gazebot.apps.sim.motion import MinJerkSegment


class ReceiverState(str, Enum):
    IDLE = "idle"
    REACH = "reach"
    WAIT = "wait"  # at the handover location, empty hand
    SHARE = "share"  # holding the object together with the robot
    HOLD = "hold"  # the robot has let go
    RETREAT = "retreat"  # moving back with the object
    DONE = "done"


class SimulatedReceiver:
    """Moves the person's (empty, then full) hand between ``rest`` and ``offer`` (base frame, m).

    The same motion interface as :class:`~gazebot.apps.sim.giver.SimulatedGiver` (``hand``,
    ``state``, ``plan``, ``reach_started_at``, ``respond_at``), with
    :meth:`update` ``(t, object_near, robot_released)``.

    Args:
        rest: Hand position before and after the handover.
        offer: Hand position that takes the object at the handover location.
        plan: Timing of this handover.
        cued: Wait for :meth:`respond_at` (the person responds to the robot's reach).
    """

    def __init__(
        self, rest: np.ndarray, offer: np.ndarray, plan: GiverPlan, cued: bool = True
    ) -> None:
        self.rest = np.asarray(rest, float)
        self.offer = np.asarray(offer, float)
        self.plan = plan
        self.state = ReceiverState.IDLE
        self.hand = self.rest.copy()
        self.reach_started_at: float | None = None
        self.took_at: float | None = None
        self._segment: MinJerkSegment | None = None
        self._hold_end = np.inf
        self._cued = cued

    def respond_at(self, t: float) -> None:
        """Start the reach at ``t`` (s) if it has not started."""
        if self.state is ReceiverState.IDLE:
            self.plan = replace(self.plan, start_t=float(t))
            self._cued = False

    @property
    def holds_object(self) -> bool:
        """True from taking the object on."""
        return self.state in (
            ReceiverState.SHARE,
            ReceiverState.HOLD,
            ReceiverState.RETREAT,
            ReceiverState.DONE,
        )

    def update(self, t: float, object_near: bool, robot_released: bool) -> None:
        """Advance to ``t`` (s); ``object_near``: the object is within the hand's grasp;
        ``robot_released``: the robot's gripper has let go of it."""
        p = self.plan
        if self.state is ReceiverState.IDLE and not self._cued and t >= p.start_t:
            self._segment = MinJerkSegment(self.rest, self.offer, p.start_t, p.reach_s)
            self.state = ReceiverState.REACH
            self.reach_started_at = p.start_t
        if (
            self.state is ReceiverState.REACH
            and self._segment is not None
            and self._segment.done(t)
        ):
            self.state = ReceiverState.WAIT
        # The hand closes on the object as soon as it is within reach (even mid-reach).
        if self.state in (ReceiverState.REACH, ReceiverState.WAIT) and object_near:
            self.took_at = t
            self._segment = None  # the hand stops where it took the object
            self.state = ReceiverState.SHARE
        if self.state is ReceiverState.SHARE and robot_released:
            self._hold_end = t + p.transfer_s
            self.state = ReceiverState.HOLD
        if self.state is ReceiverState.HOLD and t >= self._hold_end:
            self._segment = MinJerkSegment(self.hand.copy(), self.rest, t, p.retreat_s)
            self.state = ReceiverState.RETREAT
        if (
            self.state is ReceiverState.RETREAT
            and self._segment is not None
            and self._segment.done(t)
        ):
            self.state = ReceiverState.DONE
        if self._segment is not None:
            self.hand = self._segment.position(t)

    def hand_velocity(self, t: float) -> np.ndarray:
        """The hand's velocity at ``t`` (m/s) along the current motion."""
        if self._segment is None or self.state not in (ReceiverState.REACH, ReceiverState.RETREAT):
            return np.zeros(3)
        return self._segment.velocity(t)
