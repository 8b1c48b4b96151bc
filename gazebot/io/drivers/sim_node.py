"""The simulator node: a :class:`gazebot.apps.sim.HandoverSimulation` on the bus.

Each tick (120 Hz by default) it applies the newest head, eye and arm commands, advances the
simulation (giver, handover controller, physics), publishes the tracking sample, the robot
controller's events, the joint states (60 Hz) and a heartbeat (2 Hz). ``speed`` runs faster than
real time (the simulation clock stays the tracking clock); ``math.inf`` runs as fast as possible.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from gazebot.io.drivers.sim_driver import Simulation, apply_arm_command
from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint
from gazebot.io.ros2 import convert

log = logging.getLogger("gazebot.io.drivers")


@dataclass(frozen=True)
class SimNodeConfig:
    """Rates (Hz), pacing and lifetime of the simulator node.

    Attributes:
        rate: Simulation step and tracking rate.
        joint_state_rate: Joint state publishing rate (at most ``rate``).
        heartbeat_period: Heartbeat period (s).
        speed: Simulated seconds per wall second (``math.inf``: no pacing).
        view_rate: Frame rate of the on-screen view (when one is attached).
    """

    rate: float = 120.0
    joint_state_rate: float = 60.0
    heartbeat_period: float = 0.5
    speed: float = 1.0
    view_rate: float = 30.0

    def __post_init__(self) -> None:
        for name in ("rate", "joint_state_rate", "heartbeat_period", "speed", "view_rate"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and value > 0 and not math.isnan(value)):
                raise ValueError(f"SimNodeConfig.{name} must be a positive number, got {value!r}")


class SimNode:
    """Run ``sim`` on the bus through ``endpoint``.

    Args:
        sim: The simulation (``HandoverSimulation`` or anything with its interface).
        endpoint: The robot side of the bus.
        config: Rates and pacing.
        view: Optional callable ``view(sim) -> bool`` drawing the scene; returning ``False``
            stops the node (window closed).
        clock: Monotonic clock (s).
    """

    def __init__(
        self,
        sim: Simulation,
        endpoint: ZenohRobotEndpoint,
        config: SimNodeConfig | None = None,
        *,
        view: Callable[[Simulation], bool] | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.sim = sim
        self.endpoint = endpoint
        self.config = config or SimNodeConfig()
        self.view = view
        self.clock = clock
        self.ticks = 0
        self.applied = {"head": 0, "eyes": 0, "eye_frame": 0, "arm": 0}
        self.rejected: dict[str, int] = {}
        self._last_beat = -math.inf
        self._last_view = -math.inf
        self._done_reported = False

    # -- commands --------------------------------------------------------------------------
    def _reject(self, what: str, exc: Exception) -> None:
        n = self.rejected[what] = self.rejected.get(what, 0) + 1
        if n <= 3 or n % 100 == 0:
            log.warning("rejected %s command #%d: %s", what, n, exc)

    def apply_commands(self) -> None:
        """Apply the newest command of each kind received since the last tick."""
        ep, sim = self.endpoint, self.sim
        if (head := ep.head.take()) is not None:
            try:
                sim.apply_head(head.positions)
                self.applied["head"] += 1
            except ValueError as exc:
                self._reject("head", exc)
        if (frame := ep.eye_frame.take()) is not None:
            try:
                sim.set_display(convert.image_of(frame))
                self.applied["eye_frame"] += 1
            except ValueError as exc:  # MessageError among them: not a decodable image
                self._reject("eye_frame", exc)
        if (eyes := ep.eyes.take()) is not None:
            try:
                sim.apply_eyes(eyes.yaw, eyes.pitch, eyes.blink, distance=eyes.distance)
                self.applied["eyes"] += 1
            except ValueError as exc:
                self._reject("eyes", exc)
        if (arm := ep.arm.take()) is not None:
            try:
                apply_arm_command(sim, arm)
                self.applied["arm"] += 1
            except ValueError as exc:
                self._reject("arm", exc)

    # -- loop ------------------------------------------------------------------------------
    def tick(self) -> None:
        """One simulation tick: commands in, step, tracking/events/joints/heartbeat out."""
        cfg, ep, sim = self.config, self.endpoint, self.sim
        self.apply_commands()
        sim.step(1.0 / cfg.rate)
        self.ticks += 1
        for event in sim.robot_events():
            ep.publish_robot_event(event)
        ep.publish_tracking(sim.tracking())
        # Joint states every k-th tick: a rate in simulated time, whatever the pacing.
        every = max(1, round(cfg.rate / cfg.joint_state_rate))
        if (self.ticks - 1) % every == 0:
            ep.publish_joint_state(sim.t, sim.joint_state())
        now = self.clock()
        if now - self._last_beat >= cfg.heartbeat_period:
            self._last_beat = now
            self.heartbeat()
        if self.view is not None and now - self._last_view >= 1.0 / cfg.view_rate:
            self._last_view = now
            if not self.view(sim):
                raise KeyboardInterrupt  # the window was closed

    def publish_state(self) -> None:
        """Publish the current joint state and a heartbeat now (e.g. before the loop starts, so
        an engine that is starting finds the head pose at once)."""
        self.endpoint.publish_joint_state(self.sim.t, self.sim.joint_state())
        self.heartbeat()

    def wait_for_engine(
        self, timeout: float, stop: threading.Event | None = None, poll: float = 0.1
    ) -> bool:
        """Wait, the scene's clock stopped, until an engine owns the robot (its ownership
        claim is alive on the bus), so that an engine started after the simulator still sees
        the whole handover. Meanwhile the joint state and the heartbeat go out as usual (an
        engine that is starting takes the head pose from them).

        Returns:
            ``True`` once an engine owns the robot; ``False`` after ``timeout`` s or on
            ``stop``.
        """
        deadline = self.clock() + timeout
        while not (stop is not None and stop.is_set()):
            if self.endpoint.owners.owner() is not None:
                return True
            now = self.clock()
            if now >= deadline:
                return False
            if now - self._last_beat >= self.config.heartbeat_period:
                self._last_beat = now
                self.publish_state()
            if stop is None:
                time.sleep(poll)
            else:
                stop.wait(poll)
        return False

    def heartbeat(self, stopping: bool = False) -> None:
        """Publish the simulator's heartbeat (simulated time, done, ticks, commands applied and
        rejected)."""
        self.endpoint.heartbeat(
            info={
                "t": float(self.sim.t),
                "done": bool(self.sim.done),
                "ticks": self.ticks,
                "applied": dict(self.applied),
                "rejected": dict(self.rejected),
            },
            stopping=stopping,
        )

    def run(self, duration: float | None = None, stop: threading.Event | None = None) -> float:
        """Tick until ``duration`` simulated seconds passed or ``stop`` is set, paced at
        ``speed`` x real time. Returns the real-time factor achieved (sim s / wall s)."""
        cfg = self.config
        t0_sim = self.sim.t
        start = self.clock()
        try:
            while not (stop is not None and stop.is_set()):
                if duration is not None and self.sim.t - t0_sim >= duration - 1e-9:
                    break
                self.tick()
                if math.isfinite(cfg.speed):
                    due = start + (self.sim.t - t0_sim) / cfg.speed
                    delay = due - self.clock()
                    if delay > 0:
                        time.sleep(delay) if stop is None else stop.wait(delay)
        finally:
            try:
                self.heartbeat(stopping=True)
            except Exception:
                log.debug("could not send the last heartbeat", exc_info=True)
        wall = self.clock() - start
        return (self.sim.t - t0_sim) / wall if wall > 0 else math.inf
