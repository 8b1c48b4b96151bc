"""Public YCB-Handovers recordings (github paragkhanna1/YCB-Handovers: careful and non-careful
handovers of a full pitcher and cup, and baskets of other objects; 7.5 s windows of a
full-body mocap suit at 120 Hz), found through GAZEBOT_YCB_DATA or /work/data/ycb: one folder
per handover holding ``giver_RHand`` and ``taker_RHand`` pose CSVs (the dataset's
``*_pose.csv`` or ``.csv``). Never copied into the repository.

:func:`assess` scores one recording against issue 33's held-out bars, the same way
``tests/core/phases/test_phases_ycb.py`` does; ``python -m benchmarks.ycb_data [DIR]`` prints
them per recording (with the degraded copies) and the totals.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from benchmarks.degrade import KINDS, degraded
from gazebot.core.phases import PhaseConfig, Segment, Trajectory, run_online, segment
from gazebot.core.types import Event, EventKind, Phase

RATE = 120.0  # Hz, the dataset's mocap rate (901 rows = 7.5 s windows)
HANDS = ("giver_RHand", "taker_RHand")
MEET = 0.6  # m: right hands closer than this hold the object together (others use the left)
# m: hands that came this much farther apart again took an approach back (over marker noise
# and the sway of a full pitcher, 1-2 cm); the final approach starts after it
APART = 0.05
REACH_WINDOW = (-1.0, 0.15)  # s: a reach confirmed this long before / after the fifth of the gap


def in_reach_window(lag: float) -> bool:
    """Whether a reach confirmed ``lag`` s after the fifth of the gap meets the issue's bar."""
    return REACH_WINDOW[0] <= lag <= REACH_WINDOW[1]


def ycb_folders(root: str | Path | None = None) -> list[Path]:
    """The handover folders found under ``root`` (default: GAZEBOT_YCB_DATA, then
    /work/data/ycb; sorted; empty when the data is not on this machine)."""
    roots = [root] if root is not None else [os.environ.get("GAZEBOT_YCB_DATA"), "/work/data/ycb"]
    for r in roots:
        if r and Path(r).is_dir():
            found = sorted(
                d for d in Path(r).rglob("*") if d.is_dir()
                and all(any(d.glob(f"{h}*.csv")) for h in HANDS)
            )
            if found:
                return found
    return []


def load(folder: Path) -> Trajectory:
    """One recording's right hands (giver, taker) at the dataset's rate."""
    from gazebot.io.recordings import PointNames, load_recording

    return load_recording(folder, PointNames(*HANDS), rate=RATE).trajectory


def transfers(tr: Trajectory, config: PhaseConfig, pieces: bool = False) -> list[Segment]:
    """The transfers of complete handovers (reach, transfer and retreat): a window that begins
    or ends inside a neighbouring handover holds a piece of it, which is not the handover
    checked (``pieces``: keep them all, as for the seed rule's transfers)."""
    segs = segment(tr, config)
    whole = {s.handover for s in segs if s.phase is Phase.REACH}
    whole &= {s.handover for s in segs if s.phase is Phase.RETREAT}
    return [s for s in segs if s.phase is Phase.TRANSFER and (pieces or s.handover in whole)]


def closest(tr: Trajectory, d: np.ndarray, transfer: Segment) -> float:
    """When the hands were closest in this handover: between the farthest they were before the
    transfer and the farthest after it (a piece of a neighbouring handover may come closer)."""
    a, b = np.searchsorted(tr.t, [transfer.start, transfer.end])
    i0 = int(np.nanargmax(d[:a])) if a else 0
    i1 = int(b) + int(np.nanargmax(d[b:]))
    return float(tr.t[i0 + int(np.nanargmin(d[i0 : i1 + 1]))])


def approach_start(d: np.ndarray, i1: int, apart: float = APART) -> int:
    """Where the final approach before grid index ``i1`` began: where the hands were last
    farthest apart, after any point from which they had come ``apart`` farther apart again (an
    approach taken back part of the way ends there; ``inf``: the farthest before ``i1``)."""
    seen = np.isfinite(d[:i1]).nonzero()[0]
    x = d[seen]
    farthest_on = np.maximum.accumulate(x[::-1])[::-1]  # the farthest from each sample on
    nearer = (x < farthest_on - apart).nonzero()[0]
    k = int(nearer[-1]) if nearer.size else 0
    return int(seen[k + int(np.argmax(x[k:]))])


def fifth_of_gap(tr: Trajectory, d: np.ndarray, start: float, apart: float = APART) -> float:
    """When the hands had closed 20 % of the final approach's gap: from where that approach
    began (:func:`approach_start`) to where they hold before the transfer starting at
    ``start`` (median of the last 0.1 s); NaN if no approach closed in before it."""
    i1 = int(np.searchsorted(tr.t, start))
    i0 = approach_start(d, i1, apart)
    tenth = int(round(0.1 / float(np.median(np.diff(tr.t)))))  # samples in 0.1 s
    d0, d1 = d[i0], float(np.nanmedian(d[max(i1 - tenth, 0) : i1 + 1]))
    closed = np.flatnonzero(d[i0:i1] <= d0 - 0.2 * (d0 - d1))
    return float(tr.t[i0 + closed[0]]) if closed.size else float("nan")


