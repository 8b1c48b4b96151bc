"""The gaze engine: composes phases -> handover state -> behavior -> gaze target -> kinematics,
one tick at a time.

The engine owns no transport and no simulator; a robot stack calls :meth:`GazeEngine.step` with each
tracking frame and sends the returned :class:`~gazebot.core.types.GazeCommand` wherever it likes.

One handover state (:class:`~gazebot.core.handover.HandoverState`) holds the phase. Each tick the
phase detector reads it and reports the boundaries the tracking shows; the engine applies those
and the robot's events (:meth:`GazeEngine.notify`) to the state; the behavior reacts to its
phase changes and to the tick, and the command reports the phase with its source. The engine
never dies on input: a tracked point beyond the robot's ``workspace_radius_m`` is a missing
sample (counted in :attr:`GazeEngine.stats`), and whatever a sample or an event makes a stage
raise is caught, reported as a ``fault`` event and the command's ``status: degraded``, and the
tick still answers with a safe command.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from gazebot.core.behaviors import BehaviorMachine, BehaviorSpec, load_behavior
from gazebot.core.behaviors.segment import TRACKED_TARGETS
from gazebot.core.config import ConfigError
from gazebot.core.defaults import DEFAULT_BEHAVIOR, DEFAULT_ROBOT
from gazebot.core.handover import HandoverState, HandoverView, apply_event
from gazebot.core.kinematics import (
    GazeController,
    GazeShiftConfig,
    IKConfig,
    RobotConfig,
    RobotModel,
)
from gazebot.core.phases import PhaseConfig, load_phase_config, make_detector
from gazebot.core.types import (
    EVENT_OF_PHASE,
    NAN3,
    PHASE_OF_EVENT,
    Event,
    EventKind,
    GazeCommand,
    Phase,
    PhaseSource,
    TrackingFrame,
    TrackingState,
)

# Targets the engine fills from tracking each tick; all others come from the robot config.
_TRACKED_TARGETS = TRACKED_TARGETS


class PhaseDetectorLike(Protocol):
    """What the engine needs of a phase detector (:class:`gazebot.core.phases.PhaseDetector`)."""

    def update(
        self, frame: TrackingFrame, view: HandoverView, report: Callable[[Event], object]
    ) -> None:
        """Feed one frame; report every event it reveals to ``report``, which applies it to the
        state ``view`` reads."""

    def expected_end(self, view: HandoverView) -> float:
        """The estimated end of ``view``'s phase (s; NaN when unknown)."""

    def resync(self) -> None:
        """The handover state was replayed (e.g. after an engine restart): join the phase under
        way."""


@dataclass
class EngineStats:
    """What the engine bridged or survived (counts since the last reset)."""

    implausible: int = 0  # tracked points beyond the workspace, treated as missing
    faults: int = 0  # exceptions a sample or an event caused, caught and reported


# The tracked points of a frame, in the order the engine checks them.
_POINTS = ("giver_hand", "receiver_hand", "giver_face")


def _events(events: Event | Iterable[Event]) -> list[Event]:
    return [events] if isinstance(events, Event) else list(events)


