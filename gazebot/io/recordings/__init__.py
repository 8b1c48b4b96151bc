"""Recording readers: the formats labs record, into a :class:`~gazebot.core.phases.Trajectory` in
SI.

:func:`load_recording` picks the reader from the file: ``.csv`` (:mod:`.csv_table`), ``.c3d``
(:mod:`.c3d_file`), ``.mcap`` files of ROS 2 messages (:mod:`.mcap_file`), ROS 1 ``.bag`` / ROS 2
bag folders and ``.db3`` (:mod:`.rosbag`),
and folders of per-body pose CSVs (:mod:`.pose_folder`). Point names choose the giver's hand,
the receiver's hand and (optionally) the giver's face; a name the file lacks is an error that
lists the names it has.
"""

from __future__ import annotations

from pathlib import Path

from gazebot.io.recordings.base import (
    PointNames,
    Recording,
    RecordingError,
    RecordingLimits,
    median_rate,
)
from gazebot.io.recordings.c3d_file import read_c3d
from gazebot.io.recordings.csv_table import read_csv
from gazebot.io.recordings.mcap_file import read_mcap
from gazebot.io.recordings.pose_folder import read_pose_folder
from gazebot.io.recordings.rosbag import read_bag


def load_recording(
    path: str | Path,
    names: PointNames | None = None,
    unit: str | None = None,
    rate: float | None = None,
    limits: RecordingLimits | None = None,
) -> Recording:
    """Read any supported recording (see the module docstring).

    Args:
        path: The file (or bag / pose folder).
        names: Point names; ``None`` fields use the format's defaults.
        unit: Length unit of CSV and pose-folder coordinates (m, cm, mm; default m). C3D files
            and bags carry their own.
        rate: Sampling rate of a pose folder (Hz).
        limits: Largest time gap and coordinate magnitude (:class:`RecordingLimits`).

    Raises:
        RecordingError: Missing or unreadable file, unknown format or unit, a wrong name, times
            not finite and increasing or a gap beyond ``limits.max_gap_s``.
    """
    path = Path(path)
    if not path.exists():
        raise RecordingError(path, "no such file")
    suffix = path.suffix.lower()
    if path.is_dir():
        if (
            (path / "metadata.yaml").is_file()
            or any(path.glob("*.db3"))
            or any(path.glob("*.mcap"))
        ):
            return read_bag(path, names, limits=limits)
        return read_pose_folder(path, names, rate, unit or "m", limits)
    if suffix == ".csv":
        return read_csv(path, names, unit or "m", limits)
    if suffix == ".c3d":
        if unit is not None:
            raise RecordingError(path, "a C3D file states its own unit (POINT:UNITS): drop --unit")
        return read_c3d(path, names, limits)
    if suffix == ".mcap":
        return read_mcap(path, names, limits=limits)
    if suffix in (".bag", ".db3"):
        return read_bag(path, names, limits=limits)
    raise RecordingError(
        path,
        f"unknown format {suffix or '(no extension)'}: expected .csv, "
        ".c3d, .mcap, .bag, a ROS 2 bag folder or a folder of pose CSVs",
    )


__all__ = [
    "PointNames",
    "Recording",
    "RecordingError",
    "RecordingLimits",
    "load_recording",
    "median_rate",
    "read_bag",
    "read_c3d",
    "read_csv",
    "read_mcap",
    "read_pose_folder",
]
