"""Chapter 3's questionnaire measures: UEQ scales, NASA TLX items and their Pearson correlations
(seed section 3.3 and Appendix A).

The seed, quoted: "We used Laugwitz et al.'s [88] user experience questionnaire to elicit the
efficiency, perspicuity, and dependability ratings of each of the controllers. In Study 1, we
also collected responses to these measures of workload: mental demand, performance, effort, and
frustration, using the NASA TLX questionnaire". Appendix A: "Tables A.1-A.4 show the Pearson's
correlation scores for the User Experience Variables "Efficiency, "Perspicuity" and
"Dependability", and NASA TLX Variables "Mental Demand", "Performance", "Effort" and
"Frustration", for the PV and MCJ controllers in Study 1" (one table per controller and round).

The UEQ (Laugwitz, Held and Schrepp 2008) has 26 seven-point items between two opposite terms,
six scales (:data:`UEQ_SCALES`); an answer 1..7 is recoded to -3..3 so that +3 is the positive
term (:data:`UEQ_ITEMS` says which term is on the left), and a scale is the mean of its items.
The seed's Table 3.1 reports its scales on the 1..7 answer range (e.g. Efficiency 4.72); the
recoded mean + 4 is that value. Its "Overall UE" is the mean of its three scales.

Questionnaire CSV, one row per participant and rating (extra columns ignored)::

    participant,controller,round,ueq1,...,ueq26,tlx_mental,tlx_performance,tlx_effort,tlx_frustration
    1,PV,1,5,3,...

``controller``/``round`` are optional; each (controller, round) is analysed on its own, as the
seed's Tables A.1-A.4. ``ueqN`` columns may be a subset: a scale is scored when all its items are
present. TLX columns (``tlx_`` + one of :data:`TLX_ITEMS`) may be a subset (the seed's four);
their values are taken as given (any finite number: raw TLX scales differ between labs).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import stats

from gazebot.apps.study.csvio import open_text

# Item number -> (left term, right term, scale). The UEQ's item list and scale key.
UEQ_ITEMS: dict[int, tuple[str, str, str]] = {
    1: ("annoying", "enjoyable", "attractiveness"),
    2: ("not understandable", "understandable", "perspicuity"),
    3: ("creative", "dull", "novelty"),
    4: ("easy to learn", "difficult to learn", "perspicuity"),
    5: ("valuable", "inferior", "stimulation"),
    6: ("boring", "exciting", "stimulation"),
    7: ("not interesting", "interesting", "stimulation"),
    8: ("unpredictable", "predictable", "dependability"),
    9: ("fast", "slow", "efficiency"),
    10: ("inventive", "conventional", "novelty"),
    11: ("obstructive", "supportive", "dependability"),
    12: ("good", "bad", "attractiveness"),
    13: ("complicated", "easy", "perspicuity"),
    14: ("unlikable", "pleasing", "attractiveness"),
    15: ("usual", "leading edge", "novelty"),
    16: ("unpleasant", "pleasant", "attractiveness"),
    17: ("secure", "not secure", "dependability"),
    18: ("motivating", "demotivating", "stimulation"),
    19: ("meets expectations", "does not meet expectations", "dependability"),
    20: ("inefficient", "efficient", "efficiency"),
    21: ("clear", "confusing", "perspicuity"),
    22: ("impractical", "practical", "efficiency"),
    23: ("organized", "cluttered", "efficiency"),
    24: ("attractive", "unattractive", "attractiveness"),
    25: ("friendly", "unfriendly", "attractiveness"),
    26: ("conservative", "innovative", "novelty"),
}
# Items whose positive term is on the left: recoded 4 - x (the others x - 4).
UEQ_POSITIVE_LEFT = frozenset({3, 4, 5, 9, 10, 12, 17, 18, 19, 21, 23, 24, 25})
UEQ_SCALES: dict[str, tuple[int, ...]] = {
    scale: tuple(i for i, item in UEQ_ITEMS.items() if item[2] == scale)
    for scale in (
        "attractiveness", "perspicuity", "efficiency", "dependability", "stimulation", "novelty"
    )
}
#: The seed's UE variables, in Appendix A's order.
SEED_UE_SCALES = ("efficiency", "perspicuity", "dependability")
OVERALL_UE = "overall"
TLX_ITEMS = ("mental", "physical", "temporal", "performance", "effort", "frustration")
#: The seed's NASA TLX variables, in Appendix A's order.
SEED_TLX_ITEMS = ("mental", "performance", "effort", "frustration")
UEQ_RANGE = (1, 7)


def recode_ueq(item: int, answer: float) -> float:
    """An answer 1..7 to item ``item`` on the UEQ's -3..3, +3 the positive term."""
    return 4.0 - answer if item in UEQ_POSITIVE_LEFT else answer - 4.0


@dataclass(frozen=True)
class Rating:
    """One participant's questionnaire for one controller and round."""

    participant: str
    group: tuple[str, str]  # (controller, round), "" when the column is absent
    ueq: dict[int, int]
    tlx: dict[str, float]

    def scales(self) -> dict[str, float]:
        """Scale means on -3..3 of every scale whose items were all answered, and the seed's
        overall UE (mean of its three scales) when all three are."""
        out = {
            s: float(np.mean([recode_ueq(i, self.ueq[i]) for i in items]))
            for s, items in UEQ_SCALES.items()
            if all(i in self.ueq for i in items)
        }
        if all(s in out for s in SEED_UE_SCALES):
            out[OVERALL_UE] = float(np.mean([out[s] for s in SEED_UE_SCALES]))
        return out


