"""The robot's handover controller, like the seed's (sections 6.3.2 and 6.4.3): reach a predefined
handover pose once the giver starts, grasp when the object is close, retreat home after the giver
lets go (or right after grasping). The reach is a joint-space minimum-jerk move to the predefined
pose (the gaze studies' robot) or, given a
:class:`~gazebot.apps.sim.cartesian_reach.CartesianReach`,
one of the seed's Cartesian controllers (pv, mcj, mce, stl) toward the object in the giver's hand;
the retreat is a joint-space minimum-jerk move home (the seed's STL robot, 4.4.4: "the retreat
motion of the robot [was] commanded by another controller").

Table 4.2's whole task (the ``stl`` reach with an :class:`~gazebot.apps.controllers.stl_gripper.
STLGripper`): a giving robot given a ``pickup`` point starts with an open, empty gripper, goes to
the object (t_5) and grasps it (t_6) before its handover starts; a receiving robot given a
``dropoff`` point carries the object there (t_3), opens its gripper (t_4), leaves the object and
returns home. In these scenes the transfer's grasp (t_2) and release (t_8) are synthesized by the
same gripper; elsewhere the gripper closes or opens over ``gripper_close_s``."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import TYPE_CHECKING

import numpy as np

from gazebot.apps.controllers.stl_gripper import STLGripper
from gazebot.apps.sim.cartesian_reach import CartesianReach
from gazebot.apps.sim.motion import PEAK_RATE, MinJerkSegment
from gazebot.apps.sim.scene_config import ControllerConfig, RetreatTrigger
from gazebot.core.types import Event, EventKind

if TYPE_CHECKING:
    from gazebot.apps.sim.policy_reach import PolicyReach

# An infeasible reach whose arm has stood still this long (s) has given up: the handover is over
# ("If no feasible control input is found, the robot stops", the seed's STL reach).
GIVE_UP_AFTER_S = 1.0


class ControllerState(str, Enum):
    PICKING_UP = "picking_up"  # giver with a pick-up: going to the object (t_5)
    PICK_GRASPING = "pick_grasping"  # closing on the object at the pick-up (t_6)
    WAITING = "waiting"  # at home, watching for the giver to start
    REACHING = "reaching"
    AT_HANDOVER = "at_handover"  # waiting for the object to come close
    GRASPING = "grasping"  # closing the gripper
    RELEASING = "releasing"  # robot-to-human: opening the gripper
    HOLDING = "holding"  # grasped; waiting for the giver to let go
    CARRYING = "carrying"  # receiver with a drop-off: taking the object there (t_3)
    DROPPING = "dropping"  # opening the gripper at the drop-off (t_4)
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
    #: The robot's load share alpha_r (0..1), a gripper force sensor's reading (seed Table 4.1);
    #: None: not sensed. A receiver with a drop-off carries the object once it holds it alone.
    load_share: float | None = None


@dataclass(frozen=True)
class ArmCommand:
    arm: np.ndarray  # joint goals, rad, in the controller's joint order
    gripper: float  # 0 open .. 1 closed
    torque: np.ndarray | None = None  # N m: a torque-level reach's command (None: go to arm)


class HandoverController:
    """Position-level handover controller for the arm and gripper.

    Args:
        home: Arm joint positions at home (rad).
        handover: Arm joint positions at the predefined handover pose (rad).
        config: Trigger distances and motion timing.
        reach: A Cartesian reach controller on the arm, or the learned policy's torque-level
            reach (:class:`~gazebot.apps.sim.policy_reach.PolicyReach`); None: the joint-space move.
        start_at: Start the handover at this time (s) instead of on the giver's motion
            (robot-initiated handovers).
        target: The predefined handover location (m), for ``predetermined`` STL strategies.
        giver: The robot hands the object over (robot-to-human): it starts holding it, reaches,
            opens the gripper once the person's hand is at the object (seed 3.3.4: "The robot
            released the vial if the human's hand was within a certain distance from the robot's
            gripper") and retreats once it has let go. ``Sensed.object_gap`` is then the
            distance from the object to the person's hand.
        pickup: A giver's pick-up point (m): the object starts there, the robot picks it up
            first (needs ``reach`` and ``gripper``).
        dropoff: A receiver's drop-off point (m): the robot carries the object there and lets
            go of it (needs ``reach`` and ``gripper``).
        gripper: The synthesized gripper of Table 4.2's grasp and release at the pick-up and
            the drop-off.
    """

    def __init__(
        self,
        home: np.ndarray,
        handover: np.ndarray,
        config: ControllerConfig,
        reach: CartesianReach | PolicyReach | None = None,
        start_at: float | None = None,
        target: np.ndarray | None = None,
        giver: bool = False,
        pickup: np.ndarray | None = None,
        dropoff: np.ndarray | None = None,
        gripper: STLGripper | None = None,
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
        # The seed's STL reach: "If no feasible control input is found, the robot stops." Since
        # when the latest plan is infeasible and the arm is commanded still (None otherwise).
        self.stopped_at: float | None = None
        self._plan_feasible = True
        self._last_t: float | None = None
        self._last_q = self.home.copy()
        self.pickup = None if pickup is None else np.asarray(pickup, float)
        self.dropoff = None if dropoff is None else np.asarray(dropoff, float)
        if (self.pickup is not None or self.dropoff is not None) and (
            reach is None or gripper is None
        ):
            raise ValueError("a pick-up or drop-off needs a Cartesian reach and a gripper")
        if self.pickup is not None and not self.giver:
            raise ValueError("only a giving robot picks the object up")
        if self.dropoff is not None and self.giver:
            raise ValueError("only a receiving robot has a drop-off")
        self.gripper_synth = gripper
        self._g_t0: float | None = None  # when the current gripper specification started
        self._g_next = -np.inf
        self._g_u = 0.0
        self.gripper_infeasible_at: float | None = None
        self.dropped = False  # the object was left at the drop-off
        self._last_tick_dt: float | None = None
        self._torque: np.ndarray | None = None  # this tick's torque-level reach command
        if self.pickup is not None:
            self.state = ControllerState.PICKING_UP
            self._gripper = 0.0  # open, empty

    def planned_duration(self, start: np.ndarray, goal: np.ndarray, minimum: float) -> float:
        """Duration of a minimum-jerk move whose fastest joint peaks at the speed limit."""
        v_max = np.deg2rad(self.config.max_joint_speed_deg)
        return float(max(minimum, PEAK_RATE * np.max(np.abs(goal - start)) / v_max))

    def gave_up(self, t: float) -> bool:
        """Whether the robot has given up the handover at time ``t``: its reach has been
        infeasible and the arm still for :data:`GIVE_UP_AFTER_S` (a controller that finds a
        feasible plan again moves on, and has not given up)."""
        return self.stopped_at is not None and t - self.stopped_at >= GIVE_UP_AFTER_S - 1e-9

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
        self._torque = step.torque
        if step.plan is not None and not step.plan.feasible and self.infeasible_at is None:
            self.infeasible_at = t
            self._emit(
                EventKind.ROBOT_REACH_INFEASIBLE,
                t,
                reach_time=float(self.reach.controller.config.reach_time_s),
                since_start=float(self.reach.elapsed(t)),
            )
        if step.plan is not None:
            self._plan_feasible = bool(step.plan.feasible)
        still = float(np.linalg.norm(step.velocity)) <= 1e-9
        if self._plan_feasible or not still:
            self.stopped_at = None  # a feasible plan again, or moving: not given up
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
            if self._gripper_synthesized(t, release=True):  # t_8
                released = True
            elif self.gripper_synth is not None:
                released = False
            else:
                self._gripper = max(0.0, 1.0 - (t - self._grasp_t0) / cfg.gripper_close_s)
                released = self._gripper <= 0.0
            if released:
                self._emit(EventKind.ROBOT_RELEASED, t)
                start = self.reach.hold() if self.reach is not None else self._last_q
                duration = self._move(t, start, self.home, cfg.retreat_min_duration_s)
                self._emit(EventKind.ROBOT_RETREAT_STARTED, t, planned_duration=duration)
                s = ControllerState.RETREATING
        return s

    def _gripper_tick(self, t: float, dt: float, goal: float, within_s: float) -> bool:
        """One tick of the synthesized gripper toward openness ``goal`` within ``within_s`` of
        this specification's start; True once ``|g_r - goal| < eps_g``."""
        g = self.gripper_synth
        assert g is not None
        if self._g_t0 is None:
            g.reset()
            self._g_t0, self._g_next = t, t
        if t + 1e-9 >= self._g_next:
            plan = g.plan(t - self._g_t0, 1.0 - self._gripper, goal, True, within_s)
            self._g_u = plan.command
            if not plan.feasible and self.gripper_infeasible_at is None:
                self.gripper_infeasible_at = t  # it stops ("the robot stops", 4.4.1)
            self._g_next += g.dt
        self._gripper = float(np.clip(self._gripper - self._g_u * dt, 0.0, 1.0))
        return abs((1.0 - self._gripper) - goal) < g.stl.eps_g

    def _gripper_synthesized(self, t: float, release: bool) -> bool:
        """With the STL gripper: one tick of the transfer's grasp (t_2, to ``g*``) or release
        (t_8, open); True once met. Without it: False (the ramp of ``gripper_close_s`` runs)."""
        if self.gripper_synth is None:
            return False
        assert self.reach is not None and self._last_tick_dt is not None
        stl = self.reach.controller.config.stl
        goal = 1.0 if release else stl.grip_width
        if self._gripper_tick(t, self._last_tick_dt, goal, stl.transfer_time_s):
            self._gripper_done()
            return True
        return False

    def _gripper_done(self) -> None:
        self._g_t0, self._g_u = None, 0.0

    def _holds_alone(self, sensed: Sensed) -> bool:
        """``o == o_r`` from the load share (Table 4.1 with a force sensor: ``alpha_r >
        delta_2``): the t_3 carry starts when its specification's trigger holds."""
        assert self.reach is not None and sensed.load_share is not None
        return sensed.load_share > self.reach.controller.config.stl.delta_2

    def _gap_to(self, q: np.ndarray, point: np.ndarray) -> float:
        """Gripper-site distance (m) to ``point`` at arm joints ``q``."""
        assert self.reach is not None
        return float(np.linalg.norm(self.reach.ik.pose(q).translation - point))

    def _pick_up(self, t: float, dt: float, q: np.ndarray, s: ControllerState):
        """Giver with a pick-up: to the object (t_5), then grasp it (t_6); returns the state
        and the arm goal."""
        assert self.reach is not None and self.pickup is not None
        stl = self.reach.controller.config.stl
        if not self.reach.started:
            self.reach.start(t, q)
        if s is ControllerState.PICKING_UP:
            step = self.reach.update(
                t, dt, self.pickup, object_free=True, object_position=self.pickup
            )
            if self._gap_to(q, self.pickup) <= self.config.grasp_distance_m:
                s = ControllerState.PICK_GRASPING
            return s, step.q
        if self._gripper_tick(t, dt, stl.grip_width, stl.pickup_grasp_time_s):
            self._gripper_done()
            s = ControllerState.WAITING  # holds it: the handover can start
        return s, self.reach.hold()

    def _drop_off(self, t: float, dt: float, q: np.ndarray, s: ControllerState):
        """Receiver with a drop-off: carry the object there (t_3), open (t_4), go home."""
        assert self.reach is not None and self.dropoff is not None
        stl = self.reach.controller.config.stl
        if s is ControllerState.CARRYING:
            step = self.reach.update(
                t, dt, self.dropoff, robot_holds_object=True, dropoff=self.dropoff
            )
            if self._gap_to(q, self.dropoff) <= self.config.grasp_distance_m:
                s = ControllerState.DROPPING
            return s, step.q
        if self._gripper_tick(t, dt, 1.0, stl.release_time_s):
            self._gripper_done()
            self.dropped = True
            self._emit(EventKind.ROBOT_RELEASED, t)
            self._move(t, self.reach.hold(), self.home, self.config.retreat_min_duration_s)
            return ControllerState.RETREATING, None
        return s, self.reach.hold()

    def update(self, t: float, q: np.ndarray, sensed: Sensed) -> ArmCommand:
        """Advance to time ``t`` (s) with the measured arm joints ``q`` (rad)."""
        cfg, s = self.config, self.state
        dt = 0.0 if self._last_t is None else max(0.0, t - self._last_t)
        self._last_t = t
        self._last_tick_dt = dt
        self._last_q = np.asarray(q, float)
        self._torque = None
        arm_goal: np.ndarray | None = None
        if self._hand0 is None and np.all(np.isfinite(sensed.giver_hand)):
            self._hand0 = sensed.giver_hand.copy()
        if s in (ControllerState.PICKING_UP, ControllerState.PICK_GRASPING):
            s, arm_goal = self._pick_up(t, dt, self._last_q, s)
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
            if self._gripper_synthesized(t, release=False):  # t_2
                grasped = True
            elif self.gripper_synth is not None:
                grasped = False
            else:
                self._gripper = min(1.0, (t - self._grasp_t0) / cfg.gripper_close_s)
                grasped = self._gripper >= 1.0
            if grasped:
                self._emit(EventKind.ROBOT_GRASPED, t)
                s = ControllerState.HOLDING
        retreat_now = (
            s is ControllerState.HOLDING
            and not self.giver
            and (
                cfg.retreat is RetreatTrigger.AFTER_GRASP
                or (
                    self._holds_alone(sensed)
                    if self.dropoff is not None and sensed.load_share is not None
                    else sensed.hand_object_gap >= cfg.release_trigger_m
                )
            )
        )
        if retreat_now and self.dropoff is not None:
            self._emit(EventKind.ROBOT_RETREAT_STARTED, t, planned_duration=0.0)
            s = ControllerState.CARRYING
        elif retreat_now:
            start = self.reach.hold() if self.reach is not None else q
            duration = self._move(t, start, self.home, cfg.retreat_min_duration_s)
            self._emit(EventKind.ROBOT_RETREAT_STARTED, t, planned_duration=duration)
            s = ControllerState.RETREATING
        if s in (ControllerState.CARRYING, ControllerState.DROPPING):
            s, arm_goal = self._drop_off(t, dt, self._last_q, s)
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
        reaching = s in (ControllerState.REACHING, ControllerState.AT_HANDOVER)
        torque = self._torque if reaching else None
        return ArmCommand(arm=arm_goal, gripper=self._gripper, torque=torque)

    @property
    def grasped(self) -> bool:
        """Whether the robot's gripper holds the object."""
        if self.dropped:
            return False
        if self.giver:
            return self.state in (
                ControllerState.WAITING,
                ControllerState.REACHING,
                ControllerState.AT_HANDOVER,
                ControllerState.RELEASING,
            )
        return self.state in (
            ControllerState.HOLDING,
            ControllerState.CARRYING,
            ControllerState.DROPPING,
            ControllerState.RETREATING,
            ControllerState.DONE,
        )

    @property
    def picking_up(self) -> bool:
        """A giver before it has grasped the object at the pick-up."""
        return self.state in (ControllerState.PICKING_UP, ControllerState.PICK_GRASPING)
