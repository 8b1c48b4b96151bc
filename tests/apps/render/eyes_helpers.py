"""Helpers shared by the eye-renderer tests (image measurements)."""

from __future__ import annotations

import numpy as np

from gazebot.apps.render import EyeRenderer, load_eye_style

MARK = (255, 0, 0)  # a pupil color no shipped style uses, so the pupil can be found by color


def marked_renderer(style: str = "sawyer", width: int = 512, height: int = 300) -> EyeRenderer:
    """A renderer of ``style`` whose pupils are pure red and have no highlights."""
    base = load_eye_style(style)
    pupil = base.pupil.model_copy(
        update={"pupil_color": MARK, "highlight_radius": 0.0, "highlight2_radius": 0.0}
    )
    return EyeRenderer(width, height, base.model_copy(update={"pupil": pupil}))


def pupil_centroids(img: np.ndarray) -> list[tuple[float, float]]:
    """(x, y) centroid of the red pupil pixels in the left and right image halves."""
    red = (img[..., 0] > 200) & (img[..., 1] < 60) & (img[..., 2] < 60)
    out = []
    half = img.shape[1] // 2
    for x0, x1 in ((0, half), (half, img.shape[1])):
        ys, xs = np.nonzero(red[:, x0:x1])
        assert xs.size > 20, "pupil not visible"
        out.append((float(xs.mean()) + x0, float(ys.mean())))
    return out


def count_color(img: np.ndarray, color: tuple[int, int, int], tol: int = 12) -> int:
    """Number of pixels within ``tol`` (per channel) of ``color``."""
    diff = np.abs(img.astype(np.int16) - np.asarray(color, np.int16)).max(axis=2)
    return int((diff <= tol).sum())
