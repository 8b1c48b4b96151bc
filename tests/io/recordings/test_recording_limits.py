"""Every recording reader bounds what a file can do: times finite and increasing with bounded
gaps (an error naming the line), coordinates beyond the workspace as counted missing samples,
a C3D cut short as an error, a pose folder's row of zeros as lost tracking, and no numpy
warning leaking from 1e308."""

from __future__ import annotations

import math
import tracemalloc
import warnings

import numpy as np
import pytest
from recording_files import sample, write_bag, write_c3d, write_csv, write_pose_folder

from gazebot.apps.cli import main
from gazebot.core.phases import PhaseConfig, run_online, segment
from gazebot.io.recordings import PointNames, RecordingError, RecordingLimits, load_recording


@pytest.mark.parametrize("outlier", [1e5, 1e155, 1e308])
def test_one_outlier_time_stamp_is_an_error_naming_its_line_in_bounded_memory(tmp_path, outlier):
    t, pts = sample()
    t[30] = outlier
    f = write_csv(tmp_path / "r.csv", t, pts)
    tracemalloc.start()
    try:
        with pytest.raises(RecordingError) as err:
            load_recording(f)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20e6
    msg = str(err.value)
    assert msg.startswith(f"{f}: line 32:") and "after the previous sample (line 31)" in msg


def test_a_time_going_back_names_both_lines(tmp_path):
    t, pts = sample()
    t[10] = t[8]
    with pytest.raises(RecordingError, match=r"line 12: time 0\.16 s is not after .*\(line 11\)"):
        load_recording(write_csv(tmp_path / "r.csv", t, pts))


def test_a_step_under_half_a_nanosecond_is_refused_and_one_of_1_ns_kept(tmp_path):
    """Found by the fuzzer: steps of 1e-309 s made the reported rate overflow."""
    t, pts = sample()
    t[:] = np.arange(t.shape[0]) * 1e-12  # 1 ps steps: no sampling, rate 1e12 Hz
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(RecordingError, match=r"line 3: .* only 1e-12 s after .*under 5e-10"):
            load_recording(write_csv(tmp_path / "r.csv", t, pts))
    t, pts = sample()
    t[0], t[1] = 5.000000005, 5.000000006  # 1 ns apart (sim time): 0.999999e-9 s in floats
    t[2:] += 5.0
    assert math.isfinite(load_recording(write_csv(tmp_path / "ok.csv", t, pts)).rate)


def test_the_gap_bound_is_configurable(tmp_path):
    t, pts = sample()
    t[30:] += 5.0
    f = write_csv(tmp_path / "r.csv", t, pts)
    assert len(load_recording(f).trajectory) == 60  # 5 s: under the default bound
    with pytest.raises(RecordingError, match="gaps over 2 s are refused"):
        load_recording(f, limits=RecordingLimits(max_gap_s=2.0))


