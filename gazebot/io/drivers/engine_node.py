"""The engine node: runs the :class:`gazebot.core.runtime.GazeLoop` on the tracking a robot driver
delivers and sends back head commands, eye state (and frames when asked), events and heartbeats.

Faults (each pinned by ``tests/drivers``):

* tracking stops: after ``silence_after`` s without a sample the node ticks the loop without one
  at ``silence_rate`` Hz, so the loop's one tracking-loss policy applies (the phase detector
  bridges ``max_gap_hold``, then the behavior holds the gaze for its ``tracking_lost.hold_s``:
  event ``tracking_stale``, status ``tracking: hold``; then it looks at its ``tracking_lost``
  target, by default the last known face: event ``tracking_timeout`` with ``info.face``, status
  ``tracking: lost``). The status' ``tracking`` says which policy commands the head; when
  samples return, ``tracking_resumed``. A sample older than a silence tick already answered is
  too late and is dropped by the phase detector (its time is the robot clock estimated from the
  wall clock).
* engine restart: at start the node takes the head pose from the joint state and replays the
  current handover's phase and robot events from the other nodes' event history
  (``GazeEngine.resync``), then reports ``engine_resynced``.
* robot gone: the loop keeps running; ``peer_lost``/``peer_restored`` events and the status'
  ``peers`` and ``state: degraded`` report it.
* robot never seen (e.g. a wrong ``--connect``): after ``no_robot_warning`` s without any
  tracking sample or joint state, event ``no_robot`` (``info.after``, ``info.peers``), the
  ``warn`` callback (``gazebot run`` prints it on stderr), status ``state: degraded`` with
  ``info.robot_seen: false`` until the robot shows up.
* robot clock restart (a sample older than the last by ``clock_reset``): event
  ``tracking_clock_reset``, then the same resynchronisation as at start. A restart is taken
  only once ``clock_reset_confirm`` samples in a row went back, each later than the one before
  (a restarted clock runs on; stamps interleaved with the old clock's are not a restart), and at
  most once per ``clock_reset_holdoff`` s (issue 30: no stream of stamps restarts handovers);
  the samples meanwhile are dropped (``tracking_backwards``).
* malformed messages (garbage, truncated CDR, oversized, NaN or infinite values): dropped by
  the driver, counted by topic in the status' ``dropped``.
* a robot speaking another message type (or another version of it) on a topic: dropped, and
  reported at once as ``type_mismatch`` (topic, expected and received type with their hashes).
* another engine on the same robot (:mod:`gazebot.io.drivers.ownership`): at start the node claims
  the robot; if an earlier engine owns it, the node reports ``competing_engine`` (``info.role``
  ``refused``) and stops with :class:`EngineRefused`, or with ``standby`` waits (``info.role``
  ``standby``, no commands) until the owner's claim vanishes, then takes over
  (``engine_took_over``, resynchronised). The owner reports each rival as ``competing_engine``
  (``info.role`` ``owner``); the status carries ``info.role`` and ``info.rivals`` and is
  ``degraded`` while rivals exist.
* a second tracking source (another tracker, with its own clock): its samples are ignored by
  the driver (:mod:`gazebot.io.drivers.tracking_source`; counted by topic) while the first one keeps
  publishing; reported once per rival as ``competing_tracking`` (``info.source``,
  ``info.owner``, ``info.group``), the status carries ``info.tracking_sources`` and
  ``info.tracking_rivals`` and is ``degraded`` while a rival publishes. No clock reset follows.
* anything a sample, an event or a peer's message makes fail (in the loop, the engine or a
  subscription callback): caught, counted (status ``info.faults``), reported as a ``node_fault``
  event (``info.stage``, ``info.error``; the first three, then every 100th) and the status is
  ``degraded`` for ``fault_hold`` s; the node goes on with the next sample.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal, Protocol

import numpy as np

from gazebot.core.kinematics.robot import RobotModel
from gazebot.core.runtime import GazeLoop, LoopCommand
from gazebot.core.types import Event, EventKind, TrackingFrame
from gazebot.io.drivers.base import RobotDriver
from gazebot.io.drivers.rmw.node import RosNode
from gazebot.io.drivers.scene_out import SceneOut
from gazebot.io.ros2 import convert
from gazebot.io.ros2.topics import GAZE_FRAME
from gazebot.io.ros2.values import (
    BusEvent,
    EventCategory,
    EyeState,
    JointGoal,
    NodeStatus,
    category_of,
    finite_point,
    plain,
)

log = logging.getLogger("gazebot.io.drivers")

TrackingState = Literal["waiting", "ok", "hold", "lost"]
Role = Literal["owner", "standby", "refused"]

#: Warnings the node keeps (and its status carries): the latest ones. A long run warns again
#: at each restart of a tracker or each rival, and every heartbeat carries the list.
MAX_WARNINGS = 20


class EyeImages(Protocol):
    """Renders the display's eyes (:class:`gazebot.apps.render.EyeRenderer`)."""

    def render(self, yaw: float, pitch: float, blink: float = 0.0,
               distance: float | None = None) -> np.ndarray:
        """An (H, W, 3) uint8 RGB image of eyes looking at (``yaw``, ``pitch``) rad."""
        ...


