"""The gaze engine: composes phases -> handover state -> behavior -> gaze target -> kinematics,
one tick at a time.

The engine owns no transport and no simulator; a robot stack calls :meth:`GazeEngine.step` with each
tracking frame and sends the returned :class:`~gazebot.core.types.GazeCommand` wherever it likes.

One handover state (:class:`~gazebot.core.handover.HandoverState`) merges the phase detector's
events
and the robot's (:meth:`GazeEngine.notify`); the behavior reads its phase, and the command
reports it with its source. The engine never dies on input: a tracked point beyond the robot's
``workspace_radius_m`` is a missing sample (counted in :attr:`GazeEngine.stats`), and whatever a
sample or an event makes a stage raise is caught, reported as a ``fault`` event and the command's
``status: degraded``, and the tick still answers with a safe command.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from gazebot.core.behaviors import BehaviorMachine, BehaviorSpec, load_behavior
from gazebot.core.config import ConfigError
from gazebot.core.defaults import DEFAULT_BEHAVIOR, DEFAULT_ROBOT
from gazebot.core.handover import HandoverState, PhaseChange
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
    F64,
    NAN3,
    PHASE_OF_EVENT,
    Event,
    EventKind,
    GazeCommand,
    Phase,
    PhaseSource,
    Status,
    TrackingFrame,
    TrackingState,
    from_fields,
)

# Targets the engine fills from tracking each tick; all others come from the robot config.
_TRACKED_TARGETS = frozenset({"face", "hand", "object", "receiver_hand"})
# Robot events whose phase change the phase detector adopts (it cannot see a grasp).
_DETECTOR_ADOPTS = frozenset({EventKind.ROBOT_GRASPED, EventKind.ROBOT_RELEASED})


class PhaseDetectorLike(Protocol):
    """What the engine needs of a phase detector (:class:`gazebot.core.phases.PhaseDetector`)."""

    phase: Phase
    expected_phase_end: float

    def update_all(self, frame: TrackingFrame) -> list[Event]: ...

    def resync(self, event: Event) -> None: ...

    def adopt(self, phase: Phase, t0: float) -> None: ...


@dataclass
class EngineStats:
    """What the engine bridged or survived (counts since the last reset)."""

    implausible: int = 0  # tracked points beyond the workspace, treated as missing
    faults: int = 0  # exceptions a sample or an event caused, caught and reported


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
        self._radius = float(robot.config.workspace_radius_m)
        # The workspace sphere's squared radius, finite even for an absurd radius (so a sum of
        # squares that overflowed to inf is always beyond it).
        self._radius_sq = min(self._radius * self._radius, sys.float_info.max)
        self._seed = seed
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
        return self.behavior.tracking  # type: ignore[return-value]

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
        t = frame.t
        # The usual frame's time (a float after the last one) without _time's checks.
        if type(t) is float and self._last_t < t < math.inf:
            self._last_t = t
        else:
            t = self._time(frame)
        frame = self._plausible(frame)
        try:
            # Every event this sample reveals (a gripper closing can reveal a reach and a
            # transfer).
            events = self.detector.update_all(frame)
        except Exception as err:  # noqa: BLE001 - a sample must never kill the engine
            events = []
            faults.append(self._fault(t, "phases", err))
        if self._pending:
            events.extend(self._pending)
            self._pending.clear()
        stream: list[Event] = []  # the tick's events, phase events as the handover state's
        for event in events:
            try:
                stream.extend(self._apply(event))
            except Exception as err:  # noqa: BLE001 - an event must never kill the engine
                faults.append(self._fault(t, f"event {getattr(event, 'kind', event)!r}", err))
        detector = self.detector
        state = self.handover
        tracking_end = (
            detector.expected_phase_end if detector.phase is state.phase else math.nan
        )
        # The behavior's points: the robot's fixed ones and the tracked ones (a copy then item
        # sets: cheaper than a ``{**fixed, ...}`` merge, with the same key order).
        points = self._fixed_points.copy()
        points["face"] = frame.giver_face
        points["hand"] = points["object"] = frame.giver_hand
        points["receiver_hand"] = frame.receiver_hand
        try:
            # behavior.target(GazeContext(...)) without the two values it would build
            kind, point = self.behavior.aim(t, points, tracking_end)
        except Exception as err:  # noqa: BLE001
            faults.append(self._fault(t, "behavior", err))
            kind, point = self._last_target
        # (the usual tick has no event: no tuple to build)
        published = (*stream, *faults) if stream or faults else ()
        return self._command(t, kind, point, arm, published, faults)

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
        phase and robot events published before the restart, oldest first."""
        for event in sorted(_events(events), key=lambda e: e.t):
            self.detector.resync(event)
            self.behavior.handle(event)

    def reset(self, head: Mapping[str, float] | None = None) -> None:
        """Forget the current handover (e.g. after a restart) and optionally the head pose."""
        self.detector: PhaseDetectorLike = make_detector(self._phase_config)
        if hasattr(self, "behavior"):  # reuse the machine: building one costs milliseconds
            self.handover.reset()
            self.behavior.reset()
        else:
            self.handover = HandoverState()
            self.behavior = BehaviorMachine(
                self.behavior_spec, seed=self._seed, handover=self.handover,
                defaults=self._defaults,
            )
        self.gaze.reset(head)
        self.stats = EngineStats()
        self._pending: list[Event] = []
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
        t = frame.t
        if type(t) is not float:  # (a frame's usual t already is one)
            try:
                t = float(t)
            except (TypeError, ValueError, OverflowError):
                t = math.nan
        if math.isfinite(t) and t > self._last_t:  # max() as a comparison (the hot path)
            self._last_t = t
        return self._last_t if math.isfinite(self._last_t) else 0.0

    def _plausible(self, frame: TrackingFrame) -> TrackingFrame:
        """``frame`` with every point beyond the workspace (or not a numeric 3-vector) missing."""
        rr = self._radius_sq
        f64 = F64
        hand, receiver, face = frame.giver_hand, frame.receiver_hand, frame.giver_face
        # The usual frame (three float64 3-vectors, each inside the workspace or all-NaN) in
        # one test: a fifth cheaper than the loop below, which decides every other frame.
        if (
            type(hand) is np.ndarray
            and type(receiver) is np.ndarray
            and type(face) is np.ndarray
            and hand.dtype is f64
            and receiver.dtype is f64
            and face.dtype is f64
            and hand.shape == receiver.shape == face.shape == (3,)
        ):
            x, y, z = hand.tolist()
            a, b, c = receiver.tolist()
            u, v, w = face.tolist()
            s1, s2, s3 = x * x + y * y + z * z, a * a + b * b + c * c, u * u + v * v + w * w
            if (s1 <= rr or s1 != s1) and (s2 <= rr or s2 != s2) and (s3 <= rr or s3 != s3):
                return frame
        changed = {}
        for name, p in (("giver_hand", hand), ("receiver_hand", receiver), ("giver_face", face)):
            # ``is`` first: the usual array's dtype is the float64 singleton (cheaper than .kind)
            if (
                type(p) is np.ndarray
                and (p.dtype is f64 or p.dtype.kind == "f")
                and p.shape == (3,)
            ):
                x, y, z = p.tolist()  # plain floats: numpy per-call overhead is microseconds
            else:
                try:
                    x, y, z = (float(v) for v in np.asarray(p, dtype=float).reshape(3))
                except (TypeError, ValueError, OverflowError):
                    changed[name] = NAN3.copy()
                    continue
                changed[name] = np.array([x, y, z])
            # One comparison for the usual point: a float product overflows to inf (beyond
            # the radius, as it should be), never raises; any NaN coordinate makes it NaN.
            s = x * x + y * y + z * z
            if s <= rr or s != s:
                continue  # within the workspace, or already missing (NaN)
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

    def _apply(self, event: Event) -> list[Event]:
        """One event through the behavior (and so the handover state); returns what it adds
        to the tick's events. A phase event is passed on only when it changed the handover's
        phase (the stream published is the one phase stream); a robot event that changed it
        is followed by that phase's event (``info.source`` ``robot`` or ``gripper``,
        ``info.evidence`` the robot event). A grasp or a release the detector cannot see moves
        its phase too."""
        change: PhaseChange | None = self.behavior.handle(event)
        kind = getattr(event, "kind", None)
        if kind in PHASE_OF_EVENT:
            return [event] if change is not None else []
        out = [event]
        if change is not None:
            if change.rule.trigger in _DETECTOR_ADOPTS:
                self.detector.adopt(change.phase, change.t)
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
            q, yaw, pitch, residual, shift = self.gaze.update_raw(t, point, arm)
            # One float sum instead of a check per value: finite values of these sizes (angles,
            # rad) cannot overflow, so the sum is finite exactly when every value is.
            ok = math.isfinite(yaw + pitch + residual + shift + sum(q))
            names = self._head_names
            n = len(names)
            # A goal for every head joint, checked by length (zip's strict mode costs more).
            if len(q) != n:
                raise ValueError(f"{len(q)} head joint goals for {n} head joints")
            # (a one-joint head's dict as a display: a quarter of dict(zip())'s cost)
            head = {names[0]: q[0]} if n == 1 else dict(zip(names, q))  # noqa: B905 - checked
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
        status: Status = "degraded" if faults or not ok else "ok"
        handover = self.handover
        # ``is`` first: comparing a dtype with the np.float64 type converts it on every call
        if type(point) is not np.ndarray or (point.dtype is not F64 and point.dtype != F64):
            point = np.asarray(point, float)  # (the behavior's points already are)
        cmd = from_fields(
            GazeCommand,
            {  # every field, in field order (GazeCommand's dataclass fields)
                "t": t,
                "phase": handover.phase,
                "target": kind,
                "target_point": point,
                "head": head,
                "eye_yaw": yaw,
                "eye_pitch": pitch,
                "residual": residual,
                "phase_source": handover.source,
                "gaze_shift": shift,
                "tracking": self.behavior.tracking,
                "status": status,
                "blink": 0.0,
                "distance": None,
                "answers_sample": True,
                "events": events,
            },
        )
        if ok:
            self._last_safe = cmd
        return cmd