class GazeEngine:
    """Turns tracking frames into head joint goals and eye angles.

    Args:
        robot: The robot's kinematic model (head joints, limits, gaze frame, eye range).
        behavior: The gaze behavior to run.
        phases: Phase detection thresholds.
        shifts: Gaze shift timing (neck and eye durations); ``None``: the robot YAML's.
        ik: Look-at solver settings; ``None``: the robot YAML's ``ik``.
        seed: Seed for behaviors that draw random timings (reproducible runs).
    """

    def __init__(
        self,
        robot: RobotModel,
        behavior: BehaviorSpec,
        phases: PhaseConfig | None = None,
        shifts: GazeShiftConfig | None = None,
        seed: int = 0,
        ik: IKConfig | None = None,
    ) -> None:
        missing = behavior.targets() - set(robot.points) - _TRACKED_TARGETS
        if missing:
            raise ConfigError(
                f"behavior '{behavior.name}'",
                "targets",
                f"points the robot '{robot.name}' defines ({', '.join(sorted(robot.points))}) "
                f"or tracked ones ({', '.join(sorted(_TRACKED_TARGETS))})",
                sorted(missing),
            )
        self.robot = robot
        self.behavior_spec = behavior
        self._phase_config = phases or PhaseConfig()
        self.gaze = GazeController(robot, shifts, ik)
        self._head_names = tuple(robot.head_joints)
        self._fixed_points = {k: np.asarray(v, float) for k, v in robot.points.items()}
        fixed = self._fixed_points
        # A tracked point never seen yet: the robot's default for it.
        self._defaults = {
            "face": fixed["face"],
            "hand": fixed["handover_location"],
            "object": fixed["handover_location"],
            "receiver_hand": fixed["rest"],
        }
        radius = float(robot.config.workspace_radius_m)
        # The workspace sphere's squared radius, finite even for an absurd radius (so a sum of
        # squares that overflowed to inf is always beyond it).
        self._radius_sq = min(radius * radius, sys.float_info.max)
        #: The one handover state: the phase, its start and the handover index.
        self.handover = HandoverState()
        self.behavior = BehaviorMachine(
            behavior, seed=seed, handover=self.handover, defaults=self._defaults
        )
        self.detector: PhaseDetectorLike = make_detector(self._phase_config)
        self._pending: list[Event] = []  # robot events for the next tick
        self.reset()

    @classmethod
    def from_config(
        cls,
        robot: str | Path | RobotConfig = DEFAULT_ROBOT,
        behavior: str | Path = DEFAULT_BEHAVIOR,
        phases: str | Path | PhaseConfig | None = None,
        shifts: GazeShiftConfig | None = None,
        seed: int = 0,
    ) -> GazeEngine:
        """Build an engine from names or YAML paths.

        Args:
            robot: Robot name (``sawyer``, ``jaco2``), a robot YAML file or a loaded config.
            behavior: Behavior name (see ``gazebot behaviors list``) or a behavior YAML file.
            phases: Phase config YAML file or object; ``None`` for ``configs/phases.yaml``.
        """
        model = RobotModel.load(robot)
        spec = load_behavior(behavior)
        phase_cfg = phases if isinstance(phases, PhaseConfig) else load_phase_config(phases)
        return cls(model, spec, phase_cfg, shifts, seed)

    @property
    def phase(self) -> Phase:
        """The handover state's phase (the one the behavior runs and commands report)."""
        return self.handover.phase

    @property
    def phase_source(self) -> PhaseSource:
        """What decided the current phase: ``tracking``, ``robot`` or ``gripper``."""
        return self.handover.source

    @property
    def tracking(self) -> TrackingState:
        """The behavior's tracking state after the last step: ``ok``; ``hold`` while tracking is
        lost and the behavior holds the gaze (its ``tracking_lost.hold_s``); ``lost`` once it
        looks at its ``tracking_lost`` target."""
        return self.behavior.tracking

    def notify(self, events: Event | Iterable[Event]) -> None:
        """Queue one robot event or several (e.g. ``robot_reach_started`` with
        ``planned_duration``) for the next :meth:`step`."""
        self._pending.extend(_events(events))

    # ----------------------------------------------------------------- the tick
    def step(self, frame: TrackingFrame, arm: Mapping[str, float] | None = None) -> GazeCommand:
        """Advance one tick with ``frame`` and return the command for the head and the eyes.

        ``arm`` is the robot's measured arm joint positions (rad) by name; pass it when the arm
        carries the head (Sawyer's head sits on ``right_j0``) so the head goals compensate.

        Out-of-order frames are handed to the phase detector (which ignores them) and answered
        with the previous command's goals, so the output never jumps back in time. Never raises
        for what a sample or an event holds (see the module docstring).
        """
        faults: list[Event] = []
        stream: list[Event] = []  # the tick's events, phase events as the handover state's
        t = self._time(frame)
        frame = self._plausible(frame)

        def report(event: Event) -> None:
            self._take(event, t, stream, faults)

        try:
            # Every event this sample reveals, each applied before the detector looks further
            # (a gripper closing can reveal a reach and a transfer).
            self.detector.update(frame, self.handover, report)
        except Exception as err:  # noqa: BLE001 - a sample must never kill the engine
            faults.append(self._fault(t, "phases", err))
        pending, self._pending = self._pending, []
        for event in pending:
            report(event)
        try:
            tracking_end = self.detector.expected_end(self.handover)
        except Exception as err:  # noqa: BLE001
            faults.append(self._fault(t, "phases", err))
            tracking_end = math.nan
        points = {
            **self._fixed_points,
            "face": frame.giver_face,
            "hand": frame.giver_hand,
            "object": frame.giver_hand,
            "receiver_hand": frame.receiver_hand,
        }
        try:
            kind, point = self.behavior.aim(t, points, tracking_end)
        except Exception as err:  # noqa: BLE001
            faults.append(self._fault(t, "behavior", err))
            kind, point = self._last_target
        return self._command(t, kind, point, arm, (*stream, *faults), faults)

    def look_at(
        self,
        t: float,
        point: np.ndarray,
        target: str = "face",
        arm: Mapping[str, float] | None = None,
    ) -> GazeCommand:
        """Point the head and eyes at a fixed ``point`` (base frame, m), bypassing the behavior.

        A fallback for a robot stack, e.g. the last face position while tracking is lost; the
        gaze shift timing and limits still apply. The phase is left as it is.
        """
        t = self._time(TrackingFrame(t=t))
        return self._command(t, target, np.asarray(point, float), arm, (), [])

    def resync(self, events: Iterable[Event]) -> None:
        """Catch up with a handover already under way (e.g. after an engine restart): replay the
        phase and robot events published before the restart, oldest first, into the handover
        state; the phase detector then joins the phase under way, and takes the next frame's
        robot evidence as a baseline."""
        replay = sorted(_events(events), key=lambda e: e.t)
        for event in replay:
            apply_event(self.handover, self.behavior, event)
        if replay:
            # (also after a finished handover: a gripper still closed is no new grasp)
            self.detector.resync()

    def reset(self, head: Mapping[str, float] | None = None) -> None:
        """Forget the current handover (e.g. after a restart) and optionally the head pose."""
        self.detector = make_detector(self._phase_config)
        self.handover.reset()
        self.behavior.reset()  # (the machine is kept: building one takes milliseconds)
        self.gaze.reset(head)
        self.stats = EngineStats()
        self._pending = []
        self._last_t = -math.inf
        self._last_target: tuple[str, np.ndarray] = (
            self.behavior_spec.before,
            self._defaults["face"],
        )
        self._last_safe: GazeCommand | None = None

    # ----------------------------------------------------------------- internals
    def _time(self, frame: TrackingFrame) -> float:
        """The tick's time: the frame's, never earlier than the last one; a frame without a
        usable time is answered at the last known time."""
        try:
            t = float(frame.t)
        except (TypeError, ValueError, OverflowError):
            t = math.nan
        if math.isfinite(t) and t > self._last_t:
            self._last_t = t
        return self._last_t if math.isfinite(self._last_t) else 0.0

    def _plausible(self, frame: TrackingFrame) -> TrackingFrame:
        """``frame`` with every point beyond the workspace (or not a numeric 3-vector) missing."""
        changed: dict[str, np.ndarray] = {}
        for name in _POINTS:
            p = getattr(frame, name)
            kept = _is_float3(p)
            try:
                x, y, z = (p if kept else np.asarray(p, dtype=float).reshape(3)).tolist()
            except (TypeError, ValueError, OverflowError):
                changed[name] = NAN3.copy()
                continue
            if not kept:
                changed[name] = np.array([x, y, z])
            # A float product overflows to inf (beyond the radius, as it should be), never
            # raises; any NaN coordinate makes the sum NaN: a point already missing.
            r2 = x * x + y * y + z * z
            if r2 > self._radius_sq:
                self.stats.implausible += 1
                changed[name] = NAN3.copy()
        if not changed:
            return frame
        return TrackingFrame(
            t=frame.t,
            giver_hand=changed.get("giver_hand", frame.giver_hand),
            receiver_hand=changed.get("receiver_hand", frame.receiver_hand),
            giver_face=changed.get("giver_face", frame.giver_face),
            gripper_closed=frame.gripper_closed,
            load_share=frame.load_share,
        )

    def _take(self, event: Event, t: float, stream: list[Event], faults: list[Event]) -> None:
        """Apply ``event`` (the detector's or the robot's) and add what it publishes to
        ``stream``; an event that raises is a fault."""
        try:
            stream.extend(self._apply(event))
        except Exception as err:  # noqa: BLE001 - an event must never kill the engine
            faults.append(self._fault(t, f"event {getattr(event, 'kind', event)!r}", err))

    def _apply(self, event: Event) -> list[Event]:
        """One event through the handover state (the behavior follows its changes); returns
        what it adds to the tick's events. A phase event is passed on only when it changed the
        handover's phase (the stream published is the one phase stream); a robot event that
        changed it is followed by that phase's event (``info.source`` ``robot`` or
        ``gripper``, ``info.evidence`` the robot event)."""
        change = apply_event(self.handover, self.behavior, event)
        if getattr(event, "kind", None) in PHASE_OF_EVENT:
            return [event] if change is not None else []
        out = [event]
        if change is not None:
            info = {
                "handover": self.handover.handover,
                "source": change.source,
                "evidence": change.rule.trigger.value,
            }
            detected = getattr(event, "detected_at", change.t)
            out.append(Event(EVENT_OF_PHASE[change.phase], change.t, detected, info))
        return out

    def _fault(self, t: float, stage: str, err: BaseException) -> Event:
        self.stats.faults += 1
        info = {"stage": stage, "error": f"{type(err).__name__}: {err}"[:200]}
        return Event(EventKind.FAULT, t, t, info)

    def _command(
        self,
        t: float,
        kind: str,
        point: np.ndarray,
        arm: Mapping[str, float] | None,
        events: tuple[Event, ...],
        faults: list[Event],
    ) -> GazeCommand:
        """The command for ``kind`` at ``point``; the last safe one (or rest) if the kinematics
        fail or give a non-finite value."""
        try:
            q, yaw, pitch, residual, shift = self.gaze.step(t, point, arm)
            names = self._head_names
            if len(q) != len(names):
                raise ValueError(f"{len(q)} head joint goals for {len(names)} head joints")
            head = dict(zip(names, q, strict=True))
            ok = all(math.isfinite(v) for v in (yaw, pitch, residual, shift, *q))
        except Exception as err:  # noqa: BLE001 - e.g. a joint reading that is no number
            faults.append(self._fault(t, "kinematics", err))
            events = (*events, faults[-1])
            ok = False
        if not ok:
            last = self._last_safe
            head = dict(last.head) if last is not None else self.robot.head_dict(self.robot.rest)
            yaw, pitch = (last.eye_yaw, last.eye_pitch) if last is not None else (0.0, 0.0)
            residual = last.residual if last is not None else 0.0
            shift = 0.0
        self._last_target = (kind, point)
        cmd = GazeCommand(
            t=t,
            phase=self.handover.phase,
            target=kind,
            target_point=np.asarray(point, dtype=float),
            head=head,
            eye_yaw=yaw,
            eye_pitch=pitch,
            residual=residual,
            phase_source=self.handover.source,
            gaze_shift=shift,
            tracking=self.behavior.tracking,
            status="degraded" if faults or not ok else "ok",
            events=events,
        )
        if ok:
            self._last_safe = cmd
        return cmd


def _is_float3(p: object) -> bool:
    """``p`` is a float array of three values (kept as it is)."""
    return isinstance(p, np.ndarray) and p.dtype.kind == "f" and p.shape == (3,)
