"""Hypothesis over every recording reader: any file content gives a recording that holds the
readers' promises (finite increasing times, bounded or missing coordinates) or a
:class:`RecordingError`; nothing else, no hang, bounded memory."""

from __future__ import annotations

import math
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from recording_files import sample, write_bag, write_c3d

from gazebot.io.recordings import PointNames, RecordingError, RecordingLimits, load_recording

FUZZ = settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
NAMES = PointNames("giver_hand", "receiver_hand", "giver_face")
LIMITS = RecordingLimits()

NUMBER = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["", "nan", "NaN", "-nan", "inf", "-inf", "1e308", "-1e308", "1e400",
                     "0x10", "1_000", " 1 ", "²", "١", "abc", "1e5", "1e-320"]),
    st.integers(-(10**30), 10**30).map(str),
    st.text(max_size=6),
)
COLUMNS = ["t", "time", "timestamp", "giver_hand_x", "giver_hand_y", "giver_hand_z",
           "receiver_hand_x", "receiver_hand_y", "receiver_hand_z", "giver_face_x",
           "giver_face_y", "giver_face_z", "gripper_closed", "load_share", "other", ""]


def _holds_its_promises(rec) -> None:
    tr = rec.trajectory
    t = tr.t
    assert np.isfinite(t).all()
    assert (np.diff(t) >= LIMITS.min_step_s).all() and (np.diff(t) <= LIMITS.max_gap_s).all()
    assert t.shape[0] < 2 or (math.isfinite(rec.rate) and rec.rate > 0)
    for p in (tr.giver_hand, tr.receiver_hand, tr.giver_face):
        finite = p[np.isfinite(p)]
        assert not np.isinf(p).any() and (np.abs(finite) <= LIMITS.workspace_m).all()


def _read(path: Path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy overflow, a library's note: nothing leaks
        try:
            rec = load_recording(path, **kw)
        except RecordingError as exc:
            assert str(exc).startswith(str(path)) and "\n" not in str(exc).strip()
            return None
    _holds_its_promises(rec)
    return rec


@pytest.fixture
def work(tmp_path):
    return tmp_path


@pytest.mark.timeout(240)
@FUZZ
@given(
    header=st.lists(st.sampled_from(COLUMNS), min_size=1, max_size=12),
    rows=st.lists(st.lists(NUMBER, max_size=13), max_size=25),
    sep=st.sampled_from([",", ";", "\t"]),
)
def test_csv_of_any_cells(work, bounded_memory, header, rows, sep):
    f = work / "fuzz.csv"
    f.write_text("\n".join([sep.join(header)] + [sep.join(r) for r in rows]) + "\n")
    with bounded_memory(50e6):
        _read(f)


@pytest.mark.timeout(240)
@FUZZ
@given(data=st.binary(max_size=2000))
def test_csv_of_any_bytes(work, bounded_memory, data):
    f = work / "bytes.csv"
    f.write_bytes(data)
    with bounded_memory(50e6):
        _read(f)


@pytest.mark.timeout(240)
@FUZZ
@given(
    t=st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=1, max_size=30),
    x=st.floats(allow_nan=True, allow_infinity=True),
)
def test_csv_of_any_times_and_coordinates(work, bounded_memory, t, x):
    """Well-formed files with hostile values: any time sequence, any coordinate."""
    lines = ["t,giver_hand_x,giver_hand_y,giver_hand_z,receiver_hand_x,receiver_hand_y,"
             "receiver_hand_z"]
    lines += [f"{ti!r},{x!r},0,1,0.4,0,1" for ti in t]
    f = work / "values.csv"
    f.write_text("\n".join(lines) + "\n")
    with bounded_memory(50e6):
        rec = _read(f)
    if rec is not None and math.isfinite(x) and abs(x) > LIMITS.workspace_m:
        assert rec.out_of_workspace == len(t)


@pytest.fixture(scope="module")
def c3d_bytes(tmp_path_factory):
    _, pts = sample(40)
    return write_c3d(tmp_path_factory.mktemp("c3d") / "r.c3d", pts).read_bytes()


@pytest.mark.timeout(240)
@FUZZ
@given(
    cut=st.integers(0, 20_000),
    flips=st.lists(st.tuples(st.integers(0, 20_000), st.integers(0, 255)), max_size=8),
)
def test_c3d_cut_or_with_any_bytes_changed(work, bounded_memory, c3d_bytes, cut, flips):
    data = bytearray(c3d_bytes[: max(1, cut)] if cut < len(c3d_bytes) else c3d_bytes)
    for pos, value in flips:
        if pos < len(data):
            data[pos] = value
    f = work / "fuzz.c3d"
    f.write_bytes(bytes(data))
    with bounded_memory(100e6):
        _read(f, names=NAMES)


@pytest.mark.timeout(240)
@FUZZ
@given(
    files=st.dictionaries(
        st.sampled_from(["giver_hand", "receiver_hand", "giver_face", "wrench"]),
        st.one_of(
            st.lists(st.lists(NUMBER, min_size=3, max_size=7), max_size=15).map(
                lambda rows: "x,y,z,q0,q1,q2,q3\n" + "\n".join(",".join(r) for r in rows)
            ),
            st.binary(max_size=300),
        ),
        min_size=1,
    ),
    rate=st.floats(allow_nan=True, allow_infinity=True),
)
def test_pose_folder_of_any_files(work, bounded_memory, files, rate):
    d = work / "poses"
    shutil.rmtree(d, ignore_errors=True)
    d.mkdir()
    for name, text in files.items():
        data = text if isinstance(text, bytes) else text.encode("utf-8", "surrogateescape")
        (d / f"{name}_pose_saved.csv").write_bytes(data)
    with bounded_memory(50e6):
        _read(d, names=NAMES, rate=rate)


@pytest.fixture(scope="module")
def bag_dir(tmp_path_factory):
    t, pts = sample(20)
    return write_bag(tmp_path_factory.mktemp("bag") / "bag", t, pts)


@pytest.mark.timeout(300)
@settings(FUZZ, max_examples=20)
@given(flips=st.lists(st.tuples(st.floats(0, 1), st.integers(0, 255)), min_size=1, max_size=6))
def test_rosbag_with_any_bytes_changed(work, bounded_memory, bag_dir, flips):
    d = work / "bag"
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(bag_dir, d)
    db = next(p for p in d.iterdir() if p.suffix in (".db3", ".mcap"))
    data = bytearray(db.read_bytes())
    for where, value in flips:
        data[int(where * (len(data) - 1))] = value
    db.write_bytes(bytes(data))
    with bounded_memory(100e6):
        _read(d, names=PointNames("/giver_hand", "/receiver_hand", "/giver_face"))


@pytest.fixture(scope="module")
def mcap_bytes(tmp_path_factory):
    from test_recording_limits import _write_mcap

    t, pts = sample(20)
    return _write_mcap(tmp_path_factory.mktemp("mcap") / "r.mcap", t, pts).read_bytes()


@pytest.mark.timeout(300)
@settings(FUZZ, max_examples=30)
@given(
    cut=st.floats(0, 1),
    flips=st.lists(st.tuples(st.floats(0, 1), st.integers(0, 255)), max_size=6),
)
def test_mcap_cut_or_with_any_bytes_changed(work, bounded_memory, mcap_bytes, cut, flips):
    data = bytearray(mcap_bytes[: max(1, int(cut * len(mcap_bytes)))] if cut < 1 else mcap_bytes)
    for where, value in flips:
        data[int(where * (len(data) - 1))] = value
    f = work / "fuzz.mcap"
    f.write_bytes(bytes(data))
    with bounded_memory(100e6):
        _read(f)
