"""Pair videos of a session: "Handover 1" card, first handover, "Handover 2" card, second."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def title_card(text: str, width: int, height: int) -> np.ndarray:
    """A black RGB frame with ``text`` centred in white (OpenCV Hershey font)."""
    import cv2

    img = np.zeros((height, width, 3), np.uint8)
    font = cv2.FONT_HERSHEY_SIMPLEX
    scale = width / 320.0
    thickness = max(1, round(width / 240))
    (tw, th), _ = cv2.getTextSize(text, font, scale, thickness)
    org = ((width - tw) // 2, (height + th) // 2)
    cv2.putText(img, text, org, font, scale, (255, 255, 255), thickness, cv2.LINE_AA)
    return img


def make_pair_video(
    first: Path, second: Path, out_path: Path, width: int, height: int, fps: int, card_s: float
) -> Path:
    """Title card + first video + title card + second video, re-encoded as one H.264 MP4 (frames
    of another size are resized); the file appears only once it is complete."""
    import cv2
    import imageio.v2 as imageio

    from gazebot.apps.render.video import open_h264_writer

    n_card = max(1, round(card_s * fps))
    with open_h264_writer(out_path, fps, (width, height)) as writer:
        for label, src in (("Handover 1", first), ("Handover 2", second)):
            card = title_card(label, width, height)
            for _ in range(n_card):
                writer.append(card)
            with imageio.get_reader(src, format="FFMPEG") as reader:
                for frame in reader:
                    if frame.shape[:2] != (height, width):
                        frame = cv2.resize(frame, (width, height))
                    writer.append(frame[..., :3])
    return out_path
