"""The default size and frame rate of every video gazebot writes (``gazebot demo``, ``render
video``, the study's stimuli, the GPS demo) and of the simulator's observer frames: stated once,
every signature and command-line default reads them from :data:`VIDEO`."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class VideoSettings:
    """A video's frame size (px) and rate (frames/s)."""

    width: int = 640
    height: int = 480
    fps: int = 30


#: The defaults: 640 x 480 px at 30 frames/s.
VIDEO = VideoSettings()
