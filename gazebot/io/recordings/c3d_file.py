"""C3D recordings (``c3d`` package): point labels are the names, ``POINT:UNITS`` the unit (mm
converted to m), ``POINT:RATE`` the rate. A point the C3D marks invalid (negative residual) is
missing.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from gazebot.io.recordings.base import (
    PointNames,
    Recording,
    RecordingError,
    RecordingLimits,
    build,
)


def read_c3d(
    path: str | Path, names: PointNames | None = None, limits: RecordingLimits | None = None
) -> Recording:
    """Read a C3D file's points; ``limits``: see
    :class:`~gazebot.io.recordings.base.RecordingLimits`.

    Raises:
        RecordingError: Not a readable C3D file, one that ends before its last frame (cut
            short), an unknown unit, or a label the file lacks.
    """
    import c3d  # a well-kept pure-Python C3D reader

    path = Path(path)
    try:
        with path.open("rb") as fh, warnings.catch_warnings(), np.errstate(all="ignore"):
            # The library's notes on odd headers (no analog channels, parameter pointers it
            # works around) are not the user's business: only points are read, checked below.
            warnings.simplefilter("ignore")
            # The reader only warns when the file ends early and returns the frames so far.
            warnings.filterwarnings("error", "reached end of file", UserWarning)
            reader = c3d.Reader(fh)
            labels = [str(s).strip() for s in reader.point_labels]
            rate = float(reader.point_rate)
            units_param = reader.get("POINT:UNITS")
            unit = units_param.string_value.strip() if units_param is not None else "mm"
            first = int(reader.first_frame)
            frames = []
            for _, pts, _ in reader.read_frames(copy=True):
                p = np.array(pts[:, :3], dtype=float)
                p[pts[:, 3] < 0] = np.nan
                frames.append(p)
    except RecordingError:
        raise
    except UserWarning as exc:
        if "end of file" not in str(exc):
            raise RecordingError(path, f"not a readable C3D file ({exc})") from None
        expected = reader.last_frame - reader.first_frame + 1
        raise RecordingError(
            path,
            f"the file ends after {len(frames)} of its {expected} frames (cut short or still "
            "being written?)",
        ) from None
    except OSError as exc:
        raise RecordingError(path, f"cannot read: {exc.strerror or exc}") from None
    except Exception as exc:  # the reader raises plain errors on malformed files
        raise RecordingError(path, f"not a readable C3D file ({exc})") from None
    if not frames:
        raise RecordingError(path, "C3D file holds no frames")
    data = np.stack(frames)  # (N, points, 3)
    t = (np.arange(data.shape[0]) + first - 1) / rate
    points = {lab: data[:, i, :] for i, lab in enumerate(labels) if lab}
    return build(
        path,
        "c3d",
        t,
        points,
        names or PointNames(),
        unit,
        (None, None, None),
        limits=limits,
        where=lambda i: f"frame {first + i}",
    )
