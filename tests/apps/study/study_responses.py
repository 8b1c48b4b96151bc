"""Build a responses CSV whose averaged win matrices are given tables (test helper)."""

from __future__ import annotations

import csv
import itertools
from pathlib import Path

BEHAVIORS = ["face", "hand", "long-face-hand", "short-face-hand"]  # = the seed tables' order
MEASURE_QUESTIONS = {
    "likability": ("q1", "q2"),
    "anthropomorphism": ("q3", "q4"),
    "timing-communication": ("q5",),
}


def responses_from_tables(tables_by_level: dict[str, dict], n: int = 24) -> list[dict]:
    """One row per participant, level and ordered pair. For each measure the i-over-j wins of
    ``table[measure]["wins"][i][j]`` are spread over the answer slots (participant, order,
    question): ``wins * 2 * len(questions)`` of them must be an integer."""
    rows = []
    session = {}
    for level, table in tables_by_level.items():
        answers = {}  # (participant, first, second, q) -> 1/2
        for measure, qs in MEASURE_QUESTIONS.items():
            w = table[measure]["wins"]
            for i, j in itertools.combinations(range(len(BEHAVIORS)), 2):
                slots = [(k, order, q) for k in range(n) for order in (0, 1) for q in qs]
                i_wins = w[i][j] * 2 * len(qs)
                assert abs(i_wins - round(i_wins)) < 1e-9 and abs(w[i][j] + w[j][i] - n) < 1e-9
                for idx, (k, order, q) in enumerate(slots):
                    first, second = (i, j) if order == 0 else (j, i)
                    winner = i if idx < round(i_wins) else j
                    answers[(k, first, second, q)] = 1 if winner == first else 2
        for k in range(n):
            for first, second in itertools.permutations(range(len(BEHAVIORS)), 2):
                session[k] = session.get(k, 0) + 1
                row = {
                    "participant": k + 1,
                    "session": session[k],
                    "condition": "object-size",
                    "level": level,
                    "first": BEHAVIORS[first],
                    "second": BEHAVIORS[second],
                }
                for q in ("q1", "q2", "q3", "q4", "q5"):
                    row[q] = answers[(k, first, second, q)]
                row["comments"] = ""
                rows.append(row)
    return rows


def write_responses(rows: list[dict], path: Path) -> Path:
    with path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return path
