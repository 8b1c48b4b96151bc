"""The in-person studies' two further analyses (seed sections 6.3.3 and 6.4.5):

- a one-way ANOVA on the giver's reach-start time across the gaze conditions. The seed's
  in-person study of 6.3.3, quoted: "We conducted a one-way ANOVA on the human's *reach start
  time* for four gaze conditions. The results indicated no detectable difference between the
  four conditions (F = 0.429, p = 0.732)." The reach-start time is "the difference between the
  start of the human hand's reaching motion and the start of the robot arm's reaching motion",
  one per handover; a handover's condition is the gaze behavior the robot showed in it.
- the familiarity question, asked once per participant, worded in 6.4.5: "How familiar are you
  with a collaborative robot (such as the one shown)?", 1 "Not at all familiar" to 5
  "Extremely familiar", reported as its mean and standard deviation (6.4.5: "M = 1.49,
  SD = 0.60"; 6.3.3: "M = 1.29, SD = 0.55").

Both read the responses CSV (``gazebot study export``): ``first``/``second`` with
``first_reach_start_time``/``second_reach_start_time`` (s; empty: not measured) and
``familiarity`` (1-5; empty: not asked). With a ``mode`` column only its ``in-person`` rows
count; without one, every row (a sheet of the in-person study alone).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import stats

from gazebot.apps.study.csvio import open_text

FAMILIARITY_QUESTION = "How familiar are you with a collaborative robot (such as the one shown)?"
FAMILIARITY_SCALE = (1, 5)  # 1 "Not at all familiar" .. 5 "Extremely familiar"
FAMILIARITY_COLUMN = "familiarity"
IN_PERSON = "in-person"


@dataclass(frozen=True)
class OneWayAnova:
    """``F`` and its ``p`` with the degrees of freedom, and each condition's sample."""

    f: float
    p: float
    df_between: int
    df_within: int
    groups: dict[str, list[float]]

    def to_json(self) -> dict:
        return {
            "F": self.f,
            "p": self.p,
            "df_between": self.df_between,
            "df_within": self.df_within,
            "n": {k: len(v) for k, v in self.groups.items()},
            "mean": {k: float(np.mean(v)) for k, v in self.groups.items()},
        }


@dataclass(frozen=True)
class Familiarity:
    """The familiarity answers' mean, sample standard deviation and count (one per participant)."""

    mean: float
    sd: float
    n: int

    def to_json(self) -> dict:
        return {"M": self.mean, "SD": self.sd, "n": self.n}


@dataclass(frozen=True)
class InPersonData:
    """Reach-start times (s) by gaze behavior and familiarity by participant (group, id)."""

    reach_start: dict[str, list[float]]
    familiarity: dict[tuple[str, str], int]


def read_in_person(path: str | Path) -> InPersonData:
    """The reach-start times and familiarity answers of a responses CSV (module doc).

    Raises:
        FileNotFoundError: no such file.
        ValueError: a missing column, a time that is not a finite number, a familiarity outside
            1-5 or two different answers of one participant (names file, line and column).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"responses file not found: {path}")
    times: dict[str, list[float]] = {}
    fam: dict[tuple[str, str], int] = {}
    with open_text(path) as fh:
        reader = csv.DictReader(fh)
        cols = reader.fieldnames or []
        missing = [c for c in ("participant", "first", "second") if c not in cols]
        if missing:
            raise ValueError(f"{path}: missing column(s) {missing}")
        for line, raw in enumerate(reader, start=2):
            row = {k: (v or "").strip() for k, v in raw.items() if k is not None}
            if "mode" in cols and row.get("mode") != IN_PERSON:
                continue
            for which in ("first", "second"):
                col = f"{which}_reach_start_time"
                value = row.get(col, "")
                if value:
                    times.setdefault(row[which], []).append(_number(path, line, col, value))
            answer = row.get(FAMILIARITY_COLUMN, "")
            if answer:
                who = (row.get("group", ""), row["participant"])
                got = _familiarity(path, line, answer)
                if fam.setdefault(who, got) != got:
                    raise ValueError(
                        f"{path}: line {line}: column '{FAMILIARITY_COLUMN}': participant "
                        f"{row['participant']} answered {fam[who]} on an earlier line, {got} here"
                    )
    return InPersonData(times, fam)


def _number(path: Path, line: int, col: str, value: str) -> float:
    try:
        x = float(value)
    except ValueError:
        x = math.nan
    if not math.isfinite(x):
        raise ValueError(f"{path}: line {line}: column '{col}' expected seconds, got {value!r}")
    return x


def _familiarity(path: Path, line: int, value: str) -> int:
    lo, hi = FAMILIARITY_SCALE
    if not (value.isascii() and value.isdigit() and lo <= int(value) <= hi):
        raise ValueError(
            f"{path}: line {line}: column '{FAMILIARITY_COLUMN}' expected an integer "
            f"{lo}-{hi}, got {value!r}"
        )
    return int(value)


def reach_start_anova(groups: dict[str, list[float]]) -> OneWayAnova:
    """One-way ANOVA (``scipy.stats.f_oneway``) of the reach-start times across conditions.

    Raises:
        ValueError: fewer than two conditions with times, or no within-condition freedom.
    """
    samples = {k: list(v) for k, v in sorted(groups.items()) if v}
    n = sum(len(v) for v in samples.values())
    if len(samples) < 2 or n <= len(samples):
        counts = ", ".join(f"{k}: {len(v)}" for k, v in samples.items()) or "none"
        raise ValueError(
            "the reach-start ANOVA needs times of at least two gaze conditions and more times "
            f"than conditions; got {counts}"
        )
    res = stats.f_oneway(*samples.values())
    return OneWayAnova(float(res.statistic), float(res.pvalue), len(samples) - 1,
                       n - len(samples), samples)


def familiarity_summary(answers: dict[tuple[str, str], int] | list[int]) -> Familiarity:
    """Mean and sample SD (n - 1) of the familiarity answers, one per participant.

    Raises:
        ValueError: fewer than two answers (no SD).
    """
    values = np.array(list(answers.values()) if isinstance(answers, dict) else answers, float)
    if len(values) < 2:
        raise ValueError(f"familiarity needs at least two participants' answers, got {len(values)}")
    return Familiarity(float(values.mean()), float(values.std(ddof=1)), len(values))
