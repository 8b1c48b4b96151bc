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
    def arm_joints(self) -> Sequence[str]: ...
    @property
    def home(self) -> np.ndarray: ...
    @property
    def handover(self) -> np.ndarray: ...


class Simulation(Protocol):
    """What the drivers use of a simulation (:class:`gazebot.apps.sim.HandoverSimulation`)."""

    @property
    def robot(self) -> SimArm: ...
    @property
    def t(self) -> float: ...
    @property
    def done(self) -> bool: ...
    def step(self, dt: float) -> None: ...
    def tracking(self) -> TrackingFrame: ...
    def joint_state(self) -> Mapping[str, float]: ...
    def robot_events(self) -> list[Event]: ...
    def apply_head(self, joints: Mapping[str, float]) -> None: ...
    def apply_arm(self, joints: Mapping[str, float]) -> None: ...
    def release_arm(self) -> None: ...
    def apply_eyes(self, yaw: float, pitch: float, blink: float = 0.0,
                   distance: float | None = None) -> None: ...
    def set_display(self, image: np.ndarray) -> None: ...


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
        self.sim.step(self.dt)
        for event in self.sim.robot_events():
            msg = BusEvent.of(event, "sim", time.time(), self._event_seq)
            self._event_seq += 1
            self._inbox.append(msg)
            self.events.append(msg)
        return self.sim.tracking()

    def joint_state(self) -> JointState | None:
        return JointState(float(self.sim.t), dict(self.sim.joint_state()))

    def send_head(self, goal: JointGoal) -> None:
        try:
            self.sim.apply_head(goal.positions)
            self.head_commands += 1
        except ValueError as exc:
            self._reject("head", exc)

    def send_eyes(self, eyes: EyeState) -> None:
        self.sim.apply_eyes(eyes.yaw, eyes.pitch, eyes.blink, distance=eyes.distance)

    def send_eye_frame(self, image: RosCompressedImage) -> None:
        try:
            self.sim.set_display(convert.image_of(image))
        except MessageError as exc:
            self._reject("eye_frame", exc)

    def send_arm(self, cmd: ArmCommand) -> None:
        try:
            apply_arm_command(self.sim, cmd)
        except ValueError as exc:
            self._reject("arm", exc)

    def poll_events(self) -> list[BusEvent]:
        out = list(self._inbox)
        self._inbox.clear()
        return out

    def publish_event(self, event: BusEvent) -> None:
        self.events.append(event)

    def event_history(self, timeout: float = 1.0) -> list[BusEvent]:
        return list(self.events)

    def publish_status(self, status: NodeStatus) -> None:
        self.statuses.append(status)

    def peers(self) -> dict[str, bool]:
        return {"sim": True}