def read_questionnaire(path: str | Path) -> list[Rating]:
    """The ratings of a questionnaire CSV (module doc).

    Raises:
        FileNotFoundError: no such file.
        ValueError: no ``participant`` column, no UEQ or TLX column, an empty cell, a UEQ answer
            outside 1-7 or a TLX value that is not a finite number (names file, line, column).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"questionnaire file not found: {path}")
    out = []
    with open_text(path) as fh:
        reader = csv.DictReader(fh)
        cols = [c.strip() for c in reader.fieldnames or []]
        if "participant" not in cols:
            raise ValueError(f"{path}: missing column 'participant'")
        ueq_cols = [i for i in UEQ_ITEMS if f"ueq{i}" in cols]
        tlx_cols = [t for t in TLX_ITEMS if f"tlx_{t}" in cols]
        if not ueq_cols and not tlx_cols:
            raise ValueError(
                f"{path}: no questionnaire column: expected ueq1..ueq26 and/or "
                f"{', '.join('tlx_' + t for t in TLX_ITEMS)}"
            )
        lo, hi = UEQ_RANGE
        for line, raw in enumerate(reader, start=2):
            row = {(k or "").strip(): (v or "").strip() for k, v in raw.items()}
            ueq = {}
            for i in ueq_cols:
                v = row[f"ueq{i}"]
                if not (v.isascii() and v.isdigit() and lo <= int(v) <= hi):
                    raise ValueError(
                        f"{path}: line {line}: column 'ueq{i}' expected an integer {lo}-{hi}, "
                        f"got {v!r}"
                    )
                ueq[i] = int(v)
            tlx = {}
            for t in tlx_cols:
                v = row[f"tlx_{t}"]
                try:
                    x = float(v)
                except ValueError:
                    x = math.nan
                if not math.isfinite(x):
                    raise ValueError(
                        f"{path}: line {line}: column 'tlx_{t}' expected a number, got {v!r}"
                    )
                tlx[t] = x
            group = (row.get("controller", ""), row.get("round", ""))
            out.append(Rating(row["participant"], group, ueq, tlx))
    if not out:
        raise ValueError(f"{path}: no ratings")
    return out


@dataclass(frozen=True)
class Summary:
    """Mean and sample SD (n - 1; NaN for one value) of one measure."""

    mean: float
    sd: float
    n: int

    @classmethod
    def of(cls, values: list[float]) -> Summary:
        v = np.asarray(values, float)
        return cls(float(v.mean()), float(v.std(ddof=1)) if len(v) > 1 else math.nan, len(v))


@dataclass(frozen=True)
class Correlation:
    """Pearson's r of a TLX item with a UE variable over the participants, and its p."""

    tlx: str
    ue: str
    r: float
    p: float
    n: int


@dataclass(frozen=True)
class MeasuresAnalysis:
    """Per (controller, round): UEQ scale means (-3..3), TLX item means, and the Appendix A
    correlations."""

    ueq: dict[tuple[str, str], dict[str, Summary]]
    tlx: dict[tuple[str, str], dict[str, Summary]]
    correlations: dict[tuple[str, str], list[Correlation]]

    def to_json(self) -> dict:
        def key(g: tuple[str, str]) -> str:
            return "/".join(x for x in g if x) or "all"

        def summ(d: dict[str, Summary], shift: float = 0.0) -> dict:
            return {k: {"M": s.mean + shift, "SD": s.sd, "n": s.n} for k, s in d.items()}

        return {
            key(g): {
                "ueq": summ(self.ueq[g]),
                "ueq_1_to_7": summ(self.ueq[g], 4.0),
                "tlx": summ(self.tlx[g]),
                "pearson": [
                    {"tlx": c.tlx, "ue": c.ue, "r": c.r, "p": c.p, "n": c.n}
                    for c in self.correlations[g]
                ],
            }
            for g in self.ueq
        }


def analyze_measures(ratings: list[Rating]) -> MeasuresAnalysis:
    """UEQ scales, TLX items and their correlations, per (controller, round) group.

    A correlation needs three or more participants and neither measure constant (Pearson's r is
    undefined otherwise); such pairs are left out.
    """
    ueq: dict[tuple[str, str], dict[str, Summary]] = {}
    tlx: dict[tuple[str, str], dict[str, Summary]] = {}
    corr: dict[tuple[str, str], list[Correlation]] = {}
    for g in sorted({r.group for r in ratings}):
        rows = [r for r in ratings if r.group == g]
        scales = [r.scales() for r in rows]
        names = [s for s in (*UEQ_SCALES, OVERALL_UE) if all(s in x for x in scales)]
        ueq[g] = {s: Summary.of([x[s] for x in scales]) for s in names}
        items = [t for t in TLX_ITEMS if all(t in r.tlx for r in rows)]
        tlx[g] = {t: Summary.of([r.tlx[t] for r in rows]) for t in items}
        corr[g] = []
        ue_vars = [s for s in (*SEED_UE_SCALES, OVERALL_UE) if s in names]
        for t in items:
            x = np.array([r.tlx[t] for r in rows])
            for s in ue_vars:
                y = np.array([v[s] for v in scales])
                if len(x) < 3 or np.ptp(x) == 0 or np.ptp(y) == 0:
                    continue
                res = stats.pearsonr(x, y)
                corr[g].append(Correlation(t, s, float(res.statistic), float(res.pvalue), len(x)))
    return MeasuresAnalysis(ueq, tlx, corr)