def test_the_cli_says_it_in_one_line_and_exits_2(tmp_path, capsys):
    t, pts = sample()
    t[5] = 1e308
    f = write_csv(tmp_path / "r.csv", t, pts)
    assert main(["phases", str(f)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"gazebot: error: {f}: line 7:")


NAMES = PointNames("giver_hand", "receiver_hand", "giver_face")


def _huge(pts: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    pts = {k: v.copy() for k, v in pts.items()}
    pts["giver_hand"][20] = [1e308, 0.0, 0.0]
    pts["giver_hand"][21] = [0.0, -1e308, 0.0]
    pts["receiver_hand"][40] = [0.0, 0.0, 1e3]  # 1 km: beyond a plausible workspace
    return pts


def _no_warnings_through_the_phases(rec) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        segment(rec.trajectory, PhaseConfig())
        run_online(rec.trajectory, PhaseConfig())


def test_csv_coordinates_beyond_the_workspace_are_counted_missing_samples(tmp_path):
    t, pts = sample()
    f = write_csv(tmp_path / "r.csv", t, _huge(pts))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rec = load_recording(f)
    assert rec.out_of_workspace == 3
    assert np.isnan(rec.trajectory.giver_hand[[20, 21]]).all()
    assert np.isnan(rec.trajectory.receiver_hand[40]).all()
    assert np.isfinite(rec.trajectory.giver_hand[19]).all()
    assert "3 point samples beyond the workspace made missing" in rec.describe()
    _no_warnings_through_the_phases(rec)


def test_the_cli_warns_with_the_count(tmp_path, capsys):
    t, pts = sample()
    f = write_csv(tmp_path / "r.csv", t, _huge(pts))
    assert main(["phases", str(f)]) == 0
    assert "3 point sample(s) beyond the workspace bound made missing" in capsys.readouterr().err
    assert main(["phases", str(f), "--workspace", "2000"]) == 0  # the 1 km point is inside now
    assert "2 point sample(s) beyond the workspace" in capsys.readouterr().err


def test_c3d_coordinates_beyond_the_workspace_are_counted_without_warnings(tmp_path):
    t, pts = sample()
    pts = {k: v.copy() for k, v in pts.items()}
    pts["giver_hand"][20] = [3e38, 0.0, 0.0]  # float32's largest: C3D cannot hold 1e308
    pts["giver_hand"][21] = [0.0, 1e308, 0.0]  # stored as inf: the reader marks it invalid
    f = write_c3d(tmp_path / "r.c3d", pts)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rec = load_recording(f, NAMES)
    assert rec.out_of_workspace == 1 and np.isnan(rec.trajectory.giver_hand[[20, 21]]).all()
    _no_warnings_through_the_phases(rec)


def test_a_c3d_cut_in_half_is_a_clear_error_not_a_warning(tmp_path):
    t, pts = sample(200)
    f = write_c3d(tmp_path / "r.c3d", pts)
    data = f.read_bytes()
    f.write_bytes(data[: len(data) // 2])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(RecordingError, match=r"ends after \d+ of its 200 frames"):
            load_recording(f)


def test_pose_folder_bounds_coordinates_and_refuses_a_rate_with_huge_steps(tmp_path):
    _, pts = sample()
    d = write_pose_folder(tmp_path / "poses", _huge(pts))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rec = load_recording(d, NAMES, rate=50.0)
    assert rec.out_of_workspace == 3
    with pytest.raises(RecordingError, match="row 3: .*gaps over 60 s"):
        load_recording(d, NAMES, rate=1e-6)
    # a rate so small that the sample times overflow (found by the pose-folder fuzz test)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(RecordingError, match=r"--rate 2\.2250738585e-313 Hz"):
            load_recording(d, NAMES, rate=2.2250738585e-313)
    # a rate that is no finite positive number is named as the fault, not the data
    for bad in (math.inf, -50.0, 0.0, math.nan, "fast"):
        with pytest.raises(RecordingError, match="expected a finite rate > 0 in Hz"):
            load_recording(d, NAMES, rate=bad)


def test_bag_outlier_stamp_is_an_error_naming_the_topic(tmp_path):
    t, pts = sample(30)
    sec = t.astype(int)
    sec[12] = 2_000_000_000  # one header stamp in 2033
    with pytest.raises(RecordingError, match=r"stamped 2e\+09 s on /giver_face, /giver_hand"):
        load_recording(write_bag(tmp_path / "bag", t, pts, sec=sec))


def test_bag_coordinates_beyond_the_workspace_are_left_out_before_interpolating(tmp_path):
    t, pts = sample()
    f = write_bag(tmp_path / "bag", t, _huge(pts))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rec = load_recording(f, PointNames("/giver_hand", "/receiver_hand", "/giver_face"))
    assert rec.out_of_workspace == 3
    # Interpolated from its finite neighbours: nothing of 1e308 smears into them.
    g = rec.trajectory.giver_hand
    assert np.isfinite(g).all() and np.abs(g).max() < 2.0
    _no_warnings_through_the_phases(rec)


def _write_mcap(path, t, pts):
    from gazebot.io.ros2 import convert as cv
    from gazebot.io.ros2 import topics as tp
    from gazebot.io.ros2.mcap_writer import McapRecorder

    with McapRecorder(path) as rec:
        for i, ti in enumerate(t):
            for body in cv.BODIES:
                rec.write(tp.TRACKING[body].resolve(), cv.point_stamped(ti, pts[body][i], "world"),
                          ti)
    return path


def test_mcap_outlier_stamp_is_an_error_and_huge_coordinates_are_counted(tmp_path):
    t, pts = sample()
    t2 = t.copy()
    t2[30] = 1e5
    with pytest.raises(RecordingError, match=r"stamped 100000 s on .*gaps over 60 s"):
        load_recording(_write_mcap(tmp_path / "outlier.mcap", t2, pts))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rec = load_recording(_write_mcap(tmp_path / "huge.mcap", t, _huge(pts)))
    assert rec.out_of_workspace == 3
    assert np.isfinite(rec.trajectory.giver_hand).all()  # interpolated over the left-out rows
    _no_warnings_through_the_phases(rec)


def test_pose_folder_reads_a_row_at_the_origin_as_lost_tracking(tmp_path):
    # YCB-Handovers: a hand moving at 1.08 m height has one row of zeros (tracking lost).
    _, pts = sample()
    pts = {k: v + 0.5 for k, v in pts.items()}  # off the origin everywhere
    pts[NAMES.receiver_hand][7] = 0.0
    d = write_pose_folder(tmp_path / "poses", pts)
    rec = load_recording(d, NAMES, rate=50.0)
    r = rec.trajectory.receiver_hand
    assert np.isnan(r[7]).all()
    assert np.isfinite(np.delete(r, 7, axis=0)).all()
    assert np.isfinite(rec.trajectory.giver_hand).all()
    assert rec.notes == (f"{NAMES.receiver_hand}_pose_saved.csv: 1 row(s) at exactly (0, 0, 0) "
                         "read as lost tracking",)
    # a coordinate of zero alone is a position like any other
    pts[NAMES.receiver_hand][7] = [0.0, 0.0, 0.3]
    rec = load_recording(write_pose_folder(tmp_path / "p2", pts), NAMES, rate=50.0)
    assert np.isfinite(rec.trajectory.receiver_hand).all() and rec.notes == ()
