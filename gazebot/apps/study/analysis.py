"""Preference analysis of a pairwise video study (seed sections 6.3.2 and 6.4.4).

Responses CSV (one row per participant and session; extra columns such as ``comments`` or
``video`` are ignored; the questionnaire sheet written by ``gazebot study render`` has this
layout with the answers left blank)::

    participant,session,condition,level,first,second,q1,q2,q3,q4,q5
    1,1,object-size,small-box,hand,face-hand-face,2,2,2,1,2

``first``/``second``: the behaviors shown as Handover 1 / Handover 2; ``q1``..``q5``: 1 if the
participant chose the 1st handover, 2 if the 2nd. ``condition``/``level`` may be empty for a study
with a single scenario (the seed's section 6.3 studies). An optional ``group`` column names
independent groups of participants (e.g. ``video`` and ``in-person``, the seed's two studies of
section 6.4 that both number their participants from 1): a participant is identified by
(group, participant), and each group and level is analysed on its own.

Between-sample tests (seed section 6.4.4-6.4.5), per measure and pair of behaviors:

- two levels of one condition answered by the **same** participants (the seed's within-subject
  levels, hypotheses H2-H4): the matched tests, eqs 6.3-6.4 and the McNemar-type equivalence
  test, on the participants who answered both levels;
- two levels of one condition answered by **disjoint** participants (a between-subject
  condition), and one level answered by two ``group`` s (the seed's video vs in-person
  comparison, H5): the unmatched tests, eqs 6.5-6.6 and the two-proportion equivalence test, with
  X = the summed preferences (the win-matrix cell, like the seed's Tables B.1-B.6) and n = the
  participants who compared the pair;
- levels of **different** conditions are not compared: the seed states no hypothesis about them,
  and e.g. "small box" vs "sitting" would confound two factors.

Two levels with only some participants in common are compared with the matched tests on the
common participants (the others cannot be paired).

Per level and measure, participant k's preference for behavior i over j is the share of i-wins
over the measure's questions and both ordered comparisons (i first, j first); the win matrix sums
it over participants, which is the seed's "averaging both ordered comparisons" (Tables 6.1/6.2:
cell (i, j) + cell (j, i) = number of participants).
"""

from __future__ import annotations

import csv
import itertools
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gazebot.apps.study.bradley_terry import BradleyTerryFit, fit_bradley_terry
from gazebot.apps.study.conditions import DEFAULT_BEHAVIORS, REACH_BEHAVIORS
from gazebot.apps.study.csvio import open_text
from gazebot.apps.study.questionnaire import MEASURES, QUESTIONS
from gazebot.apps.study.stats import (
    BiasTest,
    ChiSquare,
    ProportionTest,
    likelihood_ratio_chi2,
    matched_equivalence,
    matched_proportion_difference,
    position_bias_test,
    seed_sides,
    seed_table,
    unmatched_equivalence,
    unmatched_proportion_difference,
)

RESPONSE_COLUMNS = ("participant", "session", "condition", "level", "first", "second") + tuple(
    QUESTIONS
)
# Rows of the seed's Tables 6.1 and 6.2.
TABLE_6_1_ORDER = ("face", "hand", "long-face-hand", "short-face-hand")
#: Optional column: independent participant groups (e.g. ``video`` / ``in-person``).
GROUP_COLUMN = "group"


@dataclass(frozen=True)
class Response:
    """One answered session: ``answers[q]`` is 1 (first handover chosen) or 2 (second);
    ``group``: the independent participant group ("" for a single group)."""

    participant: str
    session: int
    condition: str
    level: str
    first: str
    second: str
    answers: dict[str, int]
    group: str = ""

    @property
    def who(self) -> tuple[str, str]:
        """The participant's identity: (group, participant)."""
        return (self.group, self.participant)

    @property
    def sample(self) -> str:
        """The analysed sample: the level, prefixed by the group if any (``group:level``)."""
        return f"{self.group}:{self.level}" if self.group else self.level


