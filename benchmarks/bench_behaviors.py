"""Behavior machine and annotation tools against plain peers measured in the same run.

- machine tick: ``BehaviorMachine.target`` over a whole handover at 100 Hz (events included) for
  ``face-hand-face``, against a hand-written if/else implementation of the same timing;
- annotation loading: ``load_annotations`` (validating, reporting oddities) on the first 64 real
  files against a raw openpyxl read of the same cells (read-only, stop at the first empty frame);
- replay: ``gazebot.apps.annotations.replay`` of ``hand-face`` over all annotated receivers (events,
  contexts and the behavior machine frame by frame) against an independent plain-NumPy
  vectorised scoring of the same behavior (hand in reach and transfer, face from 0.375 s after
  each retreat start; ``Own Hand`` as hand, ``Other`` ignored); both must give the same matched
  and compared frame counts in every phase.

The annotation timings need the reference data (``GAZEBOT_SHARED_DATA`` or ``../shared/data``);
without it they are left out.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from benchmarks.common import Result, median_time
from gazebot.core.behaviors import BehaviorMachine, load_behavior
from gazebot.core.handover import apply_event
from gazebot.core.types import Event, EventKind, GazeContext, GazeTarget, Phase

_REPO = Path(__file__).resolve().parents[1]
_DATA = Path(os.environ.get("GAZEBOT_SHARED_DATA", _REPO.parent / "shared" / "data"))
_ANNOTATIONS = _DATA / "handover-gaze-annotations"

# One handover: reach 0-1 s, transfer 1-1.6 s, retreat 1.6-2.6 s, done; ticks at 100 Hz.
_PHASES = [(Phase.REACH, 0.0, 1.0), (Phase.TRANSFER, 1.0, 1.6), (Phase.RETREAT, 1.6, 2.6)]
_EVENTS = {
    0: [Event(EventKind.REACH_STARTED, 0.0, 0.0)],
    100: [Event(EventKind.TRANSFER_STARTED, 1.0, 1.0)],
    160: [Event(EventKind.RETREAT_STARTED, 1.6, 1.6)],
    260: [Event(EventKind.HANDOVER_DONE, 2.6, 2.6)],
}


def _contexts() -> list[GazeContext]:
    out = []
    for i in range(300):
        t = i / 100.0
        end = math.nan  # the tracking's prediction of the current phase's end (exact here)
        for _, a, b in _PHASES:
            if a <= t < b:
                end = b
        hand = np.array([1.0 - 0.2 * t, 0.0, 1.0])
        points = {
            "face": np.array([1.0, 0.0, 1.6]),
            "hand": hand,
            "object": hand,
            "handover_location": np.array([0.6, 0.0, 1.0]),
            "rest": np.array([0.4, 0.0, 0.8]),
        }
        out.append(GazeContext(t, points, tracking_end=end))
    return out


class PlainFaceHandFace:
    """The peer: face-hand-face (6.4.2) as a hand-written if/else, same halfway rule."""

    def __init__(self, reach_s: float = 0.8, retreat_s: float = 1.05) -> None:
        self.defaults = {Phase.REACH: reach_s, Phase.RETREAT: retreat_s}
        self.phase = Phase.IDLE
        self.start = 0.0
        self.shifted = False

    def handle(self, event: Event) -> None:
        new = {
            EventKind.REACH_STARTED: Phase.REACH,
            EventKind.TRANSFER_STARTED: Phase.TRANSFER,
            EventKind.RETREAT_STARTED: Phase.RETREAT,
            EventKind.HANDOVER_DONE: Phase.DONE,
        }.get(event.kind)
        if new is not None and new is not self.phase:
            self.phase, self.start, self.shifted = new, event.t, False

    def target(self, ctx: GazeContext) -> GazeTarget:
        phase, start = self.phase, self.start
        if phase in (Phase.REACH, Phase.RETREAT) and not self.shifted:
            end = ctx.tracking_end
            if not math.isfinite(end) or end <= start:
                end = start + self.defaults[phase]
            self.shifted = ctx.t >= start + 0.5 * (end - start)
        if phase is Phase.REACH:
            kind = "hand" if self.shifted else "face"
        elif phase is Phase.TRANSFER:
            kind = "hand"
        elif phase is Phase.RETREAT:
            kind = "face" if self.shifted else "hand"
        else:
            kind = "face"
        return GazeTarget(kind, ctx.points[kind])


def _run(machine, contexts: list[GazeContext]) -> list[str]:
    kinds = []
    for i, ctx in enumerate(contexts):
        for event in _EVENTS.get(i, ()):
            if isinstance(machine, BehaviorMachine):
                apply_event(machine.handover, machine, event)
            else:
                machine.handle(event)
        kinds.append(machine.target(ctx).kind)
    return kinds


def _machine_results() -> list[Result]:
    contexts = _contexts()
    spec = load_behavior("face-hand-face")
    machine = BehaviorMachine(spec)

    def ours() -> list[str]:
        machine.reset(0)
        return _run(machine, contexts)

    def peer() -> list[str]:
        return _run(PlainFaceHandFace(), contexts)

    if ours() != peer():
        raise AssertionError("the peer must produce the same gaze as the machine")
    n = len(contexts)
    t_ours = median_time(ours, repeat=7, number=5) / n
    t_peer = median_time(peer, repeat=7, number=5) / n
    t_build = median_time(lambda: BehaviorMachine(spec), repeat=5, number=3)
    return [
        Result(
            "face-hand-face tick (target + events)",
            t_ours * 1e6,
            t_peer * 1e6,
            "us/tick",
            "hand-written if/else",
            note=f"{n} ticks per handover; machine construction {t_build * 1e3:.2f} ms",
        )
    ]


def _raw_openpyxl(files: list[Path]) -> list[list[tuple]]:
    import openpyxl

    out = []
    for path in files:
        wb = openpyxl.load_workbook(path, read_only=True, data_only=True)
        rows = wb.worksheets[0].iter_rows(values_only=True)
        next(rows)
        cells = []
        for row in rows:
            if row[0] is None:
                break
            cells.append(row[:5])
        wb.close()
        out.append(cells)
    return out


def _annotation_results() -> list[Result]:
    if not _ANNOTATIONS.is_dir():
        return []
    from gazebot.apps.annotations import load_annotations, replay
    from gazebot.apps.annotations.loader import annotation_files, load_handover

    files = annotation_files(_ANNOTATIONS)[:64]

    def ours() -> list:
        return [load_handover(p) for p in files]

    t_ours = median_time(ours, repeat=3, warmup=1)
    t_peer = median_time(lambda: _raw_openpyxl(files), repeat=3, warmup=1)
    results = [
        Result(
            "annotation loading (64 xlsx files)",
            t_ours * 1e3 / len(files),
            t_peer * 1e3 / len(files),
            "ms/file",
            "raw openpyxl read-only loop",
            note="ours normalises labels and reports oddities",
        )
    ]
    annotations = load_annotations(_ANNOTATIONS)
    spec = load_behavior("hand-face")
    frames = sum(h.n_frames for h in annotations.handovers)
    delay_s = spec.parameters["retreat_face"].delay

    def ours() -> dict[str, tuple[int, int]]:
        r = replay(annotations, spec, "receiver")
        return {
            p: (
                sum(h.by_phase[p][0] for h in r.handovers),
                sum(h.by_phase[p][1] for h in r.handovers),
            )
            for p in ("reach", "transfer", "retreat")
        }

    def peer() -> dict[str, tuple[int, int]]:
        return numpy_replay_hand_face(annotations.handovers, "receiver", delay_s)

    if ours() != peer():
        raise AssertionError(f"replay peers disagree: ours {ours()} vs NumPy {peer()}")
    matched, compared = (sum(v[k] for v in ours().values()) for k in (0, 1))
    t_ours = median_time(ours, repeat=3)
    t_peer = median_time(peer, repeat=3)
    results.append(
        Result(
            f"replay hand-face over {len(annotations)} handovers",
            t_ours * 1e6 / frames,
            t_peer * 1e6 / frames,
            "us/frame",
            "plain NumPy vectorised scoring",
            note=f"{frames} frames; same match share {matched / compared:.4f} "
            f"({matched}/{compared}) from both",
        )
    )
    return results


def numpy_replay_hand_face(
    handovers, role: str, delay_s: float, fps: float = 8.0
) -> dict[str, tuple[int, int]]:
    """The peer: hand-face replay scoring written directly in NumPy over all frames at once.

    Robot gaze: hand in reach and transfer; in a retreat, hand until ``delay_s`` after the start
    of that retreat run, then face. Person's gaze: ``face``; ``hand`` and ``own_hand`` as hand;
    anything else ignored. Returns ``{phase: (matched, compared)}``.
    """
    phases = np.concatenate([np.asarray(h.phase(role)) for h in handovers])
    gaze = np.concatenate([np.asarray(h.gaze(role)) for h in handovers])
    first = np.zeros(phases.size, dtype=bool)
    first[np.cumsum([0] + [len(h.phase(role)) for h in handovers[:-1]])] = True
    idx = np.arange(phases.size)
    retreat = phases == "retreat"
    run_start = retreat & ~(np.roll(retreat, 1) & ~first)
    since_s = (idx - np.maximum.accumulate(np.where(run_start, idx, 0))) / fps
    robot_face = retreat & (since_s >= delay_s)
    human_face = gaze == "face"
    human_hand = (gaze == "hand") | (gaze == "own_hand")
    compared = human_face | human_hand
    matched = compared & np.where(robot_face, human_face, human_hand)
    return {
        p: (
            int(np.count_nonzero(matched & (phases == p))),
            int(np.count_nonzero(compared & (phases == p))),
        )
        for p in ("reach", "transfer", "retreat")
    }


def run() -> list[Result]:
    return _machine_results() + _annotation_results()
