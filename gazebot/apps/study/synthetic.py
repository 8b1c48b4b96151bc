"""A fast stand-in for ``gazebot.apps.sim.record.render_handover_video``: a short H.264 clip of flat
frames labelled with robot, behavior and scene.

Same signature as the real renderer, so ``gazebot study render --renderer synthetic`` can dry-run
a whole study (caching, pairing, title cards, questionnaire) in seconds without MuJoCo, and the
tests can exercise the pipeline with real video files.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

from gazebot.apps.render.video_settings import VIDEO


def render_synthetic_video(
    robot: str,
    behavior: str,
    scene: str,
    out_path: str | Path,
    seed: int = 0,
    width: int = VIDEO.width,
    height: int = VIDEO.height,
    fps: int = VIDEO.fps,
    progress: bool = True,
    duration: float = 1.0,
    gaze_mode: str = "head-and-eyes",
) -> Path:
    """Write a ``duration``-second clip (deterministic for its arguments) and return its path."""
    import cv2

    from gazebot.apps.render.video import open_h264_writer

    if width % 2 or height % 2 or width < 16 or height < 16:
        raise ValueError(f"width and height must be even and >= 16, got {width}x{height}")
    digest = hashlib.sha256(f"{robot}|{behavior}|{scene}|{seed}|{gaze_mode}".encode()).digest()
    color = np.frombuffer(digest[:3], dtype=np.uint8)
    frames = max(1, round(duration * fps))
    base = np.empty((height, width, 3), np.uint8)
    base[:] = color // 2 + 64
    label = f"{robot} {behavior} {scene} s{seed}"
    scale = max(width / 900.0, 0.25)
    cv2.putText(base, label, (4, height // 2), cv2.FONT_HERSHEY_SIMPLEX, scale, (255, 255, 255), 1)
    with open_h264_writer(out_path, fps, (width, height)) as writer:
        for k in range(frames):
            frame = base.copy()
            # A moving square so consecutive frames differ, like a real handover clip.
            x = int((width - 8) * k / max(frames - 1, 1))
            frame[height - 12 : height - 4, x : x + 8] = 255
            writer.append(frame)
    return Path(out_path)
