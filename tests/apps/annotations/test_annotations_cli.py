"""``gazebot annotations summarize | replay | fit-human`` on synthetic data."""

from __future__ import annotations

import argparse
import importlib
import json

cli = importlib.import_module("gazebot.apps.cli.annotations")


def run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot")
    sub = parser.add_subparsers(dest="command", required=True)
    cli.register(sub)
    args = parser.parse_args(argv)
    return args.func(args)


def test_summarize_json_has_exactly_the_issue_format(synthetic_dir, capsys):
    assert run(["annotations", "summarize", str(synthetic_dir), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert set(doc) == {"n_handovers", "reach", "three_phase"}
    assert doc["n_handovers"] == 4
    assert set(doc["reach"]) == {"giver", "receiver"}
    assert doc["reach"]["receiver"]["Short Face-Hand"] == 100.0
    assert doc["reach"]["giver"]["Hand"] == 100.0
    assert doc["three_phase"]["receiver"]["Face-Hand-Face"] == 100.0
    assert doc["three_phase"]["giver"]["Hand-Face"] == 100.0
    assert set(doc["three_phase"]["giver"]) == {"Hand", "Hand-Face", "Face-Hand-Face", "other"}


def test_summarize_text_prints_the_seed_numbers_and_writes_a_plot(synthetic_dir, tmp_path, capsys):
    plot = tmp_path / "out" / "summary.png"
    assert run(["annotations", "summarize", str(synthetic_dir), "--plot", str(plot)]) == 0
    out = capsys.readouterr().out
    assert "69.1" in out and ">50" in out and "7.53" in out
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_replay_ranks_behaviors(synthetic_dir, capsys):
    argv = ["annotations", "replay", str(synthetic_dir), "--behavior", "face", "--json"]
    assert run([*argv, "--behavior", "face-hand-face"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert [r["behavior"] for r in doc["results"]] == ["face-hand-face", "face"]
    assert doc["results"][0]["share"] == 1.0


def test_fit_human_writes_a_loadable_behavior(synthetic_dir, tmp_path, capsys):
    out = tmp_path / "human-receiver.yaml"
    assert run(["annotations", "fit-human", str(synthetic_dir), "-o", str(out)]) == 0
    from gazebot.core.behaviors import load_behavior

    spec = load_behavior(out)
    assert spec.human.patterns[0].name == "FH-H-HF" and spec.human.patterns[0].count == 4
    assert "hand_face_delay_s" in capsys.readouterr().out


def test_summarize_plot_must_be_a_png_file_not_a_folder(synthetic_dir, tmp_path):
    import pytest

    with pytest.raises(ValueError, match="is a directory"):
        run(["annotations", "summarize", str(synthetic_dir), "--plot", str(tmp_path)])
    with pytest.raises(ValueError, match=r"must end in \.png"):
        run(["annotations", "summarize", str(synthetic_dir), "--plot", str(tmp_path / "a.jpg")])
    assert not (tmp_path.parent / f"{tmp_path.name}.png").exists()
    assert not (tmp_path / "a.jpg").exists()


def test_summarize_prints_reach_shares_with_own_hand_as_hand_and_as_other(tmp_path, capsys):
    from annotation_helpers import OWN, PHASES, RECEIVER, F, H, handover_rows, write_xlsx

    # Reach of the receiver: face, Own Hand, then hand. As hand: Short Face-Hand (hand from
    # frame 1 of 6); as Other (ignored): the face lasts until frame 4 of 6 -> Long Face-Hand.
    receiver = RECEIVER[:2] + [F, OWN, OWN, OWN, H, H] + RECEIVER[8:]
    root = tmp_path / "ann"
    write_xlsx(
        root / "volunteer_1_volunteer_2" / "volunteer_1_volunteer_2 1.xlsx",
        handover_rows(receiver=receiver, phases=PHASES),
    )
    assert run(["annotations", "summarize", str(root)]) == 0
    out = capsys.readouterr().out
    assert "Sensitivity of the reach shares to Own Hand" in out
    rows = {tuple(line.split()[:3]): line.split()[3:] for line in out.splitlines() if line}
    assert rows[("receiver", "Short", "Face-Hand")][:3] == ["100.0", "0.0", "-100.0"]
    assert rows[("receiver", "Long", "Face-Hand")][:3] == ["0.0", "100.0", "+100.0"]


def test_summarize_a_folder_with_a_broken_xlsx_is_an_input_error_exit_2(tmp_path, capsys):
    from gazebot.apps.cli import main

    (tmp_path / "volunteer_1_volunteer_2 1.xlsx").write_bytes(b"not a zip")
    assert main(["annotations", "summarize", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gazebot: error: ") and "expected a readable xlsx file" in err