def read_responses(path: str | Path) -> list[Response]:
    """Read a responses CSV (format in the module doc); a missing column, an answer other than 1
    or 2, or a session comparing a behavior with itself raises ``ValueError`` naming file, line
    and column."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"responses file not found: {path}")
    out = []
    with open_text(path) as fh:
        reader = csv.DictReader(fh)
        missing = [c for c in RESPONSE_COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(
                f"{path}: missing column(s) {missing}; expected {list(RESPONSE_COLUMNS)}"
            )
        for line, row in enumerate(reader, start=2):
            row = {k: (v or "").strip() for k, v in row.items() if k is not None}
            for col in ("participant", "session", "first", "second"):
                if not row[col]:
                    raise ValueError(f"{path}: line {line}: column '{col}' is empty")
            try:
                session = int(row["session"])
            except ValueError:
                raise ValueError(
                    f"{path}: line {line}: column 'session' expected an integer, "
                    f"got {row['session']!r}"
                ) from None
            if row["first"] == row["second"]:
                raise ValueError(f"{path}: line {line}: first and second are the same behavior")
            answers = {}
            for q in QUESTIONS:
                raw = row[q]
                if raw not in ("1", "2"):
                    raise ValueError(
                        f"{path}: line {line}: column '{q}' expected 1 (1st handover) or "
                        f"2 (2nd handover), got {raw!r}"
                    )
                answers[q] = int(raw)
            out.append(
                Response(
                    participant=row["participant"],
                    session=session,
                    condition=row["condition"],
                    level=row["level"],
                    first=row["first"],
                    second=row["second"],
                    answers=answers,
                    group=row.get(GROUP_COLUMN, ""),
                )
            )
    if not out:
        raise ValueError(f"{path}: no responses")
    return out


def behaviors_of(responses: list[Response]) -> list[str]:
    """The behaviors compared, the seed's first (in the order of its tables), then the others.
    A study of the 6.3 behaviors only is ordered as Tables 6.1/6.2: Face, Hand, L-FH, S-FH."""
    seen = {r.first for r in responses} | {r.second for r in responses}
    if seen <= set(REACH_BEHAVIORS):
        return [b for b in TABLE_6_1_ORDER if b in seen]
    order = dict.fromkeys((*DEFAULT_BEHAVIORS, "hand-face", "face-hand-face", *REACH_BEHAVIORS))
    known = [b for b in order if b in seen]
    return known + sorted(seen - set(known))


def preferences(
    responses: list[Response], behaviors: list[str], questions: tuple[str, ...]
) -> dict[tuple[str, str], np.ndarray]:
    """Per participant (key :attr:`Response.who`) a ``g x g`` matrix: entry (i, j) = share of
    i-wins over ``questions`` and all of the participant's comparisons of i with j (NaN where the
    pair was never compared)."""
    index = {b: i for i, b in enumerate(behaviors)}
    g = len(behaviors)
    sums: dict[tuple[str, str], np.ndarray] = {}
    counts: dict[tuple[str, str], np.ndarray] = {}
    for r in responses:
        s = sums.setdefault(r.who, np.zeros((g, g)))
        c = counts.setdefault(r.who, np.zeros((g, g)))
        i, j = index[r.first], index[r.second]
        first_share = float(np.mean([r.answers[q] == 1 for q in questions]))
        s[i, j] += first_share
        s[j, i] += 1.0 - first_share
        c[i, j] += 1
        c[j, i] += 1
    out = {}
    for k, s in sums.items():
        with np.errstate(invalid="ignore", divide="ignore"):
            out[k] = np.where(counts[k] > 0, s / np.maximum(counts[k], 1), np.nan)
    return out


def win_matrix(
    responses: list[Response], behaviors: list[str], questions: tuple[str, ...]
) -> np.ndarray:
    """The seed's averaged win matrix: cell (i, j) = sum over participants of their preference
    for i over j (see :func:`preferences`)."""
    prefs = preferences(responses, behaviors, questions)
    g = len(behaviors)
    w = np.zeros((g, g))
    for m in prefs.values():
        w += np.nan_to_num(m, nan=0.0)
    np.fill_diagonal(w, 0.0)
    return w


@dataclass(frozen=True)
class MeasureResult:
    """Bradley-Terry analysis of one measure in one level."""

    measure: str
    participants: int
    wins: np.ndarray
    fit: BradleyTerryFit
    chi2: ChiSquare


@dataclass(frozen=True)
class LevelComparison:
    """Between-sample tests for one pair of behaviors and measure; the proportions are of
    participants preferring ``behavior_i`` over ``behavior_j`` in sample a and sample b.

    ``design``: ``"matched"`` (same participants in both samples: eqs 6.3-6.4 and the
    McNemar-type equivalence test) or ``"unmatched"`` (independent participants: eqs 6.5-6.6 and
    the two-proportion equivalence test); ``group_a``/``group_b``: the participant groups ("" for
    a single group); ``n_a``/``n_b``: participants in each test.
    """

    measure: str
    behavior_i: str
    behavior_j: str
    level_a: str
    level_b: str
    proportion_a: float
    proportion_b: float
    difference: ProportionTest
    equivalence: ProportionTest
    design: str = "matched"
    group_a: str = ""
    group_b: str = ""
    n_a: int = 0
    n_b: int = 0
    #: "one" or "two": the sidedness of ``difference.p_value``.
    sides: str = "one"
    #: The seed's Appendix B table that reports this test ("B.7".."B.12"), else "".
    table: str = ""

    @property
    def sample_a(self) -> str:
        return f"{self.group_a}:{self.level_a}" if self.group_a else self.level_a

    @property
    def sample_b(self) -> str:
        return f"{self.group_b}:{self.level_b}" if self.group_b else self.level_b


@dataclass
class StudyAnalysis:
    """Everything ``gazebot study analyze`` reports."""

    behaviors: list[str]
    levels: list[str]
    per_level: dict[str, dict[str, MeasureResult]] = field(default_factory=dict)
    bias: dict[str, BiasTest] = field(default_factory=dict)
    bias_per_question: dict[str, BiasTest] = field(default_factory=dict)
    #: With several ``group`` s: the bias tests of each group on its own (measures and
    #: questions), as the seed reports each study's (6.4.4 video, 6.4.5 in person).
    bias_by_group: dict[str, dict[str, BiasTest]] = field(default_factory=dict)
    comparisons: list[LevelComparison] = field(default_factory=list)
    #: "seed" (each difference test as the seed's table for its design) or the override.
    sides: str = "seed"

    def to_json(self) -> dict:
        """A JSON-ready dict."""
        return {
            "behaviors": self.behaviors,
            "levels": self.levels,
            "per_level": {
                level: {
                    m: {
                        "participants": r.participants,
                        "wins": r.wins.round(6).tolist(),
                        "a": r.fit.wins.round(6).tolist(),
                        "p": r.fit.p.round(6).tolist(),
                        "chi2": round(r.chi2.chi2, 6),
                        "df": r.chi2.df,
                        "p_value": r.chi2.p_value,
                    }
                    for m, r in measures.items()
                }
                for level, measures in self.per_level.items()
            },
            "bias": {
                m: b.as_json(with_p_z=False) for m, b in self.bias.items()
            },
            "bias_per_question": {
                q: b.as_json() for q, b in self.bias_per_question.items()
            },
            "bias_by_group": {
                g: {
                    k: b.as_json() for k, b in tests.items()
                }
                for g, tests in self.bias_by_group.items()
            },
            "sides": self.sides,
            "level_comparisons": [
                {
                    "measure": c.measure,
                    "pair": [c.behavior_i, c.behavior_j],
                    "design": c.design,
                    "levels": [c.level_a, c.level_b],
                    "groups": [c.group_a, c.group_b],
                    "n": [c.n_a, c.n_b],
                    "proportions": [c.proportion_a, c.proportion_b],
                    "difference": c.difference.difference,
                    "z": c.difference.z,
                    "p_value": c.difference.p_value,
                    "sides": c.sides,
                    "table": c.table,
                    "equivalence_margin": c.equivalence.margin,
                    "equivalence_p_value": c.equivalence.p_value,
                }
                for c in self.comparisons
            ],
        }


def position_differences(
    responses: list[Response], questions: tuple[str, ...], unit: str = "participant"
) -> np.ndarray:
    """Share of "1st" answers minus share of "2nd" answers over ``questions``, one value per
    participant (``unit="participant"``: independent observations) or per answered session
    (``unit="session"``: what the seed's S statistics imply, about 300 values for 24
    participants; repeated measures of one participant are then treated as independent)."""
    if unit not in ("participant", "session"):
        raise ValueError(f"bias unit must be 'participant' or 'session', got {unit!r}")
    groups: dict[object, list[int]] = {}
    for r in responses:
        key = r.who if unit == "participant" else (r.who, r.session, r.level)
        groups.setdefault(key, []).extend(r.answers[q] for q in questions)
    return np.array(
        [np.mean([a == 1 for a in v]) - np.mean([a == 2 for a in v]) for v in groups.values()]
    )


def analyze(
    responses: list[Response],
    margin: float = 0.1,
    behaviors: list[str] | None = None,
    bias_unit: str = "participant",
    sides: str | None = None,
) -> StudyAnalysis:
    """Bradley-Terry P_i with the likelihood-ratio chi-square (= eqs 6.1-6.2 for a complete
    design) per sample (level, or ``group:level``) and measure, the first/second bias test per
    measure (see :func:`position_differences` for ``bias_unit``), and the between-sample
    difference and equivalence tests (margin ``margin``) per pair of behaviors: matched or
    unmatched as the module doc explains. ``behaviors`` fixes the order of the conditions
    (default: :func:`behaviors_of`). The bias test is run per measure and per question (the seed
    reports it per measure in 6.3 and per question in 6.4), over all participants and, with
    several groups, per group. ``sides``: None (default) gives each difference test the seed's
    sidedness for its design (:data:`~gazebot.apps.study.stats.SEED_SIDES`: matched one-sided in the
    observed direction as Tables B.7-B.9, unmatched two-sided as Tables B.10-B.12); ``"one"`` or
    ``"two"`` overrides it for every test."""
    if sides not in (None, "one", "two"):
        raise ValueError(f"sides must be 'one', 'two' or None (the seed's), got {sides!r}")
    if not (isinstance(margin, int | float) and math.isfinite(margin) and 0 < margin < 1):
        raise ValueError(f"equivalence margin must be a finite proportion in (0, 1), got {margin}")
    found = behaviors_of(responses)
    if behaviors is None:
        behaviors = found
    elif sorted(behaviors) != sorted(found):
        raise ValueError(f"responses compare behaviors {found}, not {list(behaviors)}")
    behaviors = list(behaviors)
    samples = list(dict.fromkeys(r.sample for r in responses))
    result = StudyAnalysis(behaviors=behaviors, levels=samples, sides=sides or "seed")
    for sample in samples:
        rows = [r for r in responses if r.sample == sample]
        result.per_level[sample] = {}
        for measure, questions in MEASURES.items():
            w = win_matrix(rows, behaviors, questions)
            n = len({r.who for r in rows})
            try:
                fit = fit_bradley_terry(w, behaviors)
            except ValueError as exc:  # say which sample: a study may hold several
                raise ValueError(
                    f"sample {sample or '(single scenario)'!r} ({n} participants, "
                    f"{len(rows)} sessions), {measure}: {exc}"
                ) from None
            result.per_level[sample][measure] = MeasureResult(
                measure=measure,
                participants=n,
                wins=w,
                fit=fit,
                chi2=likelihood_ratio_chi2(w, fit.p),
            )
    for measure, questions in MEASURES.items():
        diffs = position_differences(responses, questions, bias_unit)
        result.bias[measure] = position_bias_test(diffs)
    for q in QUESTIONS:
        diffs = position_differences(responses, (q,), bias_unit)
        result.bias_per_question[q] = position_bias_test(diffs)
    groups = list(dict.fromkeys(r.group for r in responses))
    if len(groups) > 1:  # independent studies: each its own bias test, as the seed reports them
        for g in groups:
            rows = [r for r in responses if r.group == g]
            tests = dict(MEASURES) | {q: (q,) for q in QUESTIONS}
            result.bias_by_group[g] = {
                k: position_bias_test(position_differences(rows, qs, bias_unit))
                for k, qs in tests.items()
            }
    for a, b in comparable_samples(responses):
        result.comparisons += _compare(a, b, behaviors, margin, sides)
    return result


def comparable_samples(
    responses: list[Response],
) -> list[tuple[list[Response], list[Response]]]:
    """The pairs of samples the module doc says to compare, in order of appearance: two levels
    of one condition within a group, then one level across two groups."""
    by_sample: dict[tuple[str, str, str], list[Response]] = {}
    for r in responses:
        by_sample.setdefault((r.group, r.condition, r.level), []).append(r)
    keys = list(by_sample)
    pairs = []
    for ka, kb in itertools.combinations(keys, 2):
        same_group_levels = ka[0] == kb[0] and ka[1] == kb[1] and ka[2] != kb[2]
        same_level_groups = ka[0] != kb[0] and ka[1:] == kb[1:]
        if same_group_levels or same_level_groups:
            pairs.append((by_sample[ka], by_sample[kb]))
    pairs.sort(key=lambda ab: ab[0][0].group != ab[1][0].group)  # stable: levels first
    return pairs


def _compare(
    rows_a: list[Response],
    rows_b: list[Response],
    behaviors: list[str],
    margin: float,
    sides: str | None = None,
) -> list[LevelComparison]:
    """Matched tests if the samples share participants (on the shared ones), else unmatched;
    ``sides`` None: the seed's sidedness for the design (see :func:`analyze`)."""
    ra, rb = rows_a[0], rows_b[0]
    out = []
    for measure, questions in MEASURES.items():
        pa = preferences(rows_a, behaviors, questions)
        pb = preferences(rows_b, behaviors, questions)
        both = [k for k in pa if k in pb]
        for i, j in itertools.combinations(range(len(behaviors)), 2):
            if both:
                xa = np.array([pa[k][i, j] for k in both])
                xb = np.array([pb[k][i, j] for k in both])
                keep = np.isfinite(xa) & np.isfinite(xb)
                xa, xb = xa[keep], xb[keep]
                if xa.size == 0:
                    continue
                design = "matched"
                used = sides or seed_sides(design)
                difference = matched_proportion_difference(xa, xb, used)
                equivalence = matched_equivalence(xa, xb, margin)
            else:
                xa = np.array([v[i, j] for v in pa.values() if np.isfinite(v[i, j])])
                xb = np.array([v[i, j] for v in pb.values() if np.isfinite(v[i, j])])
                if xa.size == 0 or xb.size == 0:
                    continue
                design = "unmatched"
                used = sides or seed_sides(design)
                counts = (float(xa.sum()), xa.size, float(xb.sum()), xb.size)
                difference = unmatched_proportion_difference(*counts, sides=used)
                equivalence = unmatched_equivalence(*counts, margin=margin)
            out.append(
                LevelComparison(
                    measure=measure,
                    behavior_i=behaviors[i],
                    behavior_j=behaviors[j],
                    level_a=ra.level,
                    level_b=rb.level,
                    proportion_a=float(xa.mean()),
                    proportion_b=float(xb.mean()),
                    difference=difference,
                    equivalence=equivalence,
                    design=design,
                    group_a=ra.group,
                    group_b=rb.group,
                    n_a=int(xa.size),
                    n_b=int(xb.size),
                    sides=used,
                    table=_table_of(design, ra, rb),
                )
            )
    return out


