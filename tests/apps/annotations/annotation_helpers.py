"""Synthetic annotation files in the published layout (fast tests without the real data)."""

from __future__ import annotations

from pathlib import Path

HEADER = ["Frame number", "Giver Gaze", "Giver Phase", "Receiver Gaze", "Receiver Phase"]
F, H, OWN, X = "Other Person's Face", "Other Person's Hand", "Own Hand", "Other"

# (gaze, phase) per frame for (giver, receiver): a receiver with Face-Hand-Face, a giver Hand-Face.
PHASES = ["Other"] * 2 + ["Reach"] * 6 + ["Transfer"] * 3 + ["Retreat"] * 6 + ["Other"] * 2
RECEIVER = [F, F] + [F, F, F, H, H, H] + [H, OWN, H] + [OWN, OWN, OWN, F, F, F] + [F, F]
GIVER = [F, F] + [H, H, H, H, H, H] + [H, H, H] + [H, F, F, F, X, F] + [F, F]


def write_xlsx(path: Path, rows: list[list[object]], header: list[str] | None = None) -> Path:
    """Write rows (after the header) like the published files, plus trailing empty rows."""
    import openpyxl

    wb = openpyxl.Workbook()
    ws = wb.active
    ws.append(header or HEADER)
    for row in rows:
        ws.append(row)
    for _ in range(3):
        ws.append([None] * 5)
    path.parent.mkdir(parents=True, exist_ok=True)
    wb.save(path)
    return path


def handover_rows(
    giver: list[str] = GIVER, receiver: list[str] = RECEIVER, phases: list[str] = PHASES
) -> list[list[object]]:
    return [
        [i + 1, g, p, r, p] for i, (g, r, p) in enumerate(zip(giver, receiver, phases, strict=True))
    ]
