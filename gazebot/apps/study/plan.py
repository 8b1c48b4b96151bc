"""Counterbalanced session plans for the video study (seed sections 6.3.2 and 6.4.4).

Two designs, as the seed ran them:

- **no condition** (6.3, reach phase): every participant sees each ordered pairing of the ``g``
  behaviors once, ``k = g (g - 1)`` sessions ("The 12 sessions consisted of the six possible
  pairings of the four gaze patterns and their reverse order");
- **one condition** (6.4, Tables 6.3/6.4): each ordered pairing once for each of the two levels
  of the condition, ``k = 2 g (g - 1)`` sessions (12 for the seed's 3 behaviors).

Balance property. The session orders come from a Williams design: a ``k x k`` Latin square whose
rows are participants and columns session positions, in which

1. every session (ordered pairing x level) appears exactly once in every position, and
2. every session immediately follows every other session exactly once (first-order carry-over
   balance; possible because ``k`` is even).

A *full block* is the ``k`` participants of one such square, so the number of participants must be
a positive multiple of ``k`` (12 for the seed's design: 24 participants = 2 blocks). Across any
number of full blocks each session therefore appears in each position equally often (once per
block). Randomisation keeps both properties: per block, sessions are assigned to the square's
symbols by a random permutation, and the rows are dealt to that block's participants in random
order (seeded, so a plan is reproducible).
"""

from __future__ import annotations

import csv
import itertools
from collections import Counter
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from gazebot.apps.study.conditions import (
    CONDITION_LEVELS,
    DEFAULT_BEHAVIORS,
    DEFAULT_SCENES,
    GAZE_MODES,
    default_gaze_mode,
    default_robot,
)
from gazebot.apps.study.csvio import check_output_file, open_text

__all__ = [
    "CONDITION_LEVELS",
    "DEFAULT_BEHAVIORS",
    "GAZE_MODES",
    "DEFAULT_SCENES",
    "PLAN_COLUMNS",
    "BalanceReport",
    "Session",
    "check_balance",
    "make_plan",
    "ordered_pairings",
    "read_plan",
    "williams_square",
    "write_plan",
]


@dataclass(frozen=True)
class Session:
    """One row of a plan: ``participant`` (1-based) watches, in session ``session`` (1-based
    position), the handover with behavior ``first`` then ``second``, both in ``scene`` (the level
    ``level`` of ``condition``; both empty in a design without a condition), on ``robot`` showing
    its gaze as ``gaze_mode``, rendered with ``video_seed``."""

    participant: int
    session: int
    condition: str
    level: str
    scene: str
    robot: str
    first: str
    second: str
    video_seed: int
    gaze_mode: str = "head-and-eyes"

    @property
    def key(self) -> tuple[str, str, str]:
        """What the participant compares: (first, second, level)."""
        return (self.first, self.second, self.level)


PLAN_COLUMNS = tuple(f.name for f in fields(Session))


def ordered_pairings(behaviors: list[str] | tuple[str, ...]) -> list[tuple[str, str]]:
    """Every ordered pair of distinct behaviors in the seed's Table 6.4 order: first the pairs
    ``(b_i, b_j)`` with i < j, then their reverses in the same order."""
    behaviors = list(behaviors)
    if len(behaviors) < 2:
        raise ValueError("a study needs at least 2 behaviors")
    if len(set(behaviors)) != len(behaviors):
        raise ValueError(f"behaviors must be distinct, got {behaviors}")
    forward = list(itertools.combinations(behaviors, 2))
    return forward + [(b, a) for a, b in forward]


def williams_square(k: int) -> np.ndarray:
    """A ``k x k`` Williams Latin square (``k`` even): row r is ``(base + r) mod k`` with base
    ``0, 1, k-1, 2, k-2, ...``, so every symbol follows every other symbol exactly once."""
    if k < 2 or k % 2:
        raise ValueError(f"a single Williams square needs an even size >= 2, got {k}")
    base = [0]
    lo, hi = 1, k - 1
    while len(base) < k:
        base.append(lo)
        lo += 1
        if len(base) < k:
            base.append(hi)
            hi -= 1
    return (np.asarray(base)[None, :] + np.arange(k)[:, None]) % k


