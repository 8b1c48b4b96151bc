"""The robot's handover controller, like the seed's (sections 6.3.2 and 6.4.3): reach a predefined
handover pose once the giver starts, grasp when the object is close, retreat home after the giver
lets go (or right after grasping). The reach is a joint-space minimum-jerk move to the predefined
pose (the gaze studies' robot) or, given a :class:`~gazebot.sim.cartesian_reach.CartesianReach`,
one of the seed's Cartesian controllers (pv, mcj, mce, stl) toward the object in the giver's hand;
the retreat is a joint-space minimum-jerk move home (the seed's STL robot, 4.4.4: "the retreat
motion of the robot [was] commanded by another controller")."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from gazebot.sim.cartesian_reach import CartesianReach
from gazebot.sim.motion import PEAK_RATE, MinJerkSegment
from gazebot.sim.scene_config import ControllerConfig, RetreatTrigger
from gazebot.types import Event, EventKind


class ControllerState(str, Enum):
    WAITING = "waiting"  # at home, watching for the giver to start
    REACHING = "reaching"
    AT_HANDOVER = "at_handover"  # waiting for the object to come close
    GRASPING = "grasping"  # closing the gripper
    RELEASING = "releasing"  # robot-to-human: opening the gripper
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
    object_pos: np.ndarray | None = None  # where to take the object (Cartesian reaches)


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
        reach: A Cartesian reach controller on the arm (None: the joint-space move).
        start_at: Start the handover at this time (s) instead of on the giver's motion
            (robot-initiated handovers).
        target: The predefined handover location (m), for ``predetermined`` STL strategies.
        giver: The robot hands the object over (robot-to-human): it starts holding it, reaches,
            opens the gripper once the person's hand is at the object (seed 3.3.4: "The robot
            released the vial if the human's hand was within a certain distance from the robot's
            gripper") and retreats once it has let go. ``Sensed.object_gap`` is then the
            distance from the object to the person's hand.
    """

    def __init__(
        self,
        home: np.ndarray,
        handover: np.ndarray,
        config: ControllerConfig,
        reach: CartesianReach | None = None,
        start_at: float | None = None,
        target: np.ndarray | None = None,
        giver: bool = False,
    ) -> None:
        self.home = np.asarray(home, float)
        self.handover = np.asarray(handover, float)
        if self.home.shape != self.handover.shape:
            raise ValueError("home and handover poses need the same joints")
        self.config = config
        self.state = ControllerState.WAITING
        self._segment: MinJerkSegment | None = None
        self._hand0: np.ndarray | None = None
        self._grasp_t0 = np.nan
        self.giver = bool(giver)
        self._gripper = 1.0 if self.giver else 0.0
        self._events: list[Event] = []
        self.reach = reach
        self.start_at = start_at
        self.target = target
        self.handover_start: float | None = None  # the "handover's start" of the timing
        self.reach_started_at: float | None = None  # the robot's reach start (first motion)
        self.infeasible_at: float | None = None
        # The seed's STL reach: "If no feasible control input is found, the robot stops." Set
        # once the reach was infeasible and the arm is commanded still (None while it moves).
        self.stopped_at: float | None = None
        self._last_t: float | None = None
        self._last_q = self.home.copy()

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

    def _started(self, t: float, sensed: Sensed) -> bool:
        """The handover's start: the robot's own start time, else the giver's hand moving
        (the seed's range sensor)."""
        if self.start_at is not None:
            return t + 1e-9 >= self.start_at
        if self._hand0 is None:
            return False
        travel = float(np.linalg.norm(sensed.giver_hand - self._hand0))
        return np.isfinite(travel) and travel >= self.config.start_trigger_m

    def _cartesian(self, t: float, dt: float, sensed: Sensed) -> np.ndarray:
        """One tick of the Cartesian reach: events for motion start and infeasible timing."""
        assert self.reach is not None
        goal = sensed.object_pos if sensed.object_pos is not None else sensed.giver_hand
        if not np.all(np.isfinite(goal)):  # lost the hand: hold still
            return self.reach.hold()
        step = self.reach.update(t, dt, goal, target=self.target, robot_holds_object=self.grasped)
        if step.plan is not None and not step.plan.feasible and self.infeasible_at is None:
            self.infeasible_at = t
            self._emit(
                EventKind.ROBOT_REACH_INFEASIBLE,
                t,
                reach_time=float(self.reach.controller.config.reach_time_s),
                since_start=float(self.reach.elapsed(t)),
            )
        if self.infeasible_at is not None:
            still = float(np.linalg.norm(step.velocity)) <= 1e-9
            if not still:
                self.stopped_at = None
            elif self.stopped_at is None:
                self.stopped_at = t
        if self.reach_started_at is None and float(np.linalg.norm(step.velocity)) > 1e-6:
            self.reach_started_at = t
            left = self.reach.controller.config.reach_time_s - self.reach.elapsed(t)
            self._emit(EventKind.ROBOT_REACH_STARTED, t, planned_duration=max(0.0, left))
        return step.q

    def _giver_transfer(self, t: float, s: ControllerState, sensed: Sensed) -> ControllerState:
        """Robot-to-human: open the gripper once the person's hand is at the object, then
        retreat home ("within t_9 seconds after the human has received the object")."""
        cfg = self.config
        if s is ControllerState.AT_HANDOVER and sensed.object_gap <= cfg.grasp_distance_m:
            self._grasp_t0 = t
            s = ControllerState.RELEASING
        if s is ControllerState.RELEASING:
            self._gripper = max(0.0, 1.0 - (t - self._grasp_t0) / cfg.gripper_close_s)
            if self._gripper <= 0.0:
                self._emit(EventKind.ROBOT_RELEASED, t)
                start = self.reach.hold() if self.reach is not None else self._last_q
                duration = self._move(t, start, self.home, cfg.retreat_min_duration_s)
                self._emit(EventKind.ROBOT_RETREAT_STARTED, t, planned_duration=duration)
                s = ControllerState.RETREATING
        return s

    def update(self, t: float, q: np.ndarray, sensed: Sensed) -> ArmCommand:
        """Advance to time ``t`` (s) with the measured arm joints ``q`` (rad)."""
        cfg, s = self.config, self.state
        dt = 0.0 if self._last_t is None else max(0.0, t - self._last_t)
        self._last_t = t
        self._last_q = np.asarray(q, float)
        arm_goal: np.ndarray | None = None
        if self._hand0 is None and np.all(np.isfinite(sensed.giver_hand)):
            self._hand0 = sensed.giver_hand.copy()
        if s is ControllerState.WAITING and self._started(t, sensed):
            self.handover_start = t
            s = ControllerState.REACHING
            if self.reach is None:
                duration = self._move(t, q, self.handover, cfg.reach_min_duration_s)
                self.reach_started_at = t
                self._emit(EventKind.ROBOT_REACH_STARTED, t, planned_duration=duration)
            else:
                self.reach.start(t, q)
        if self.reach is not None and s in (ControllerState.REACHING, ControllerState.AT_HANDOVER):
            # The seed's controllers follow the hand until the grasp.
            arm_goal = self._cartesian(t, dt, sensed)
            if s is ControllerState.REACHING and sensed.object_gap <= cfg.grasp_distance_m:
                if self.reach_started_at is None:  # arrived without a planned motion
                    self.reach_started_at = t
                    self._emit(EventKind.ROBOT_REACH_STARTED, t, planned_duration=0.0)
                self._emit(EventKind.ROBOT_REACH_ENDED, t)
                s = ControllerState.AT_HANDOVER
        if s is ControllerState.REACHING and self._segment is not None and self._segment.done(t):
            self._emit(EventKind.ROBOT_REACH_ENDED, t)
            s = ControllerState.AT_HANDOVER
        if self.giver:
            s = self._giver_transfer(t, s, sensed)
        elif s is ControllerState.AT_HANDOVER and sensed.object_gap <= cfg.grasp_distance_m:
            self._grasp_t0 = t
            s = ControllerState.GRASPING
        if s is ControllerState.GRASPING:
            self._gripper = min(1.0, (t - self._grasp_t0) / cfg.gripper_close_s)
            if self._gripper >= 1.0:
                self._emit(EventKind.ROBOT_GRASPED, t)
                s = ControllerState.HOLDING
        retreat_now = (
            s is ControllerState.HOLDING
            and not self.giver
            and (
                cfg.retreat is RetreatTrigger.AFTER_GRASP
                or sensed.hand_object_gap >= cfg.release_trigger_m
            )
        )
        if retreat_now:
            start = self.reach.hold() if self.reach is not None else q
            duration = self._move(t, start, self.home, cfg.retreat_min_duration_s)
            self._emit(EventKind.ROBOT_RETREAT_STARTED, t, planned_duration=duration)
            s = ControllerState.RETREATING
        if s is ControllerState.RETREATING and self._segment is not None and self._segment.done(t):
            self._emit(EventKind.ROBOT_RETREAT_ENDED, t)
            s = ControllerState.DONE
        self.state = s
        if arm_goal is None:
            if self._segment is not None:
                arm_goal = self._segment.position(t)
            elif self.reach is not None and self.reach.started:
                arm_goal = self.reach.hold()
            else:
                arm_goal = self.home
        return ArmCommand(arm=arm_goal, gripper=self._gripper)

    @property
    def grasped(self) -> bool:
        """Whether the robot's gripper holds the object."""
        if self.giver:
            return self.state in (
                ControllerState.WAITING,
                ControllerState.REACHING,
                ControllerState.AT_HANDOVER,
                ControllerState.RELEASING,
            )
        return self.state in (
            ControllerState.HOLDING,
            ControllerState.RETREATING,
            ControllerState.DONE,
        )
