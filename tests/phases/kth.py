"""The public KTH human-human handover sample (github KTH-RPL/handovers_dataset, folder
one_saved_handover_New/handover_sample), found through GAZEBOT_KTH_DATA or /work/data/kth.
Never copied into the repository."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

SUB = Path("one_saved_handover_New/handover_sample")
RATE = 120.0  # Hz, OptiTrack export of the sample (801 rows = 6.675 s)
GRIP_LOADED_N = 2.0  # N above the unloaded baseline: ~10x the sensors' noise at rest


def kth_dir() -> Path | None:
    """The sample folder, or ``None`` when it is not on this machine."""
    for root in (os.environ.get("GAZEBOT_KTH_DATA"), "/work/data/kth"):
        if root:
            for cand in (Path(root) / SUB, Path(root)):
                if (cand / "Wrench_giver_saved.csv").is_file():
                    return cand
    return None


def force_truth(folder: Path) -> tuple[float, float]:
    """Transfer start (both grips loaded) and end (the giver's grip lets go), in s."""

    def grip(name: str) -> np.ndarray:
        w = np.genfromtxt(folder / name, delimiter=",", skip_header=1)
        return np.linalg.norm(w[:, :3], axis=1)

    g, k = grip("Wrench_giver_saved.csv"), grip("Wrench_taker_saved.csv")
    t = np.arange(g.shape[0]) / RATE
    # Unloaded baselines: the taker's before the handover, the giver's after it (1 s each).
    g0, k0 = np.median(g[-int(RATE) :]), np.median(k[: int(RATE)])
    both = (np.abs(g - g0) > GRIP_LOADED_N) & (np.abs(k - k0) > GRIP_LOADED_N)
    i = int(np.flatnonzero(both)[0])
    j = i + int(np.flatnonzero(np.abs(g[i:] - g0) <= GRIP_LOADED_N)[0])
    return float(t[i]), float(t[j])
