"""H.264 MP4 writing shared by every video gazebot makes (the simulated handovers, the study's
pair videos and its synthetic stand-in clips): one encoder setting, and atomic files.

:func:`open_h264_writer` encodes RGB frames with libx264 to yuv420p through imageio-ffmpeg into a
temporary file beside the target and renames it over the target only when the writer closes
without an error, so a failed or interrupted run never leaves a truncated, undecodable MP4.

The handover recording loop (``record_handover``, ``render_handover_video``) lives in
:mod:`gazebot.apps.sim.record`: render draws things, sim runs the handover, and data flows one way
(sim imports render, never the reverse).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from gazebot.io.atomic import AtomicWriter

# One encoder thread keeps the bit stream identical run to run (same seed, same bytes) and leaves
# the other core to physics and rendering; CRF 20 at "veryfast" is visually clean at 640x480.
H264_OUTPUT_PARAMS = ("-preset", "veryfast", "-crf", "20", "-threads", "1")


class H264Writer(AtomicWriter):
    """An open H.264 MP4 being written; use :func:`open_h264_writer` to make one.

    Frames go to a temporary file (:attr:`part`); :meth:`close` finishes the stream and renames
    it to :attr:`path`; :meth:`abort` (or leaving the ``with`` block by an exception) deletes it.
    """

    def __init__(self, path: Path, fps: float, size: tuple[int, int]) -> None:
        import imageio_ffmpeg

        super().__init__(path)
        self.fps = fps
        self.size = size  # (width, height) px
        self.frames = 0
        self._gen: Any = imageio_ffmpeg.write_frames(
            str(self.part),
            size,
            fps=fps,
            codec="libx264",
            pix_fmt_in="rgb24",
            pix_fmt_out="yuv420p",
            macro_block_size=2,
            quality=None,
            output_params=list(H264_OUTPUT_PARAMS),
            ffmpeg_log_level="error",
        )
        self._gen.send(None)
        self._open = True

    def append(self, frame: np.ndarray) -> None:
        """Add one (height, width, 3) uint8 RGB frame.

        Raises:
            ValueError: wrong shape or dtype (the encoder would silently misread the bytes).
        """
        width, height = self.size
        if frame.shape != (height, width, 3) or frame.dtype != np.uint8:
            raise ValueError(
                f"video frame must be ({height}, {width}, 3) uint8 RGB, "
                f"got {frame.shape} {frame.dtype}"
            )
        if not self._open:
            raise ValueError(f"the video writer for {self.path} is closed")
        self._gen.send(np.ascontiguousarray(frame))
        self.frames += 1

    def close(self) -> Path:
        """Finish the MP4 and move it to :attr:`path`; returns the path.

        Raises:
            ValueError: no frame was written (an empty MP4 is not a video).
        """
        if not self._open:
            return self.path
        if self.frames == 0:
            self.abort()
            raise ValueError(f"no frames were written to {self.path}")
        self._open = False
        try:
            self._gen.close()
        except BaseException:
            self.part.unlink(missing_ok=True)
            raise
        return self._commit()

    def abort(self) -> None:
        """Stop encoding and delete the partial file (the target is left untouched)."""
        if self._open:
            self._open = False
            try:
                self._gen.close()
            except Exception:  # noqa: BLE001 - already failing; the partial file goes anyway
                pass
        self.part.unlink(missing_ok=True)


def open_h264_writer(path: str | Path, fps: float, size: tuple[int, int]) -> H264Writer:
    """Open an H.264 (libx264, yuv420p) MP4 writer for ``size`` = (width, height) px frames.

    Use it as a context manager: the file appears at ``path`` only if the block ends without an
    error. Deterministic: the same frames give the same bytes.

    Raises:
        ValueError: odd or tiny size (yuv420p needs even sides), or a non-positive frame rate.
    """
    width, height = size
    for name, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 16 or v % 2:
            raise ValueError(f"video {name} must be an even number of pixels >= 16, got {v!r}")
    if not (isinstance(fps, (int, float)) and math.isfinite(fps) and fps > 0):
        raise ValueError(f"video fps must be a positive number, got {fps!r}")
    return H264Writer(Path(path), float(fps), (int(width), int(height)))


__all__ = ["H264_OUTPUT_PARAMS", "H264Writer", "open_h264_writer"]
