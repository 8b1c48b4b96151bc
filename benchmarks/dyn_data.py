"""Public dynamic-handover recordings (github hyeonseong-kim98/dynamic_handover_dataset: 1,000
human-human handovers, many on the move, ZED2i body tracking at 30 Hz, 34 keypoints a person),
found through GAZEBOT_DYN_DATA or /work/data/dyn: ``motion_*.pkl`` files under its
``data/whole_motions`` folder. Never copied into the repository. The files are Python pickles:
read them only from that public dataset.

No force truth: :func:`assess` scores one recording the way issue 33 reads this set, against
the seed rule (``seed-7.2.5``) where it finds a transfer: the default's transfer within 0.3 s
of its ends, the online transfer start within 0.35 s of the offline one, and degraded
copies (NaN bursts, 5 mm noise, 6 cm marker offsets, all at once: the set is already 30 Hz)
keeping the transfer within 0.25 s. The reach is not scored here: many pairs walk toward each
other, so the hands' distance closes with the walk, not the giver's reach.
``python -m benchmarks.dyn_data [DIR] [N]`` prints the first ``N`` motions (by number, default
30) and the totals.
"""

from __future__ import annotations

import os
import pickle
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from benchmarks.degrade import degraded
from benchmarks.ycb_data import transfers
from gazebot.core.phases import PhaseConfig, Trajectory, run_online
from gazebot.core.types import EventKind

RATE = 30.0  # Hz, the ZED2i's body tracking
RIGHT_HAND = 15  # the ZED BODY_34 keypoint of the right hand (givers hand over with it)
KINDS = ("nan", "noise", "offset", "all")  # degraded copies (resampling to 30 Hz changes nothing)


def dyn_files(root: str | Path | None = None) -> list[Path]:
    """The motion files found under ``root`` (default: GAZEBOT_DYN_DATA, then /work/data/dyn),
    in-distribution ones first, each kind by its number; empty when the data is not here."""
    roots = [root] if root is not None else [os.environ.get("GAZEBOT_DYN_DATA"), "/work/data/dyn"]
    for r in roots:
        if r and Path(r).is_dir():
            found = list(Path(r).rglob("motion_*.pkl"))
            if found:
                return sorted(found, key=lambda p: (p.stem.rsplit("_", 1)[0] != "motion_normal",
                                                    p.stem.rsplit("_", 1)[0],
                                                    int(p.stem.rsplit("_", 1)[1])))
    return []


def load(path: Path) -> Trajectory:
    """One motion's right hands (giver, receiver) at the set's rate."""
    with path.open("rb") as f:
        m = pickle.load(f)  # noqa: S301 (the public dataset's own format)
    giver = np.asarray(m["pose_giver"], dtype=float)[:, RIGHT_HAND]
    receiver = np.asarray(m["pose_receiver"], dtype=float)[:, RIGHT_HAND]
    return Trajectory(np.arange(giver.shape[0]) / RATE, giver, receiver)


@dataclass
class Assessment:
    """One motion against the seed rule (``scored``: the seed rule finds a transfer in it).

    Attributes:
        offline: The default's transfer nearest the seed rule's first is within 0.3 s of it
            at both ends.
        online: An online transfer start within 0.35 s of that transfer's start.
        degraded: Per degraded copy (kind, whether it keeps a transfer within 0.25 s at both
            ends).
    """

    name: str
    scored: bool
    offline: bool = False
    online: bool = False
    degraded: list[tuple[str, bool]] = field(default_factory=list)


def assess(path: Path) -> Assessment:
    """Score one motion (with one degraded copy of each kind, drawn from a fixed seed)."""
    tr = load(path)
    seed = transfers(tr, PhaseConfig(method="seed-7.2.5"), pieces=True)
    if not seed:
        return Assessment(path.stem, False)
    out = Assessment(path.stem, True)
    ours = transfers(tr, PhaseConfig(), pieces=True)
    if not ours:
        return out
    s = seed[0]
    o = min(ours, key=lambda x: abs(x.start - s.start))
    out.offline = abs(o.start - s.start) <= 0.3 and abs(o.end - s.end) <= 0.3
    out.online = any(e.kind is EventKind.TRANSFER_STARTED and abs(e.t - o.start) <= 0.35
                     for e in run_online(tr).events)
    for how in KINDS:
        got = transfers(degraded(tr, how, np.random.default_rng(0)), PhaseConfig(), pieces=True)
        out.degraded.append((how, any(
            abs(g.start - o.start) <= 0.25 and abs(g.end - o.end) <= 0.25 for g in got)))
    return out


def main(argv: list[str]) -> int:
    """Print each motion's scores and the totals."""
    files = dyn_files(argv[0] if argv else None)
    if not files:
        print("no dynamic-handover motions found (give a folder or set GAZEBOT_DYN_DATA)")
        return 1
    n = int(argv[1]) if len(argv) > 1 else 30
    scored = []
    for path in files[:n]:
        a = assess(path)
        if not a.scored:
            print(f"{a.name}: the seed rule finds no transfer (not scored)")
            continue
        scored.append(a)
        missed = [h for h, ok in a.degraded if not ok]
        kept = f"{len(a.degraded) - len(missed)}/{len(a.degraded)}"
        print(f"{a.name}: offline {a.offline:d} online {a.online:d}; degraded {kept} "
              + " ".join(missed))
    copies = [ok for a in scored for _, ok in a.degraded]
    print(
        f"{min(n, len(files))} motions, {len(scored)} with a seed-rule transfer: offline "
        f"{sum(a.offline for a in scored)}, online start {sum(a.online for a in scored)}, "
        f"degraded copies {sum(copies)} of {len(copies)}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