class EngineRefused(RuntimeError):
    """Another engine owns the robot and this one does not wait: it must stop (``gazebot run``
    exits with status 3 and this one-line message)."""


@dataclass(frozen=True)
class EngineNodeConfig:
    """Timing of the engine node (s, Hz).

    Attributes:
        silence_after: Silence of the tracking (s) after which the node ticks the loop without
            a sample (the tracking-loss timings themselves are the phase detector's and the
            behavior's). silence_rate: Rate (Hz) of those ticks while the silence lasts.
        heartbeat_period: Period of the status heartbeat.
        resync: Catch up with a handover under way at start (events + joint state).
        resync_timeout: How long to wait at start for the joint state and the event history.
        eye_frame_rate: Maximum rate of rendered eye frames (only while someone subscribes).
        clock_reset: A sample this much older than the previous one (s) means the robot's
            clock restarted: the engine is reset and resynchronised.
        clock_reset_confirm: Samples in a row (each later than the one before) that must go
            back before the clock counts as restarted.
        clock_reset_holdoff: Least time (s) between two clock resets.
        no_robot_warning: Warn once when no tracking sample or joint state arrived this long
            (s) after the start.
        fault_hold: The status stays ``degraded`` this long (s) after a caught fault.
        standby: When another engine owns the robot, wait as standby instead of stopping.
        claim_timeout: How long (s) the claim at start waits to learn the other engines'.
    """

    silence_after: float = 0.15
    silence_rate: float = 30.0
    heartbeat_period: float = 0.5
    resync: bool = True
    resync_timeout: float = 1.0
    eye_frame_rate: float = 30.0
    clock_reset: float = 0.5
    clock_reset_confirm: int = 3
    clock_reset_holdoff: float = 5.0
    no_robot_warning: float = 3.0
    fault_hold: float = 5.0
    standby: bool = False
    claim_timeout: float = 0.5

    def __post_init__(self) -> None:
        for name in ("silence_after", "silence_rate", "heartbeat_period", "resync_timeout",
                     "eye_frame_rate", "clock_reset", "no_robot_warning", "fault_hold",
                     "clock_reset_confirm", "clock_reset_holdoff",
                     "claim_timeout"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(
                    f"EngineNodeConfig.{name} must be a positive number, got {value!r}"
                )


def current_handover(events: Sequence[Event]) -> list[Event]:
    """The events of the handover under way: those after the last ``handover_done`` (or just
    that ``handover_done`` when nothing followed it), oldest first."""
    ordered = sorted(events, key=lambda e: e.t)
    done = [i for i, e in enumerate(ordered) if e.kind == EventKind.HANDOVER_DONE]
    if not done:
        return ordered
    last = done[-1]
    return ordered[last:] if last == len(ordered) - 1 else ordered[last + 1 :]


class EngineNode:
    """Drive one robot with one runtime loop.

    Args:
        loop: The runtime loop (engine, blinks, safety, tracking-loss policy).
        driver: The robot (``ZenohRobotDriver`` over the bus, ``SimRobotDriver`` in process).
        config: Timeouts and rates.
        eye_renderer: Optional renderer with ``render(yaw, pitch, blink=, distance=) -> (H, W, 3)
            uint8``, used only while the robot wants eye frames.
        warn: Called with a one-line message for conditions an operator must see (no robot).
        clock: Monotonic clock (s).
    """

    def __init__(
        self,
        loop: GazeLoop,
        driver: RobotDriver,
        config: EngineNodeConfig | None = None,
        *,
        eye_renderer: EyeImages | None = None,
        warn: Callable[[str], None] | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.loop = loop
        self.engine = loop.engine
        self.driver = driver
        self.config = config or EngineNodeConfig()
        self.eye_renderer = eye_renderer
        self.warn = warn
        self.clock = clock
        self.robot_seen = False
        self.warnings: list[str] = []  # the latest MAX_WARNINGS
        self.tracking: TrackingState = "waiting"
        self.commands_sent = 0
        self.frames_processed = 0
        self._started = clock()
        self._run_started = self._started
        self._seq = {"event": 0, "status": 0}
        self._last_frame_wall = math.nan
        self._last_t = math.nan
        self._back_run: list[float] = []  # stamps of samples in a row going back
        self._last_reset_at = -math.inf
        self.tracking_backwards = 0  # samples dropped while a clock restart was unconfirmed
        self._last_silence_tick = -math.inf
        self._last_beat = -math.inf
        self._last_eye_frame = -math.inf
        self._behavior_state: str | None = None
        self._target: str | None = None
        self._mismatch_warned: set[str] = set()
        self._no_robot_warned = False
        self._last_head: JointGoal | None = None
        self._phase_sent: tuple[str, float] | None = None
        self._peers: dict[str, bool] = {}
        self._skip_events: set[tuple[str, str, int, int]] = set()
        self.role: Role = "owner"
        self._rivals_reported: set[str] = set()
        self.faults = 0
        self.last_fault: str | None = None
        self._last_fault_at = -math.inf
        self._callback_faults: dict[str, int] = {}
        self.ready = threading.Event()  # set once started (and resynchronised)
        self._last_frame: TrackingFrame | None = None
        # The scene for rviz2 / Foxglove, when the robot is on the bus (not an in-process one).
        ros, robot = getattr(driver, "ros", None), getattr(self.engine, "robot", None)
        self.scene = (SceneOut(ros, robot) if isinstance(ros, RosNode)
                      and isinstance(robot, RobotModel) else None)

    # -- helpers ---------------------------------------------------------------------------
    def _next(self, name: str) -> int:
        self._seq[name] += 1
        return self._seq[name] - 1

    def emit(self, kind: str, t: float | None = None, category: EventCategory | None = None,
             **info: object) -> BusEvent:
        """Publish one of the node's own events (fault, behavior, node). Without ``t``: the
        tracking clock now; a node event's ``info.clock`` says ``tracking``, or ``none`` (``t``
        0) before the first sample (docs/cli.md)."""
        category = category or category_of(kind)
        if t is None and category == "node":
            info.setdefault("clock", "tracking" if math.isfinite(self._last_t) else "none")
        t = self._now_t() if t is None else t
        t = t if math.isfinite(t) else 0.0
        msg = BusEvent(
            source=self.driver.node,
            category=category,
            kind=kind,
            t=t,
            detected_at=t,
            stamp=time.time(),
            info={k: plain(v) for k, v in info.items()},
            seq=self._next("event"),
        )
        self.driver.publish_event(msg)
        log.info("event %s %s", kind, msg.info)
        return msg

    def _now_t(self) -> float:
        """Robot time now: the last sample's time plus the wall time since it arrived."""
        if not math.isfinite(self._last_t):
            return 0.0
        return self._last_t + max(0.0, self.clock() - self._last_frame_wall)

    @property
    def phase(self) -> str:
        """The engine's current phase as a string (``idle`` without one)."""
        phase = getattr(self.engine, "phase", None)
        return str(getattr(phase, "value", phase)) if phase is not None else "idle"

    # -- start -----------------------------------------------------------------------------
    def start(self) -> int:
        """Announce the node, claim the robot and, if configured, resynchronise with a
        handover under way. Returns the number of events replayed.

        Raises:
            EngineRefused: Another engine owns the robot and ``standby`` is off.
        """
        self._run_started = self.clock()  # the no-robot delay counts from here
        self.emit("node_started", category="node", robot=getattr(self.engine.robot, "name", ""))
        self.driver.claim(self.config.claim_timeout)
        if not self.driver.owns_robot():
            self._yield_robot()
        replayed = self._catch_up() if self.role == "owner" else 0
        self.ready.set()
        return replayed

    def _catch_up(self) -> int:
        replayed = 0
        if self.config.resync:
            try:
                replayed = self.resync()
            except Exception as exc:  # a history the engine cannot replay: start afresh
                self.fault("resync", exc)
                self.loop.reset(None)
        return replayed

    # -- ownership -------------------------------------------------------------------------
    def _yield_robot(self) -> None:
        """An earlier engine owns the robot: wait as standby, or stop."""
        rivals = self.driver.rival_engines()
        owner = rivals[0] if rivals else "another engine"
        self.role = "standby" if self.config.standby else "refused"
        self._report_rivals(rivals)
        if self.role == "refused":
            raise EngineRefused(
                f"another engine, {owner}, already commands the robot under "
                f"{getattr(getattr(self.driver, 'names', None), 'namespace', '?')}: stop it "
                "first, or start this one with --standby to take over when it stops")

    def _report_rivals(self, rivals: Sequence[str]) -> None:
        new = [r for r in rivals if r not in self._rivals_reported]
        if not new and self.role == "owner":
            return
        self._rivals_reported.update(new)
        text = {"owner": f"another engine ({', '.join(new)}) claims this robot: it is "
                         "refused or waits as standby",
                "standby": f"another engine ({', '.join(rivals)}) commands this robot: "
                           "standing by until it stops"}
        if self.role == "refused":  # the node stops and says why itself
            self.emit("competing_engine", role=self.role, rivals=list(rivals), new=new)
        else:
            self._warn("competing_engine", text[self.role], role=self.role, rivals=list(rivals),
                       new=new)

    def _check_ownership(self) -> None:
        """Report rivals; yield to an earlier engine; take over when the owner went away."""
        rivals = self.driver.rival_engines()
        owns = self.driver.owns_robot()
        if self.role == "owner":
            if any(r not in self._rivals_reported for r in rivals):
                self._report_rivals(rivals)
            if not owns and rivals:
                self._yield_robot()
        elif self.role == "standby" and owns:
            self.role = "owner"
            self.emit("engine_took_over", category="node", rivals=rivals)
            self._catch_up()
        self._rivals_reported.intersection_update(rivals)

    def resync(self) -> int:
        """Take the head pose from the joint state and replay the current handover's events
        from the other nodes' history. Returns the number of events replayed."""
        deadline = self.clock() + self.config.resync_timeout
        joints = self.driver.joint_state()
        while joints is None and self.clock() < deadline:
            time.sleep(0.005)
            joints = self.driver.joint_state()
        head = None
        if joints is not None:
            names = list(getattr(self.engine.robot, "head_joints", []))
            head = {n: joints.position[n] for n in names if n in joints.position} or None
        history = self.driver.event_history(timeout=max(0.05, deadline - self.clock()))
        self._skip_events = {m.identity for m in history}
        events = [e for m in history if m.category in ("phase", "robot")
                  if (e := m.to_event()) is not None]
        replay = current_handover(events)
        self.loop.reset(head)
        if replay:
            self.loop.resync(replay)
        self.emit(
            "engine_resynced",
            t=replay[-1].t if replay else 0.0,
            category="node",
            events=len(replay),
            phase=self.phase,
            head_from_joint_state=head is not None,
        )
        return len(replay)

    # -- loop ------------------------------------------------------------------------------
    def run(self, duration: float | None = None, stop: threading.Event | None = None) -> None:
        """:meth:`start`, then :meth:`tick` until ``stop`` is set or ``duration`` s passed.

        Raises:
            EngineRefused: Another engine owns the robot (and ``standby`` is off).
        """
        try:
            self.start()
            end = math.inf if duration is None else self.clock() + duration
            while not (stop is not None and stop.is_set()) and self.clock() < end:
                self.tick()
        finally:
            self.shutdown()

    def shutdown(self) -> None:
        """Report that the node stops (event and a last heartbeat)."""
        try:
            self.emit("node_stopped", category="node")
            self._heartbeat(stopping=True)
        except Exception:  # the bus may already be gone
            log.debug("could not report the node's stop", exc_info=True)

    def _wait_budget(self) -> float:
        now = self.clock()
        budget = min(0.05, max(0.0, self._last_beat + self.config.heartbeat_period - now))
        if self.tracking != "waiting":
            due = max(self._last_frame_wall + self.config.silence_after,
                      self._last_silence_tick + 1 / self.config.silence_rate)
            budget = min(budget, max(0.0, due - now))
        return budget

    def tick(self) -> None:
        """Wait briefly for a tracking sample and answer it, or handle the silence. Nothing a
        sample, an event or a peer causes stops the node: each stage's failure is a
        :meth:`fault` and the next stage runs."""
        self._check_ownership()
        msg = self.driver.wait_tracking(self._wait_budget())
        if self.role != "owner":  # standby: nothing is commanded; the resync catches up later
            self.driver.poll_events()
            if self.clock() - self._last_beat >= self.config.heartbeat_period:
                self._guarded("heartbeat", self._heartbeat)
            return
        for ev in self.driver.poll_events():
            if ev.identity in self._skip_events:
                continue
            if ev.category == "robot" and (event := ev.to_event()) is not None:
                self._guarded("event", self.loop.notify, event)
        if msg is not None:
            self._guarded("tracking", self.on_tracking, msg)
        else:
            self._guarded("silence", self.on_silence)
        self._guarded("checks", self._checks)
        if self.clock() - self._last_beat >= self.config.heartbeat_period:
            self._guarded("heartbeat", self._heartbeat)

    def _checks(self) -> None:
        self._check_peers()
        self._check_mismatches()
        self._check_robot_seen()
        self._check_callback_faults()
        self._check_tracking_sources()

    def _check_tracking_sources(self) -> None:
        for r in self.driver.tracking_rivals(new_only=True):
            self._warn("competing_tracking", f"a second tracking source, {r.source}, publishes "
                       f"the {r.group} beside {r.owner}: ignored while {r.owner} publishes",
                       source=r.source, owner=r.owner, group=r.group)

    def _guarded(self, stage: str, fn: Callable[..., Any], *args: Any) -> None:
        try:
            fn(*args)
        except Exception as exc:
            self.fault(stage, exc)

    def fault(self, stage: str, exc: BaseException | str) -> None:
        """Count and report a failure the node survives: a ``node_fault`` event (the first
        three, then every 100th), ``degraded`` status for ``fault_hold`` s."""
        self.faults += 1
        self._last_fault_at = self.clock()
        text = exc if isinstance(exc, str) else f"{type(exc).__name__}: {exc}"
        text = " ".join(str(text).split())[:300]
        self.last_fault = f"{stage}: {text}"
        if self.faults <= 3 or self.faults % 100 == 0:
            if isinstance(exc, BaseException):
                log.error("engine node fault #%d in %s", self.faults, stage, exc_info=exc)
            try:
                self.emit("node_fault", stage=stage, error=text, faults=self.faults)
            except Exception:  # the bus itself failing: the count and the status remain
                log.debug("could not report a fault", exc_info=True)

    def _check_callback_faults(self) -> None:
        """Report handler failures in the driver's subscription callbacks (Zenoh's threads)."""
        counts = self.driver.callback_faults()
        for topic, n in sorted(counts.items()):
            new = n - self._callback_faults.get(topic, 0)
            if new > 0:
                self._callback_faults[topic] = n
                reason = self.driver.callback_fault_reasons().get(topic, "")
                self.fault(f"callback {topic}", f"{new} failed: {reason}")

    def on_tracking(self, frame: TrackingFrame) -> None:
        """Tick the loop with one sample and send the command."""
        now = self.clock()
        if frame.t < self._last_t - self.config.clock_reset:
            if not self._clock_restarted(frame.t, now):
                return
            # The robot's clock went back (e.g. the simulator restarted): the engine would
            # ignore every sample as out of order, so start over from the robot's state.
            self.emit("tracking_clock_reset", t=frame.t, previous_t=self._last_t)
            self._last_t = math.nan
            self.resync()
        else:
            self._back_run.clear()
        self._last_frame_wall = now
        self._last_t = frame.t
        self._last_frame = frame
        # The latest measured joints: an arm joint may carry the head (Sawyer's right_j0).
        joints = self.driver.joint_state()
        cmd = self._tick_loop("tracking", frame,
                              joints=joints.position if joints is not None else None)
        self.frames_processed += 1
        if cmd is not None:
            self._send(cmd)

    def _clock_restarted(self, t: float, now: float) -> bool:
        """Whether a sample at ``t``, going back, confirms a clock restart (else it is
        dropped and counted)."""
        run = self._back_run
        if run and t < run[-1]:  # not one clock running on: start the run again
            run.clear()
        run.append(t)
        if (len(run) < self.config.clock_reset_confirm
                or now - self._last_reset_at < self.config.clock_reset_holdoff):
            self.tracking_backwards += 1
            del run[:-self.config.clock_reset_confirm]  # bounded
            return False
        run.clear()
        self._last_reset_at = now
        return True

    def on_silence(self) -> None:
        """No sample arrived: after ``silence_after``, tick the loop without one (its
        tracking-loss policy decides where to look)."""
        if self.tracking == "waiting":
            return
        now = self.clock()
        if (now - self._last_frame_wall < self.config.silence_after
                or now - self._last_silence_tick < 1 / self.config.silence_rate):
            return
        self._last_silence_tick = now
        cmd = self._tick_loop("silence", None, t=self._now_t())
        if cmd is not None:
            self._send(cmd)

    def _tick_loop(self, stage: str, *args: Any, **kwargs: Any) -> LoopCommand | None:
        """``loop.tick``; a tick the engine raised on (the loop answers it with nothing) is
        reported as a fault of ``stage``."""
        before = getattr(self.loop, "faults", 0)
        cmd = self.loop.tick(*args, **kwargs)
        if getattr(self.loop, "faults", 0) > before:
            self.fault(stage, "the engine raised on this tick; nothing was sent")
        return cmd

    @property
    def unsafe_commands(self) -> int:
        """Commands the loop refused (non-finite): never sent."""
        return self.loop.unsafe

    def _track(self, cmd: LoopCommand) -> None:
        """Report the tracking state's changes as fault events."""
        before, now = self.tracking, cmd.tracking
        if before == now:
            return
        self.tracking = now
        silence = self.clock() - self._last_frame_wall
        if now == "ok":
            if before in ("hold", "lost"):
                self.emit("tracking_resumed", t=cmd.t, silence=silence)
            return
        if before in ("ok", "waiting"):
            self.emit("tracking_stale", t=cmd.t, silence=silence, last_t=self._last_t)
        if now == "lost":
            self.emit("tracking_timeout", t=cmd.t, silence=silence, target=cmd.target,
                      face=finite_point(cmd.target_point))

    def _send(self, cmd: LoopCommand) -> None:
        self._track(cmd)
        for event in cmd.events:
            if event.kind is EventKind.FAULT:  # caught inside the engine; the command is safe
                info = event.info or {}
                self.fault(f"engine {info.get('stage', '?')}", str(info.get("error", "")))
            elif category_of(event.kind.value) == "phase":
                self.driver.publish_event(
                    BusEvent.of(event, self.driver.node, time.time(), self._next("event"))
                )
        head = JointGoal.head_of(cmd, self._last_head)
        self._last_head = head
        self.driver.send_head(head)
        if (point := finite_point(cmd.target_point)) is not None:
            self.driver.send_gaze_target(cmd.t, point)
        self._send_phase(cmd.t)
        if self.scene is not None:
            self._guarded("scene", self.scene.send, cmd, self.phase, self._last_frame)
        self.driver.send_eyes(EyeState.of(cmd))
        now = self.clock()
        if (
            self.eye_renderer is not None
            and now - self._last_eye_frame >= 1 / self.config.eye_frame_rate
            and self.driver.wants_eye_frames()
        ):
            self._last_eye_frame = now
            img = self.eye_renderer.render(
                cmd.eye_yaw, cmd.eye_pitch, blink=cmd.blink, distance=cmd.distance
            )
            self.driver.send_eye_frame(convert.compressed_image(img, cmd.t, GAZE_FRAME))
        self.commands_sent += 1
        state = str(getattr(getattr(self.engine, "behavior", None), "state", ""))
        if state != self._behavior_state:
            self._behavior_state = state
            self.emit("behavior_state", t=cmd.t, category="behavior", state=state)
        if cmd.target != self._target:
            self._target = cmd.target
            self.emit("gaze_target", t=cmd.t, category="behavior", target=cmd.target,
                      point=finite_point(cmd.target_point))

    def _send_phase(self, t: float, again: bool = False) -> None:
        """Send the phase when it changed (``again``: also when it did not, for late
        subscribers)."""
        phase = self.phase
        if self._phase_sent is None or self._phase_sent[0] != phase:
            self._phase_sent = (phase, t)
        elif not again:
            return
        try:
            self.driver.send_phase(t, phase, self._phase_sent[1])
        except ValueError:
            log.debug("phase %r not sent", phase, exc_info=True)

    def _check_mismatches(self) -> None:
        """Report each topic on which a publisher of another message type was heard, once."""
        for topic, mismatch in sorted(self.driver.type_mismatches().items()):
            if topic in self._mismatch_warned:
                continue
            self._mismatch_warned.add(topic)
            self._warn("type_mismatch", f"{mismatch}: its messages are dropped; the robot "
                       "bridge must publish the type (and version) gazebot expects",
                       topic=topic, expected=list(mismatch.expected), received=mismatch.received)

    def _check_robot_seen(self) -> None:
        """Warn once if no tracking sample or joint state arrived ``no_robot_warning`` s after
        the start: otherwise a wrong endpoint would look like a quiet robot."""
        if self.robot_seen:
            return
        if self.frames_processed or self.driver.joint_state() is not None:
            self.robot_seen = True
            return
        after = self.clock() - self._run_started
        if after < self.config.no_robot_warning or self._no_robot_warned:
            return
        peers = self.driver.peers()
        text = (
            f"no robot seen after {after:.1f} s: no tracking or joint state received "
            f"(peers: {peers or 'none'}); is the robot running and the bus endpoint right?"
        )
        self._no_robot_warned = True
        self._warn("no_robot", text, after=after, peers=peers)

    def _warn(self, kind: str, text: str, **info: object) -> None:
        self.warnings.append(text)
        del self.warnings[:-MAX_WARNINGS]
        self.emit(kind, None, None, **info)
        if self.warn is not None:
            self.warn(text)
        else:
            log.warning("%s", text)

    def _check_peers(self) -> None:
        peers = self.driver.peers()
        for node, alive in peers.items():
            before = self._peers.get(node)
            if before is None and not alive or before and not alive:
                self.emit("peer_lost", peer=node)
            elif before is False and alive:
                self.emit("peer_restored", peer=node)
        self._peers = peers

    def _heartbeat(self, stopping: bool = False) -> NodeStatus:
        self._last_beat = self.clock()
        if self._phase_sent is not None:
            self._send_phase(self._now_t(), again=True)
        peers = self.driver.peers()
        no_robot = self._no_robot_warned and not self.robot_seen
        faulty = self.clock() - self._last_fault_at < self.config.fault_hold
        rivals = self.driver.rival_engines()
        tracking_rivals = sorted({r.source for r in self.driver.tracking_rivals()})
        degraded = (not all(peers.values()) or self.tracking in ("hold", "lost") or no_robot
                    or faulty or bool(rivals) or self.role != "owner" or bool(tracking_rivals))
        msg = NodeStatus(
            node=self.driver.node,
            seq=self._next("status"),
            stamp=time.time(),
            uptime=max(0.0, self.clock() - self._started),
            state="stopping" if stopping else ("degraded" if degraded else "ok"),
            tracking=self.tracking,
            peers=peers,
            dropped=self.driver.dropped(),
            phase=self.phase,
            info={
                "frames": self.frames_processed,
                "commands": self.commands_sent,
                "unsafe_commands": self.unsafe_commands,
                "behavior": self._behavior_state,
                "target": self._target,
                "robot_seen": self.robot_seen,
                "warnings": list(self.warnings),
                "role": self.role,
                "rivals": rivals,
                "tracking_sources": self.driver.tracking_sources(),
                "tracking_rivals": tracking_rivals,
                "faults": self.faults,
                "last_fault": self.last_fault,
            },
        )
        self.driver.publish_status(msg)
        return msg
