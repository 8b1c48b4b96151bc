"""Reading the published gaze annotations (xlsx, one handover per file) with openpyxl.

Layout (as published in alapkshirsagar/handover-gaze-annotations): folders
``volunteer_A_volunteer_B/`` holding ``volunteer_A_volunteer_B N.xlsx``; one sheet whose first row
is the header ``Frame number | Giver Gaze | Giver Phase | Receiver Gaze | Receiver Phase``; one row
per video frame (8 fps); rows end at the first empty ``Frame number``.

Nothing is dropped silently: a label with stray spaces or odd case is normalised and reported, an
unknown or missing label is kept as ``other`` and reported, a non-empty cell right of the five
columns and a frame number out of sequence are reported. Reports are :class:`LoadIssue` values.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from gazebot.core.config import ConfigError

HEADER = ("Frame number", "Giver Gaze", "Giver Phase", "Receiver Gaze", "Receiver Phase")
FPS = 8.0  # frame rate of the annotated videos

#: Published gaze labels -> normalised names.
GAZE_LABELS = {
    "Other Person's Face": "face",
    "Other Person's Hand": "hand",
    "Own Hand": "own_hand",
    "Other": "other",
}
#: Published phase labels -> normalised names.
PHASE_LABELS = {
    "Other": "other",
    "Approach": "approach",
    "Reach": "reach",
    "Transfer": "transfer",
    "Retreat": "retreat",
}
ROLES = ("giver", "receiver")

_FILE_RE = re.compile(r"^(volunteer_\d+_volunteer_\d+) (\d+)\.xlsx$")


@dataclass(frozen=True)
class LoadIssue:
    """Something odd in a file, reported instead of silently fixed or dropped."""

    path: Path
    row: int  # spreadsheet row (1 = header)
    column: str
    value: object
    message: str

    def __str__(self) -> str:
        return f"{self.path.name}: row {self.row}, {self.column}: {self.message} ({self.value!r})"


@dataclass(frozen=True)
class AnnotatedHandover:
    """One annotated handover video: per-frame gaze and phase labels of giver and receiver.

    Labels are normalised (:data:`GAZE_LABELS`, :data:`PHASE_LABELS` values).
    """

    path: Path
    pair: str
    index: int
    giver_gaze: tuple[str, ...]
    giver_phase: tuple[str, ...]
    receiver_gaze: tuple[str, ...]
    receiver_phase: tuple[str, ...]
    issues: tuple[LoadIssue, ...] = ()

    @property
    def n_frames(self) -> int:
        return len(self.giver_gaze)

    def gaze(self, role: str) -> tuple[str, ...]:
        """Gaze labels of ``role`` (``giver`` or ``receiver``)."""
        return self.giver_gaze if _role(role) == "giver" else self.receiver_gaze

    def phase(self, role: str) -> tuple[str, ...]:
        """Phase labels of ``role`` (``giver`` or ``receiver``)."""
        return self.giver_phase if _role(role) == "giver" else self.receiver_phase


@dataclass(frozen=True)
class AnnotationSet:
    """All handovers of a folder plus everything odd found while reading them."""

    root: Path
    handovers: tuple[AnnotatedHandover, ...]
    issues: tuple[LoadIssue, ...] = field(default=())

    def __len__(self) -> int:
        return len(self.handovers)


def _role(role: str) -> str:
    if role not in ROLES:
        raise ValueError(f"role must be one of {ROLES}, got {role!r}")
    return role


def _label(
    raw: object, table: dict[str, str], path: Path, row: int, column: str, issues: list[LoadIssue]
) -> str:
    if raw is None or (isinstance(raw, str) and not raw.strip()):
        issues.append(LoadIssue(path, row, column, raw, "missing label, counted as 'other'"))
        return "other"
    text = str(raw)
    if text in table:
        return table[text]
    for key, value in table.items():
        if " ".join(text.split()).casefold() == key.casefold():
            issues.append(LoadIssue(path, row, column, raw, f"stray spaces/case, read as {key!r}"))
            return value
    issues.append(LoadIssue(path, row, column, raw, "unknown label, counted as 'other'"))
    return "other"


def _frame_number(raw: object) -> float | None:
    """The frame number of a cell (numbers may be stored as text), None if empty/not a number."""
    if raw is None or (isinstance(raw, str) and not raw.strip()):
        return None
    try:
        value = float(raw)
    except (TypeError, ValueError):
        return math.nan
    return value


def load_handover(path: str | Path) -> AnnotatedHandover:
    """Read one annotation file (issues are in ``.issues``).

    Raises:
        FileNotFoundError: no such file.
        ValueError: not a readable xlsx or the header is not the published one.
    """
    import openpyxl  # only the annotation tools need it

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"annotation file not found: {path}")
    try:
        wb = openpyxl.load_workbook(path, read_only=True, data_only=True)
    except Exception as exc:  # openpyxl raises several types for a broken file
        raise ConfigError(path, "<file>", "a readable xlsx file", str(exc)) from exc
    issues: list[LoadIssue] = []
    cols: list[list[str]] = [[], [], [], []]
    try:
        ws = wb.worksheets[0]
        rows = ws.iter_rows(values_only=True)
        header = next(rows, ())
        got = tuple(str(h).strip() if h is not None else "" for h in header[: len(HEADER)])
        if got != HEADER:
            raise ConfigError(path, "header", f"the columns {list(HEADER)}", list(got))
        extra_header = [h for h in header[len(HEADER) :] if h is not None and str(h).strip()]
        if extra_header:
            issues.append(LoadIssue(path, 1, "header", extra_header, "extra header cells ignored"))
        expected = 1.0
        for row_no, row in enumerate(rows, start=2):
            frame = _frame_number(row[0] if row else None)
            if frame is None:
                break  # the published layout ends at the first empty frame number
            if not (frame == expected):
                issues.append(
                    LoadIssue(path, row_no, HEADER[0], row[0], f"expected frame {expected:g}")
                )
            expected = (frame if math.isfinite(frame) else expected) + 1.0
            cells = list(row[1 : len(HEADER)]) + [None] * (len(HEADER) - len(row))
            for j, (table, column) in enumerate(
                (
                    (GAZE_LABELS, HEADER[1]),
                    (PHASE_LABELS, HEADER[2]),
                    (GAZE_LABELS, HEADER[3]),
                    (PHASE_LABELS, HEADER[4]),
                )
            ):
                cols[j].append(_label(cells[j], table, path, row_no, column, issues))
            stray = [v for v in row[len(HEADER) :] if v is not None]
            if stray:
                issues.append(
                    LoadIssue(path, row_no, "beyond column E", stray, "stray cells ignored")
                )
    finally:
        wb.close()
    match = _FILE_RE.match(path.name)
    pair, index = (match.group(1), int(match.group(2))) if match else (path.parent.name, 0)
    if not cols[0]:
        issues.append(LoadIssue(path, 2, HEADER[0], None, "no frames"))
    for column, labels in ((HEADER[2], cols[1]), (HEADER[4], cols[3])):
        issues.extend(_order_issues(path, column, labels))
    return AnnotatedHandover(
        path=path,
        pair=pair,
        index=index,
        giver_gaze=tuple(cols[0]),
        giver_phase=tuple(cols[1]),
        receiver_gaze=tuple(cols[2]),
        receiver_phase=tuple(cols[3]),
        issues=tuple(issues),
    )


_ORDER = {"reach": 1, "transfer": 2, "retreat": 3}


def _order_issues(path: Path, column: str, labels: list[str]) -> list[LoadIssue]:
    """Report phases that go backwards (e.g. a second handover in one file)."""
    out = []
    last = 0
    for label, start, _ in phase_runs(labels):
        rank = _ORDER.get(label)
        if rank is None:
            continue
        if rank < last:
            out.append(
                LoadIssue(
                    path, start + 2, column, label, "phase goes backwards (another handover?)"
                )
            )
        last = rank
    return out


def annotation_files(root: str | Path) -> list[Path]:
    """The annotation files under ``root`` in the published order (pair, then handover number).

    Raises:
        FileNotFoundError: ``root`` is not a folder or holds no ``*.xlsx`` file.
    """
    root = Path(root)
    if not root.is_dir():
        raise FileNotFoundError(f"annotations folder not found: {root}")
    files = [p for p in root.rglob("*.xlsx") if not p.name.startswith("~$")]
    if not files:
        raise FileNotFoundError(f"no .xlsx annotation files under {root}")

    def key(p: Path) -> tuple:
        m = _FILE_RE.match(p.name)
        nums = [int(x) for x in re.findall(r"\d+", m.group(1))] if m else []
        return (nums, int(m.group(2)) if m else 0, str(p))

    return sorted(files, key=key)


@lru_cache(maxsize=4)
def _load_cached(root: str, stamp: tuple[tuple[str, int, int], ...]) -> AnnotationSet:
    handovers = tuple(load_handover(p) for p, _, _ in stamp)
    issues = tuple(i for h in handovers for i in h.issues)
    return AnnotationSet(Path(root), handovers, issues)


def load_annotations(root: str | Path, cache: bool = True) -> AnnotationSet:
    """Read every handover under ``root``.

    With ``cache`` (default) a folder whose files did not change (same names, sizes and
    modification times) is read once per process.
    """
    files = annotation_files(root)
    stamp = tuple((str(p), p.stat().st_size, p.stat().st_mtime_ns) for p in files)
    if cache:
        return _load_cached(str(Path(root).resolve()), stamp)
    return _load_cached.__wrapped__(str(Path(root).resolve()), stamp)


def phase_runs(labels: Iterable[str]) -> list[tuple[str, int, int]]:
    """Runs of equal labels as ``(label, first_index, length)``."""
    out: list[tuple[str, int, int]] = []
    for i, label in enumerate(labels):
        if out and out[-1][0] == label:
            name, start, n = out[-1]
            out[-1] = (name, start, n + 1)
        else:
            out.append((label, i, 1))
    return out
