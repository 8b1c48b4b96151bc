"""Golden images: each shipped style at a few poses, rendered small, must match the stored PNGs.

Regenerate after an intended change of the drawing or the styles (then look at the PNGs):

    GAZEBOT_REGEN_GOLDEN=1 PYTHONPATH=. .venv/bin/pytest tests/apps/render/test_eyes_golden.py -q
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import cv2
import numpy as np
import pytest

from gazebot.apps.render import EyeRenderer

GOLDEN = Path(__file__).resolve().parent / "golden"
SIZE = (192, 112)  # small, to keep the repository light; same aspect as the head screens
POSES = {
    "center": (0.0, 0.0, 0.0, None),
    "right_down_near": (math.radians(25), math.radians(12), 0.0, 0.5),
    "left_up_halfblink": (math.radians(-20), math.radians(-15), 0.5, None),
}
STYLES = ["sawyer", "jaco2-head", "cartoon"]
# Per-pixel tolerance: OpenCV versions may differ in antialiasing by a few levels per edge pixel.
MEAN_ABS_TOL = 1.0
PIXEL_TOL = 48
MAX_BAD_FRACTION = 0.005


@pytest.mark.parametrize("style", STYLES)
@pytest.mark.parametrize("pose", sorted(POSES))
def test_render_matches_golden_image(style, pose):
    yaw, pitch, blink, distance = POSES[pose]
    img = EyeRenderer(*SIZE, style).render(yaw, pitch, blink=blink, distance=distance)
    path = GOLDEN / f"{style}_{pose}.png"
    if os.environ.get("GAZEBOT_REGEN_GOLDEN"):
        GOLDEN.mkdir(exist_ok=True)
        cv2.imwrite(str(path), img[..., ::-1], [cv2.IMWRITE_PNG_COMPRESSION, 9])
        pytest.skip(f"regenerated {path.name}")
    assert path.is_file(), f"missing golden image {path} (see this module's docstring)"
    golden = cv2.imread(str(path), cv2.IMREAD_COLOR)[..., ::-1]
    assert golden.shape == img.shape
    diff = np.abs(img.astype(np.int16) - golden.astype(np.int16)).max(axis=2)
    assert diff.mean() <= MEAN_ABS_TOL, f"mean abs diff {diff.mean():.3f}"
    assert (diff > PIXEL_TOL).mean() <= MAX_BAD_FRACTION, (
        f"{(diff > PIXEL_TOL).sum()} pixels differ"
    )


def test_golden_comparison_detects_a_gaze_change():
    # Guard against a tolerance so loose that the golden tests could not fail.
    r = EyeRenderer(*SIZE, "sawyer")
    a = r.render(0.0, 0.0).astype(np.int16)
    b = r.render(math.radians(8), 0.0).astype(np.int16)
    diff = np.abs(a - b).max(axis=2)
    assert (diff > PIXEL_TOL).mean() > MAX_BAD_FRACTION
