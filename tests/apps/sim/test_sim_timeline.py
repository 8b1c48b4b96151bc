"""The timeline CSV/plot writers and the off-screen rendering check's advice."""

from __future__ import annotations

import argparse
import csv

import numpy as np
import pytest

from gazebot.apps.cli import render_video
from gazebot.apps.render import gl_check
from gazebot.apps.render.timeline import TickRecord, phase_spans, plot_timeline, write_timeline_csv


def _ticks():
    out = []
    for i, (phase, target) in enumerate(
        [("idle", "face"), ("reach", "face"), ("reach", "hand"), ("transfer", "hand"),
         ("retreat", "face"), ("done", "face")]
    ):  # fmt: skip
        out.append(
            TickRecord(
                t=i * 0.5, phase=phase, target=target, head={"head_pan": 0.1 * i},
                eye_yaw=0.0, eye_pitch=0.2, target_point=np.array([1.0, 0.0, 1.5]),
                hand=np.array([0.8, 0.0, 1.0]), face=np.array([1.0, 0.0, 1.5]),
                head_measured={"head_pan": 0.1 * i - 0.01}, events=("reach_started",) * (i == 1),
            )
        )  # fmt: skip
    return out


def test_phase_spans_join_consecutive_ticks():
    spans = phase_spans(_ticks())
    assert [s[0] for s in spans] == ["idle", "reach", "transfer", "retreat", "done"]
    assert spans[1] == ("reach", 0.5, 1.5)


def test_csv_has_one_row_per_tick_with_the_required_columns(tmp_path):
    path = write_timeline_csv(_ticks(), tmp_path / "t.csv")
    with path.open() as fh:
        reader = csv.DictReader(fh)
        rows = list(reader)
    assert reader.fieldnames[:6] == ["t", "phase", "target", "head_pan", "eye_yaw", "eye_pitch"]
    assert len(rows) == 6 and rows[1]["events"] == "reach_started"
    assert float(rows[2]["head_pan"]) == pytest.approx(0.2)


def test_plot_is_written_and_empty_input_is_an_error(tmp_path):
    assert plot_timeline(_ticks(), tmp_path / "t.png").stat().st_size > 5000
    with pytest.raises(ValueError, match="no ticks"):
        plot_timeline([], tmp_path / "e.png")
    with pytest.raises(ValueError, match="no ticks"):
        write_timeline_csv([], tmp_path / "e.csv")


def test_gl_check_names_the_packages_to_install(monkeypatch, capsys):
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    monkeypatch.setattr(gl_check, "probe", lambda backend, timeout=60.0: (False, "no display"))
    assert gl_check.main() == 1
    err = capsys.readouterr().err
    assert "libegl1" in err and "libosmesa6" in err


def test_gl_check_passes_with_the_test_backend(capsys):
    assert gl_check.main() == 0
    assert "works" in capsys.readouterr().out


def test_render_video_cli_wants_an_mp4(tmp_path):
    parser = argparse.ArgumentParser()
    render_video.register(parser.add_subparsers())
    args = parser.parse_args(["video", "--behavior", "hand", "--out", str(tmp_path / "x.avi")])
    with pytest.raises(ValueError, match="mp4"):
        args.func(args)