def make_plan(
    behaviors: list[str] | tuple[str, ...] = DEFAULT_BEHAVIORS,
    condition: str | None = "object-size",
    participants: int = 24,
    seed: int = 0,
    robot: str | None = None,
    scenes: dict[str, str] | None = None,
    video_seed: int = 0,
    gaze_mode: str | None = None,
) -> list[Session]:
    """A counterbalanced plan (see the module doc): ``participants`` must be a positive multiple
    of the block size (``g (g - 1)`` without a condition, ``2 g (g - 1)`` with one). ``condition``
    ``None`` or ``""``: the 6.3 design (one scenario, level ``""``). ``scenes`` maps a level to a
    scene name (overrides :data:`DEFAULT_SCENES`); ``robot`` and ``gaze_mode`` default to the
    seed's for the design (:func:`~gazebot.apps.study.conditions.default_robot`,
    :func:`~gazebot.apps.study.conditions.default_gaze_mode`). Raises ``ValueError`` for an
    unknown condition or gaze mode or an invalid participant count."""
    condition = condition or ""
    if condition and condition not in CONDITION_LEVELS:
        raise ValueError(
            f"unknown condition {condition!r}; expected one of {sorted(CONDITION_LEVELS)} "
            "(or none for the seed's 6.3 design)"
        )
    gaze_mode = gaze_mode or default_gaze_mode(condition)
    robot = robot or default_robot(condition)
    if gaze_mode not in GAZE_MODES:
        raise ValueError(f"unknown gaze mode {gaze_mode!r}; expected one of {list(GAZE_MODES)}")
    pairings = ordered_pairings(behaviors)
    levels = CONDITION_LEVELS[condition] if condition else ("",)
    items = [(level, first, second) for level in levels for first, second in pairings]
    k = len(items)
    if participants <= 0 or participants % k:
        raise ValueError(
            f"participants must be a positive multiple of {k} (one full counterbalancing block "
            f"of the {k} sessions), got {participants}"
        )
    scenes = {**DEFAULT_SCENES, **(scenes or {})}
    square = williams_square(k)
    rng = np.random.default_rng(seed)
    plan: list[Session] = []
    for block in range(participants // k):
        relabel = rng.permutation(k)  # square symbol -> session item
        rows = rng.permutation(k)  # which square row each participant of the block gets
        for offset, row in enumerate(rows):
            participant = block * k + offset + 1
            for position, symbol in enumerate(square[row]):
                level, first, second = items[relabel[symbol]]
                plan.append(
                    Session(
                        participant=participant,
                        session=position + 1,
                        condition=condition,
                        level=level,
                        scene=scenes.get(level, level),
                        robot=robot,
                        first=first,
                        second=second,
                        video_seed=int(video_seed),
                        gaze_mode=gaze_mode,
                    )
                )
    return plan


@dataclass(frozen=True)
class BalanceReport:
    """Counts that show whether a plan is counterbalanced.

    ``position_counts[(key, position)]``: how many participants saw session ``key`` at
    ``position``; ``carryover_counts[(key_a, key_b)]``: how often ``key_b`` directly followed
    ``key_a``; ``complete``: every participant saw every session exactly once.
    """

    position_counts: dict[tuple[tuple[str, str, str], int], int]
    carryover_counts: dict[tuple[tuple[str, str, str], tuple[str, str, str]], int]
    complete: bool

    @property
    def position_balanced(self) -> bool:
        """Every session appears in every position equally often."""
        return self.complete and len(set(self.position_counts.values())) == 1

    @property
    def carryover_balanced(self) -> bool:
        """Every session directly follows every other session equally often."""
        return self.complete and len(set(self.carryover_counts.values())) == 1


def check_balance(plan: list[Session]) -> BalanceReport:
    """Count positions and immediate successions of each session (first, second, level)."""
    by_participant: dict[int, list[Session]] = {}
    for s in plan:
        by_participant.setdefault(s.participant, []).append(s)
    keys = {s.key for s in plan}
    k = len(keys)
    complete = True
    positions: Counter = Counter({(key, pos): 0 for key in keys for pos in range(1, k + 1)})
    carry: Counter = Counter({(a, b): 0 for a in keys for b in keys if a != b})
    for sessions in by_participant.values():
        sessions = sorted(sessions, key=lambda s: s.session)
        seq = [s.key for s in sessions]
        if sorted(seq) != sorted(keys) or [s.session for s in sessions] != list(range(1, k + 1)):
            complete = False
        for s in sessions:
            positions[(s.key, s.session)] += 1
        for a, b in itertools.pairwise(seq):
            carry[(a, b)] += 1
    return BalanceReport(dict(positions), dict(carry), complete)


def write_plan(plan: list[Session], path: str | Path) -> Path:
    """Write the plan as CSV with the columns :data:`PLAN_COLUMNS`; ``ValueError`` if ``path`` is
    a folder (see :func:`~gazebot.apps.study.csvio.check_output_file`)."""
    path = check_output_file(path, "plan")
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=PLAN_COLUMNS)
        writer.writeheader()
        for s in plan:
            writer.writerow(asdict(s))
    return path


def read_plan(path: str | Path) -> list[Session]:
    """Read a plan CSV written by :func:`write_plan`; a missing column or a malformed value raises
    ``ValueError`` naming the file, row and column. ``condition`` and ``level`` may be empty (a
    design without a condition); a plan without a ``gaze_mode`` column (older gazebot) is
    ``head-and-eyes``."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"plan file not found: {path}")
    with open_text(path) as fh:
        reader = csv.DictReader(fh)
        optional = {"gaze_mode"}
        missing = [
            c for c in PLAN_COLUMNS if c not in (reader.fieldnames or []) and c not in optional
        ]
        if missing:
            raise ValueError(f"{path}: missing column(s) {missing}; expected {list(PLAN_COLUMNS)}")
        plan = []
        for line, row in enumerate(reader, start=2):
            values: dict[str, object] = {}
            for col in PLAN_COLUMNS:
                raw = (row.get(col) or "").strip()
                if col == "gaze_mode":
                    raw = raw or "head-and-eyes"
                    if raw not in GAZE_MODES:
                        raise ValueError(
                            f"{path}: line {line}: column 'gaze_mode' expected one of "
                            f"{list(GAZE_MODES)}, got {raw!r}"
                        )
                if not raw and col not in ("condition", "level"):
                    raise ValueError(f"{path}: line {line}: column '{col}' is empty")
                if col in ("participant", "session", "video_seed"):
                    try:
                        values[col] = int(raw)
                    except ValueError:
                        raise ValueError(
                            f"{path}: line {line}: column '{col}' expected an integer, got {raw!r}"
                        ) from None
                else:
                    values[col] = raw
            plan.append(Session(**values))  # type: ignore[arg-type]
    if not plan:
        raise ValueError(f"{path}: the plan has no sessions")
    return plan
