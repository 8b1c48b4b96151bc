"""``SimRobotDriver``: a :class:`gazebot.apps.sim.HandoverSimulation` in this process, no bus.

The simulation advances in lockstep with the engine: each :meth:`SimRobotDriver.wait_tracking`
steps it by one tracking period and returns the new sample, so a run is deterministic for a
seed and as fast as the CPU allows.
"""

from __future__ import annotations

import logging
import time
from collections import deque
from collections.abc import Mapping, Sequence
from typing import Protocol

import numpy as np

from gazebot.core.types import Event, TrackingFrame
from gazebot.io.drivers.base import RobotDriver
from gazebot.io.ros2 import convert
from gazebot.io.ros2.convert import RosCompressedImage
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.values import (
    ArmCommand,
    BusEvent,
    EyeState,
    JointGoal,
    JointState,
    NodeStatus,
)

log = logging.getLogger("gazebot.io.drivers")


class SimArm(Protocol):
    """The simulated robot's arm: its joints and named poses (rad, in ``arm_joints`` order)."""

    @property
    def arm_joints(self) -> Sequence[str]:
        """Arm joint names."""

    @property
    def home(self) -> np.ndarray:
        """The home pose (rad)."""

    @property
    def handover(self) -> np.ndarray:
        """The handover pose (rad)."""


class Simulation(Protocol):
    """What the drivers use of a simulation (:class:`gazebot.apps.sim.HandoverSimulation`)."""

    @property
    def robot(self) -> SimArm:
        """The simulated robot's arm."""

    @property
    def t(self) -> float:
        """Simulated time (s)."""

    @property
    def done(self) -> bool:
        """Whether the run is over (handover finished, or the robot stopped after an infeasible
        reach)."""

    def step(self, dt: float) -> None:
        """Advance the simulation by ``dt`` s."""

    def tracking(self) -> TrackingFrame:
        """The current tracking sample."""

    def joint_state(self) -> Mapping[str, float]:
        """The joint positions (rad or m) by name."""

    def robot_events(self) -> list[Event]:
        """The robot controller's events since the last call, oldest first."""

    def apply_head(self, joints: Mapping[str, float]) -> None:
        """Set head joint goals (rad); ``ValueError`` for an unknown joint or a non-finite value."""

    def apply_arm(self, joints: Mapping[str, float]) -> None:
        """Command arm joint goals (rad), taking the arm from its handover controller."""

    def release_arm(self) -> None:
        """Hand the arm back to its handover controller."""

    def apply_eyes(self, yaw: float, pitch: float, blink: float = 0.0,
                   distance: float | None = None) -> None:
        """Set the display eyes: yaw, pitch (rad), blink (0..1) and the target distance (m)."""

    def set_display(self, image: np.ndarray) -> None:
        """Show ``image`` on the robot's head screen."""


def apply_arm_command(sim: Simulation, cmd: ArmCommand) -> None:
    """Apply an arm command to a simulation: joint goals or a named pose take the arm over from
    its handover controller; ``resume`` hands it back.

    Raises:
        ValueError: unknown joints, or a capability the simulation does not have.
    """
    robot = sim.robot
    if cmd.resume:
        sim.release_arm()
        return
    goal = dict(cmd.positions or {})
    grip = goal.pop("gripper", cmd.gripper)
    if cmd.pose is not None:
        pose = robot.home if cmd.pose == "home" else robot.handover
        goal = dict(zip(robot.arm_joints, (float(q) for q in pose), strict=True))
    if grip is not None:
        gripper = getattr(sim, "apply_gripper", None)
        if gripper is None:
            raise ValueError("this simulation's gripper follows its handover controller only")
        gripper(cmd.gripper if cmd.gripper is not None else grip)
    if goal:
        sim.apply_arm(goal)


class SimRobotDriver(RobotDriver):
    """Drive an in-process simulation.

    Args:
        sim: A ``HandoverSimulation`` (or anything with its interface).
        rate: Tracking rate (Hz): each :meth:`wait_tracking` advances the simulation 1/rate s.
        node: Name used as the source of the engine's events.
    """

    def __init__(self, sim: Simulation, rate: float = 120.0, node: str = "engine") -> None:
        if not rate > 0:
            raise ValueError(f"rate must be > 0 Hz, got {rate!r}")
        self.sim = sim
        self.dt = 1.0 / rate
        self.node = node
        self._event_seq = 0
        self._inbox: deque[BusEvent] = deque()
        self.events: list[BusEvent] = []  # everything published (robot's and the engine's)
        self.statuses: list[NodeStatus] = []
        self.head_commands = 0
        self.rejected: dict[str, int] = {}

    def _reject(self, what: str, exc: Exception) -> None:
        self.rejected[what] = self.rejected.get(what, 0) + 1
        log.warning("simulation rejected a %s command: %s", what, exc)

    def wait_tracking(self, timeout: float) -> TrackingFrame | None:
        """Step the simulation by one tracking period and return its new sample (``timeout`` is not
        waited)."""
        self.sim.step(self.dt)
        for event in self.sim.robot_events():
            msg = BusEvent.of(event, "sim", time.time(), self._event_seq)
            self._event_seq += 1
            self._inbox.append(msg)
            self.events.append(msg)
        return self.sim.tracking()

    def joint_state(self) -> JointState | None:
        """The simulation's joint state now."""
        return JointState(float(self.sim.t), dict(self.sim.joint_state()))

    def send_head(self, goal: JointGoal) -> None:
        """Apply head joint goals; a goal the simulation refuses is counted in ``rejected``."""
        try:
            self.sim.apply_head(goal.positions)
            self.head_commands += 1
        except ValueError as exc:
            self._reject("head", exc)

    def send_eyes(self, eyes: EyeState) -> None:
        """Set the simulated display's eyes."""
        self.sim.apply_eyes(eyes.yaw, eyes.pitch, eyes.blink, distance=eyes.distance)

    def send_eye_frame(self, image: RosCompressedImage) -> None:
        """Show a rendered eye frame on the simulated display; an unreadable one is counted in
        ``rejected``."""
        try:
            self.sim.set_display(convert.image_of(image))
        except MessageError as exc:
            self._reject("eye_frame", exc)

    def send_arm(self, cmd: ArmCommand) -> None:
        """Apply an arm command (:func:`apply_arm_command`); a refused one is counted in
        ``rejected``."""
        try:
            apply_arm_command(self.sim, cmd)
        except ValueError as exc:
            self._reject("arm", exc)

    def poll_events(self) -> list[BusEvent]:
        """The simulation's robot events since the last call, oldest first."""
        out = list(self._inbox)
        self._inbox.clear()
        return out

    def publish_event(self, event: BusEvent) -> None:
        """Keep one of the engine's events in :attr:`events`."""
        self.events.append(event)

    def event_history(self, timeout: float = 1.0) -> list[BusEvent]:
        """Every event published so far (the robot's and the engine's), oldest first."""
        return list(self.events)

    def publish_status(self, status: NodeStatus) -> None:
        """Keep the engine's heartbeat in :attr:`statuses`."""
        self.statuses.append(status)

    def peers(self) -> dict[str, bool]:
        """The one peer, the simulation (``sim``), always alive."""
        return {"sim": True}
