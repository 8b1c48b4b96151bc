"""Chapter 3's questionnaire measures (seed 3.3, Appendix A): UEQ recoding and scales, NASA TLX
item means and Pearson correlations, pinned against hand computations."""

from __future__ import annotations

import argparse
import csv
import json
import math

import pytest

from gazebot.apps.cli import study as study_cli
from gazebot.apps.study.measures import (
    UEQ_ITEMS,
    UEQ_SCALES,
    analyze_measures,
    read_questionnaire,
    recode_ueq,
)


def run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot")
    study_cli.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(argv)
    return args.func(args)


def test_the_ueq_key_has_26_items_in_six_scales():
    assert sorted(i for items in UEQ_SCALES.values() for i in items) == list(range(1, 27))
    assert {s: len(v) for s, v in UEQ_SCALES.items()} == {
        "attractiveness": 6, "perspicuity": 4, "efficiency": 4, "dependability": 4,
        "stimulation": 4, "novelty": 4,
    }
    assert UEQ_SCALES["efficiency"] == (9, 20, 22, 23)


def test_recoding_puts_the_positive_term_at_plus_three():
    assert UEQ_ITEMS[9][:2] == ("fast", "slow")  # positive left: 1 -> +3
    assert (recode_ueq(9, 1), recode_ueq(9, 7)) == (3.0, -3.0)
    assert UEQ_ITEMS[20][:2] == ("inefficient", "efficient")  # positive right: 7 -> +3
    assert (recode_ueq(20, 1), recode_ueq(20, 7)) == (-3.0, 3.0)


# Three participants rating PV in round 1. Efficiency items 9, 20, 22, 23 (9 and 23 positive
# left): P1 4,4,4,4 -> 0, 0, 0, 0 = 0; P2 3,5,5,3 -> 1, 1, 1, 1 = 1; P3 1,6,7,2 -> 3, 2, 3, 2 = 2.5.
# Perspicuity (2, 4, 13, 21) and dependability (8, 11, 17, 19) neutral (4) for everyone.
EFF = {"1": (4, 4, 4, 4), "2": (3, 5, 5, 3), "3": (1, 6, 7, 2)}
MENTAL = {"1": 1.0, "2": 2.0, "3": 3.0}
FRUSTRATION = {"1": 5.0, "2": 5.0, "3": 5.0}  # constant: no correlation


def _write(path):
    items = (*UEQ_SCALES["efficiency"], *UEQ_SCALES["perspicuity"], *UEQ_SCALES["dependability"])
    cols = ["participant", "controller", "round", *(f"ueq{i}" for i in items),
            "tlx_mental", "tlx_frustration"]
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for p, eff in EFF.items():
            w.writerow([p, "PV", "1", *eff, *[4] * 8, MENTAL[p], FRUSTRATION[p]])
    return path


def test_scales_tlx_means_and_pearson_by_hand(tmp_path):
    res = analyze_measures(read_questionnaire(_write(tmp_path / "q.csv")))
    g = ("PV", "1")
    eff = res.ueq[g]["efficiency"]
    # M = (0 + 1 + 2.5) / 3 = 7/6; SD = sqrt(((7/6)^2 + (1/6)^2 + (8/6)^2) / 2) = sqrt(114/72)
    assert eff.mean == pytest.approx(7 / 6)
    assert eff.sd == pytest.approx(math.sqrt(114 / 72))
    assert res.ueq[g]["perspicuity"].mean == 0.0
    assert res.ueq[g]["overall"].mean == pytest.approx(7 / 18)  # (7/6 + 0 + 0) / 3
    assert set(res.ueq[g]) == {"efficiency", "perspicuity", "dependability", "overall"}
    assert res.tlx[g]["mental"].mean == 2.0 and res.tlx[g]["mental"].sd == 1.0
    # r(mental, efficiency): Sxy = (-1)(-7/6) + 0 + (1)(8/6) = 2.5, Sxx = 2, Syy = 114/36
    r = 2.5 / math.sqrt(2 * 114 / 36)
    # n = 3: t = r / sqrt(1 - r^2) on 1 df (Cauchy): two-sided p = 1 - (2 / pi) atan(|t|)
    p = 1 - 2 / math.pi * math.atan(abs(r) / math.sqrt(1 - r * r))
    by = {(c.tlx, c.ue): c for c in res.correlations[g]}
    assert by[("mental", "efficiency")].r == pytest.approx(r, rel=1e-9)
    assert by[("mental", "efficiency")].p == pytest.approx(p, rel=1e-6)
    assert by[("mental", "overall")].r == pytest.approx(r, rel=1e-9)  # overall = eff / 3
    # Constant measures (frustration; perspicuity) have no Pearson r: left out.
    assert set(by) == {("mental", "efficiency"), ("mental", "overall")}


def test_study_measures_cli_reports_scales_on_both_ranges(tmp_path, capsys):
    assert run(["study", "measures", str(_write(tmp_path / "q.csv")), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)["PV/1"]
    assert doc["ueq"]["efficiency"]["M"] == pytest.approx(7 / 6)
    assert doc["ueq_1_to_7"]["efficiency"]["M"] == pytest.approx(4 + 7 / 6)  # Table 3.1's range
    assert run(["study", "measures", str(_write(tmp_path / "q.csv"))]) == 0
    assert "UEQ efficiency: M = 1.17 (1-7: 5.17)" in capsys.readouterr().out


@pytest.mark.parametrize(
    "header, row, message",
    [
        (["participant", "ueq9"], ["1", "8"], "column 'ueq9' expected an integer 1-7, got '8'"),
        (["participant", "ueq9"], ["1", ""], "column 'ueq9' expected an integer 1-7, got ''"),
        (["participant", "tlx_effort"], ["1", "lots"], "column 'tlx_effort' expected a number"),
        (["participant", "comment"], ["1", "x"], "no questionnaire column"),
    ],
)
def test_bad_questionnaires_name_file_line_and_column(tmp_path, header, row, message):
    path = tmp_path / "bad.csv"
    path.write_text(",".join(header) + "\n" + ",".join(row) + "\n")
    with pytest.raises(ValueError, match=message) as err:
        read_questionnaire(path)
    assert "bad.csv" in str(err.value)
