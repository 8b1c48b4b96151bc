"""Write ``examples/sample-handover.csv``: one human-to-robot handover made by gazebot's own
generator (``gazebot.core.phases.synthetic``), so ``gazebot phases`` has something to run on in a
fresh clone. Its ground truth is printed (and in ``sample-handover.truth.json``).

    python examples/make_sample_recording.py     # rewrites both files (reproducible)
    gazebot phases examples/sample-handover.csv
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from gazebot.core.phases.synthetic import SyntheticOptions, generate

HERE = Path(__file__).resolve().parent
SEED = 7
OPTIONS = SyntheticOptions(rate=100.0, noise=0.001, marker_offset=0.3, posture="standing")


def rows(seed: int = SEED, options: SyntheticOptions = OPTIONS) -> tuple[list[str], dict]:
    """The CSV lines (0.1 mm and 1 ms resolution keep the file small) and the truth (s)."""
    h = generate(seed, options)
    tr = h.trajectory
    points = ("giver_hand", "receiver_hand", "giver_face")
    cols = ["t"] + [f"{p}_{a}" for p in points for a in "xyz"]
    cols += ["gripper_closed", "load_share"]
    lines = [",".join(cols)]

    def cell(v: float, digits: int) -> str:
        return "" if math.isnan(v) else f"{v:.{digits}f}"

    for i in range(len(tr)):
        pts = [*tr.giver_hand[i], *tr.receiver_hand[i], *tr.giver_face[i]]
        lines.append(
            ",".join(
                [f"{tr.t[i]:.3f}"]
                + [cell(v, 4) for v in pts]
                + [cell(tr.gripper_closed[i], 0), cell(tr.load_share[i], 3)]
            )
        )
    truth = [
        {"reach_start": round(x.reach_start, 3), "transfer_start": round(x.transfer_start, 3),
         "transfer_end": round(x.transfer_end, 3), "retreat_end": round(x.retreat_end, 3)}
        for x in h.truth
    ]
    return lines, {"seed": seed, "handovers": truth}


def main(out_dir: Path = HERE) -> int:
    lines, truth = rows()
    (out_dir / "sample-handover.csv").write_text("\n".join(lines) + "\n")
    (out_dir / "sample-handover.truth.json").write_text(json.dumps(truth, indent=1) + "\n")
    print(f"wrote {out_dir / 'sample-handover.csv'} ({len(lines) - 1} samples); truth {truth}")
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE))
