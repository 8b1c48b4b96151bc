"""The robot's handover controller, like the seed's (sections 6.3.2 and 6.4.3): reach a predefined
handover pose once the giver starts, grasp when the object is close, retreat home after the giver
lets go. Arm motions are joint-space minimum-jerk moves (the seed's MCJ idea, section 3.2.1)."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from gazebot.sim.motion import PEAK_RATE, MinJerkSegment
from gazebot.sim.scene_config import ControllerConfig
from gazebot.types import Event, EventKind


class ControllerState(str, Enum):
    WAITING = "waiting"  # at home, watching for the giver to start
    REACHING = "reaching"
    AT_HANDOVER = "at_handover"  # waiting for the object to come close
    GRASPING = "grasping"  # closing the gripper
    HOLDING = "holding"  # grasped; waiting for the giver to let go
    RETREATING = "retreating"
    DONE = "done"


@dataclass(frozen=True)
class Sensed:
    """What the controller senses each tick (base frame, m).

    ``giver_hand`` stands in for the seed's range sensor (start of the handover), ``object_gap``
    for the gripper's proximity sensor (distance object to gripper site) and ``hand_object_gap``
    tells whether the giver still holds the object.
    """

    giver_hand: np.ndarray
    object_gap: float
    hand_object_gap: float


@dataclass(frozen=True)
class ArmCommand:
    arm: np.ndarray  # joint goals, rad, in the controller's joint order
    gripper: float  # 0 open .. 1 closed


class HandoverController:
    """Position-level handover controller for the arm and gripper.

    Args:
        home: Arm joint positions at home (rad).
        handover: Arm joint positions at the predefined handover pose (rad).
        config: Trigger distances and motion timing.
    """

    def __init__(self, home: np.ndarray, handover: np.ndarray, config: ControllerConfig) -> None:
        self.home = np.asarray(home, float)
        self.handover = np.asarray(handover, float)
        if self.home.shape != self.handover.shape:
            raise ValueError("home and handover poses need the same joints")
        self.config = config
        self.state = ControllerState.WAITING
        self._segment: MinJerkSegment | None = None
        self._hand0: np.ndarray | None = None
        self._grasp_t0 = np.nan
        self._gripper = 0.0
        self._events: list[Event] = []

    def planned_duration(self, start: np.ndarray, goal: np.ndarray, minimum: float) -> float:
        """Duration of a minimum-jerk move whose fastest joint peaks at the speed limit."""
        v_max = np.deg2rad(self.config.max_joint_speed_deg)
        return float(max(minimum, PEAK_RATE * np.max(np.abs(goal - start)) / v_max))

    def pop_events(self) -> list[Event]:
        """Robot events since the last call, oldest first."""
        out, self._events = self._events, []
        return out

    def _emit(self, kind: EventKind, t: float, **info: float) -> None:
        self._events.append(Event(kind=kind, t=t, detected_at=t, info=dict(info)))

    def _move(self, t: float, q: np.ndarray, goal: np.ndarray, minimum: float) -> float:
        duration = self.planned_duration(q, goal, minimum)
        self._segment = MinJerkSegment(q.copy(), goal.copy(), t, duration)
        return duration

    def update(self, t: float, q: np.ndarray, sensed: Sensed) -> ArmCommand:
        """Advance to time ``t`` (s) with the measured arm joints ``q`` (rad)."""
        cfg, s = self.config, self.state
        if self._hand0 is None and np.all(np.isfinite(sensed.giver_hand)):
            self._hand0 = sensed.giver_hand.copy()
        if s is ControllerState.WAITING and self._hand0 is not None:
            travel = float(np.linalg.norm(sensed.giver_hand - self._hand0))
            if np.isfinite(travel) and travel >= cfg.start_trigger_m:
                duration = self._move(t, q, self.handover, cfg.reach_min_duration_s)
                self._emit(EventKind.ROBOT_REACH_STARTED, t, planned_duration=duration)
                s = ControllerState.REACHING
        if s is ControllerState.REACHING and self._segment is not None and self._segment.done(t):
            self._emit(EventKind.ROBOT_REACH_ENDED, t)
            s = ControllerState.AT_HANDOVER
        if s is ControllerState.AT_HANDOVER and sensed.object_gap <= cfg.grasp_distance_m:
            self._grasp_t0 = t
            s = ControllerState.GRASPING
        if s is ControllerState.GRASPING:
            self._gripper = min(1.0, (t - self._grasp_t0) / cfg.gripper_close_s)
            if self._gripper >= 1.0:
                self._emit(EventKind.ROBOT_GRASPED, t)
                s = ControllerState.HOLDING
        if s is ControllerState.HOLDING and sensed.hand_object_gap >= cfg.release_trigger_m:
            duration = self._move(t, q, self.home, cfg.retreat_min_duration_s)
            self._emit(EventKind.ROBOT_RETREAT_STARTED, t, planned_duration=duration)
            s = ControllerState.RETREATING
        if s is ControllerState.RETREATING and self._segment is not None and self._segment.done(t):
            self._emit(EventKind.ROBOT_RETREAT_ENDED, t)
            s = ControllerState.DONE
        self.state = s
        goal = self._segment.position(t) if self._segment is not None else self.home
        return ArmCommand(arm=goal, gripper=self._gripper)

    @property
    def grasped(self) -> bool:
        return self.state in (
            ControllerState.HOLDING,
            ControllerState.RETREATING,
            ControllerState.DONE,
        )
