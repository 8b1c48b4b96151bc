"""Public YCB-Handovers recordings (github paragkhanna1/YCB-Handovers: careful and non-careful
handovers of a full pitcher and cup, and baskets of other objects; 7.5 s windows of a
full-body mocap suit at 120 Hz), found through GAZEBOT_YCB_DATA or /work/data/ycb: one folder
per handover holding ``giver_RHand`` and ``taker_RHand`` pose CSVs (the dataset's
``*_pose.csv`` or ``.csv``). Never copied into the repository."""

from __future__ import annotations

import os
from pathlib import Path

RATE = 120.0  # Hz, the dataset's mocap rate (901 rows = 7.5 s windows)
HANDS = ("giver_RHand", "taker_RHand")


def ycb_folders() -> list[Path]:
    """The handover folders found (sorted; empty when the data is not on this machine)."""
    for root in (os.environ.get("GAZEBOT_YCB_DATA"), "/work/data/ycb"):
        if root and Path(root).is_dir():
            found = sorted(
                d for d in Path(root).rglob("*") if d.is_dir()
                and all(any(d.glob(f"{h}*.csv")) for h in HANDS)
            )
            if found:
                return found
    return []
