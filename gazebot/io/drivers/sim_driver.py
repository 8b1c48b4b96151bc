"""``SimRobotDriver``: a :class:`gazebot.apps.sim.HandoverSimulation` in this process, no bus.

The simulation advances in lockstep with the engine: each :meth:`SimRobotDriver.wait_tracking`
steps it by one tracking period and returns the new sample, so a run is deterministic for a
seed and as fast as the CPU allows.
"""

from __future__ import annotations

import logging
import time
from collections import deque
from typing import Any

from gazebot.io.drivers.base import RobotDriver
from gazebot.io.drivers.payloads import (
    ArmCommandMsg,
    EventMsg,
    EyeFrameMsg,
    EyeStateMsg,
    HeadCommandMsg,
    JointStateMsg,
    StatusMsg,
    TrackingMsg,
)

log = logging.getLogger("gazebot.io.drivers")


def apply_arm_command(sim: Any, msg: ArmCommandMsg) -> None:
    """Apply an arm command to a simulation: joint goals or a named pose take the arm over from
    its handover controller; ``resume`` hands it back.

    Raises:
        ValueError: unknown joints, or a capability the simulation does not have.
    """
    robot = sim.robot
    if msg.resume:
        sim.release_arm()
        return
    if msg.pose is not None:
        goal = dict(zip(robot.arm_joints, (float(q) for q in getattr(robot, msg.pose)),
                        strict=True))
    else:
        goal = dict(msg.positions or {})
        goal.pop("gripper", None)
    if msg.gripper is not None or (msg.positions and "gripper" in msg.positions):
        gripper = getattr(sim, "apply_gripper", None)
        if gripper is None:
            raise ValueError("this simulation's gripper follows its handover controller only")
        gripper(msg.gripper if msg.gripper is not None else msg.positions["gripper"])
    if goal:
        sim.apply_arm(goal)


class SimRobotDriver(RobotDriver):
    """Drive an in-process simulation.

    Args:
        sim: A ``HandoverSimulation`` (or anything with its interface).
        rate: Tracking rate (Hz): each :meth:`wait_tracking` advances the simulation 1/rate s.
        node: Name used as the source of the engine's events.
    """

    def __init__(self, sim: Any, rate: float = 120.0, node: str = "engine") -> None:
        if not rate > 0:
            raise ValueError(f"rate must be > 0 Hz, got {rate!r}")
        self.sim = sim
        self.dt = 1.0 / rate
        self.node = node
        self._seq = 0
        self._event_seq = 0
        self._inbox: deque[EventMsg] = deque()
        self.events: list[EventMsg] = []  # everything published (robot's and the engine's)
        self.statuses: list[StatusMsg] = []
        self.head_commands = 0
        self.rejected: dict[str, int] = {}

    def _reject(self, what: str, exc: Exception) -> None:
        self.rejected[what] = self.rejected.get(what, 0) + 1
        log.warning("simulation rejected a %s command: %s", what, exc)

    def wait_tracking(self, timeout: float) -> TrackingMsg | None:
        self.sim.step(self.dt)
        for event in self.sim.robot_events():
            msg = EventMsg.from_event(event, "sim", self._event_seq, time.time())
            self._event_seq += 1
            self._inbox.append(msg)
            self.events.append(msg)
        msg = TrackingMsg.from_frame(self.sim.tracking(), self._seq, time.time())
        self._seq += 1
        return msg

    def joint_state(self) -> JointStateMsg | None:
        return JointStateMsg(seq=self._seq, t=float(self.sim.t), stamp=time.time(),
                             position=dict(self.sim.joint_state()))

    def send_head(self, msg: HeadCommandMsg) -> None:
        try:
            self.sim.apply_head(msg.head)
            self.head_commands += 1
        except ValueError as exc:
            self._reject("head", exc)

    def send_eyes(self, msg: EyeStateMsg) -> None:
        self.sim.apply_eyes(msg.yaw, msg.pitch, msg.blink, distance=msg.distance)

    def send_eye_frame(self, msg: EyeFrameMsg) -> None:
        self.sim.set_display(msg.image())

    def send_arm(self, msg: ArmCommandMsg) -> None:
        try:
            apply_arm_command(self.sim, msg)
        except ValueError as exc:
            self._reject("arm", exc)

    def poll_events(self) -> list[EventMsg]:
        out = list(self._inbox)
        self._inbox.clear()
        return out

    def publish_event(self, msg: EventMsg) -> None:
        self.events.append(msg)

    def event_history(self, timeout: float = 1.0) -> list[EventMsg]:
        return list(self.events)

    def publish_status(self, msg: StatusMsg) -> None:
        self.statuses.append(msg)

    def peers(self) -> dict[str, bool]:
        return {"sim": True}