@dataclass
class Assessment:
    """One recording against issue 33's bars (``meets``: its right hands hold the object; the
    others are not scored).

    Attributes:
        offline: One complete transfer within 0.3 s of the seed rule's at both ends, holding
            the closest point.
        online: Exactly one online transfer start within 0.35 s of the offline start.
        reach: The last online reach before that start confirmed 1.0 s before to 0.15 s after
            the hands closed a fifth of the final approach's gap (:func:`fifth_of_gap`).
        reach_lag: That reach's confirmation minus the fifth (s; NaN without one).
        reach_lag_window: ... minus the fifth of the gap from the farthest the hands were in
            the window before the transfer (an approach taken back counts; not the bar).
        degraded: Per degraded copy (kind, draw, whether it keeps the transfer within 0.25 s
            at both ends).
    """

    name: str
    meets: bool
    ours: list[Segment] = field(default_factory=list)
    seed: list[Segment] = field(default_factory=list)
    events: list[Event] = field(default_factory=list)
    offline: bool = False
    online: bool = False
    reach: bool = False
    reach_lag: float = float("nan")
    reach_lag_window: float = float("nan")
    degraded: list[tuple[str, int, bool]] = field(default_factory=list)


def assess(folder: Path, degrade: bool = False) -> Assessment:
    """Score one recording (``degrade``: also its 20 degraded copies, as the test makes them)."""
    tr = load(folder)
    d = np.linalg.norm(tr.giver_hand - tr.receiver_hand, axis=1)
    if not np.nanmin(d) < MEET:
        return Assessment(folder.name, False)
    ours = transfers(tr, PhaseConfig())
    seed = transfers(tr, PhaseConfig(method="seed-7.2.5"), pieces=True)
    events = run_online(tr).events
    out = Assessment(folder.name, True, ours, seed, events)
    if len(ours) != 1:
        return out
    o = ours[0]
    if seed:
        s = min(seed, key=lambda x: abs(x.start - o.start))
        out.offline = (
            abs(o.start - s.start) <= 0.3 and abs(o.end - s.end) <= 0.3
            and o.start <= closest(tr, d, o) <= o.end
        )
    starts = [e.t for e in events if e.kind is EventKind.TRANSFER_STARTED]
    out.online = sum(abs(t - o.start) <= 0.35 for t in starts) == 1
    k = [i for i, e in enumerate(events)
         if e.kind is EventKind.TRANSFER_STARTED and abs(e.t - o.start) <= 0.35]
    reach = [e for e in events[: k[0]] if e.kind is EventKind.REACH_STARTED] if k else []
    if reach:
        out.reach_lag = reach[-1].detected_at - fifth_of_gap(tr, d, o.start)
        out.reach_lag_window = reach[-1].detected_at - fifth_of_gap(tr, d, o.start, np.inf)
        out.reach = in_reach_window(out.reach_lag)
    if degrade:
        for how in [*KINDS, "all"]:
            for i in range(4):
                got = transfers(degraded(tr, how, np.random.default_rng(100 + i)), PhaseConfig())
                ok = (len(got) == 1 and abs(got[0].start - o.start) <= 0.25
                      and abs(got[0].end - o.end) <= 0.25)
                out.degraded.append((how, i, ok))
    return out


def _spans(segs: list[Segment]) -> str:
    return " ".join(f"{s.start:.2f}-{s.end:.2f}" for s in segs) or "-"


def main(argv: list[str]) -> int:
    """Print each recording's scores and the totals."""
    folders = ycb_folders(argv[0] if argv else None)
    if not folders:
        print("no YCB-Handovers recordings found (give a folder or set GAZEBOT_YCB_DATA)")
        return 1
    scored = []
    for folder in folders:
        a = assess(folder, degrade=True)
        if not a.meets:
            print(f"{a.name}: right hands never meet (not scored)")
            continue
        scored.append(a)
        missed = [f"{h}#{i}" for h, i, ok in a.degraded if not ok]
        print(
            f"{a.name}: ours {_spans(a.ours)}, seed rule {_spans(a.seed)}; offline {a.offline:d} "
            f"online {a.online:d} reach {a.reach:d} ({a.reach_lag:+.2f} s; from the window's "
            f"farthest {a.reach_lag_window:+.2f} s); degraded "
            f"{len(a.degraded) - len(missed)}/{len(a.degraded)} {' '.join(missed)}"
        )
    n = len(scored)
    copies = [ok for a in scored for _, _, ok in a.degraded]
    print(
        f"{n} recordings: offline {sum(a.offline for a in scored)}, online start "
        f"{sum(a.online for a in scored)}, reach {sum(a.reach for a in scored)} (from the window's "
        f"farthest {sum(in_reach_window(a.reach_lag_window) for a in scored)}), degraded copies "
        f"{sum(copies)} of {len(copies)}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
