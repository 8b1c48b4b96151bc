"""Trajectories: written as CSV and read back by the one CSV reader
(gazebot.io.recordings.csv_table), whose errors name the file, the line, the column and what
was expected; conversion to and from tracking frames; cleaning."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from gazebot.core.phases import Trajectory
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.core.types import TrackingFrame
from gazebot.io.recordings import RecordingError
from gazebot.io.recordings.csv_table import read_csv

HEADER = "t,giver_hand_x,giver_hand_y,giver_hand_z,receiver_hand_x,receiver_hand_y,receiver_hand_z"


def _write(tmp_path: Path, text: str) -> Path:
    f = tmp_path / "traj.csv"
    f.write_text(text)
    return f


def _read(path: Path) -> Trajectory:
    return read_csv(path).trajectory


def test_csv_round_trip_keeps_values_and_missing_samples(tmp_path):
    case = generate(2, SyntheticOptions(rate=30, dropouts_per_s=2.0, robot_evidence=True))
    tr = case.trajectory
    back = _read(tr.to_csv(tmp_path / "x.csv"))
    np.testing.assert_array_equal(back.t, tr.t)
    np.testing.assert_array_equal(back.giver_hand, tr.giver_hand)  # NaN == NaN here
    np.testing.assert_array_equal(back.receiver_hand, tr.receiver_hand)
    np.testing.assert_array_equal(back.giver_face, tr.giver_face)
    np.testing.assert_array_equal(back.gripper_closed, tr.gripper_closed)
    np.testing.assert_array_equal(back.load_share, tr.load_share)
    assert np.isnan(tr.giver_hand).any(), "the dropouts should have produced missing samples"


def test_minimal_csv_without_face_or_robot_columns(tmp_path):
    tr = _read(_write(tmp_path, HEADER + "\n0,1,0,0,0.5,0,0\n0.1,,,,0.5,0,0\n"))
    assert len(tr) == 2
    assert np.isnan(tr.giver_hand[1]).all() and np.isnan(tr.giver_face).all()
    assert tr.gripper_closed.size == 0 or np.isnan(tr.gripper_closed).all()


def test_partly_missing_point_counts_as_missing(tmp_path):
    tr = _read(_write(tmp_path, HEADER + "\n0,1,,0,0.5,0,0\n0.1,1,0,0,0.5,0,0\n"))
    assert np.isnan(tr.giver_hand[0]).all() and np.isfinite(tr.giver_hand[1]).all()


@pytest.mark.parametrize(
    ("body", "line", "column", "expected"),
    [
        ("0,1,0,0,0.5,0,0\n0.1,1,abc,0,0.5,0,0\n", 3, "giver_hand_y", "not a number"),
        ("0,1,0,0,0.5,0,0\n,1,0,0,0.5,0,0\n", 3, "t", "time is missing"),
        ("0,1,0,0,0.5,0\n", 2, "receiver_hand_z", "expected 7 cells, got 6"),
        ("0,1,0,0,0.5,0,inf\n", 2, "receiver_hand_z", "infinite value"),
        ("nan,1,0,0,0.5,0,0\n", 2, "t", "time is missing"),
    ],
)
def test_malformed_cell_error_names_file_line_column_and_expectation(tmp_path, body, line,
                                                                     column, expected):
    path = _write(tmp_path, HEADER + "\n" + body)
    with pytest.raises(RecordingError) as exc:
        read_csv(path)
    assert str(exc.value).startswith(f"{path}: line {line}, column '{column}': ")
    assert expected in str(exc.value)


def test_nan_cells_are_missing_samples_like_empty_ones(tmp_path):
    tr = _read(_write(tmp_path, HEADER + "\n0,NaN,0,0,0.5,0,0\n0.1,1,0,0,0.5,,nan\n"))
    assert np.isnan(tr.giver_hand[0]).all() and np.isnan(tr.receiver_hand[1]).all()
    assert np.isfinite(tr.receiver_hand[0]).all() and np.isfinite(tr.giver_hand[1]).all()


def test_a_missing_point_is_named_with_the_points_the_file_has(tmp_path):
    short = HEADER.rsplit(",", 3)[0] + "\n0,1,0,0\n"
    with pytest.raises(RecordingError, match="receiver_hand.*the file has: giver_hand"):
        read_csv(_write(tmp_path, short))
    extra = read_csv(_write(tmp_path, HEADER + ",elbow_x,elbow_y,elbow_z\n0,1,0,0,0.5,0,0,1,1,1\n"))
    assert "elbow" in extra.available  # other points are kept as named points


def test_robot_columns_are_range_checked(tmp_path):
    with pytest.raises(RecordingError, match="column 'load_share': expected 0..1"):
        read_csv(_write(tmp_path, HEADER + ",load_share\n0,1,0,0,0.5,0,0,1.5\n"))
    with pytest.raises(RecordingError, match="column 'gripper_closed': expected 0 or 1"):
        read_csv(_write(tmp_path, HEADER + ",gripper_closed\n0,1,0,0,0.5,0,0,0.5\n"))


def test_a_missing_file_is_a_recording_error_naming_it(tmp_path):
    with pytest.raises(RecordingError, match="nope.csv: cannot read"):
        read_csv(tmp_path / "nope.csv")


def test_frames_round_trip():
    frames = [
        TrackingFrame.make(0.0, [1, 0, 0], [0.5, 0, 0], None, gripper_closed=False, load_share=0.0),
        TrackingFrame.make(0.1, None, [0.5, 0, 0], [1, 0, 0.6], gripper_closed=True),
    ]
    tr = Trajectory.from_frames(frames)
    back = tr.frames()
    assert [f.t for f in back] == [0.0, 0.1]
    assert back[0].gripper_closed is False and back[1].gripper_closed is True
    assert back[0].load_share == 0.0 and back[1].load_share is None
    assert np.isnan(back[1].giver_hand).all()
    np.testing.assert_array_equal(back[1].giver_face, [1, 0, 0.6])


def test_cleaned_sorts_and_drops_duplicates_and_bad_times():
    t = np.array([0.0, 0.2, 0.1, 0.2, math.nan, 0.3])
    p = np.arange(18, dtype=float).reshape(6, 3)
    tr, reordered, dropped = Trajectory(t, p, p).cleaned()
    np.testing.assert_array_equal(tr.t, [0.0, 0.1, 0.2, 0.3])
    assert dropped == 2  # the repeated 0.2 and the NaN time
    assert reordered == 1  # 0.2 -> 0.1 goes back in time
    np.testing.assert_array_equal(tr.giver_hand[2], p[1])  # first 0.2 kept


def test_shape_mismatch_is_rejected():
    with pytest.raises(ValueError, match="giver_hand"):
        Trajectory(np.zeros(3), np.zeros((2, 3)), np.zeros((3, 3)))