def _table_of(design: str, ra: Response, rb: Response) -> str:
    """The seed's table for a comparison: B.7-B.9 for two levels of a condition answered by the
    same participants, B.10-B.12 for one level answered by two groups (video, in person)."""
    across_groups = ra.group != rb.group
    if (design == "unmatched") != across_groups:
        return ""  # e.g. a between-subject condition: no table of the seed's
    table = seed_table(design, ra.condition)
    return table.name if table is not None else ""


def read_win_matrix(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Read a win-count matrix CSV: header row and first column hold the condition names (same
    order), cell (i, j) = participants preferring i over j (fractions allowed; the diagonal may
    be empty)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"win matrix file not found: {path}")
    with open_text(path) as fh:
        rows = [r for r in csv.reader(fh) if any(c.strip() for c in r)]
    if len(rows) < 3:
        raise ValueError(f"{path}: expected a header row and at least 2 condition rows")
    header = [c.strip() for c in rows[0][1:]]
    names = [r[0].strip() for r in rows[1:]]
    if header != names:
        raise ValueError(
            f"{path}: header conditions {header} differ from first-column conditions {names}"
        )
    g = len(names)
    w = np.zeros((g, g))
    for i, r in enumerate(rows[1:]):
        cells = [c.strip() for c in r[1:]]
        if len(cells) != g:
            raise ValueError(f"{path}: line {i + 2}: expected {g} values, got {len(cells)}")
        for j, c in enumerate(cells):
            if i == j and c in ("", "-"):
                continue
            try:
                w[i, j] = float(c)
            except ValueError:
                w[i, j] = math.nan
            if not math.isfinite(w[i, j]):
                raise ValueError(
                    f"{path}: line {i + 2}, column '{names[j]}': expected a number, got {c!r}"
                )
            if i == j and w[i, j] != 0:
                raise ValueError(
                    f"{path}: line {i + 2}: diagonal cell ({names[i]}, {names[i]}) must be empty "
                    f"or 0, got {c!r}"
                )
    return names, w
