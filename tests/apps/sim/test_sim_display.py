"""Eyes drawn by the eye renderer show on the head display in the observer's video frames."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.sim.scene import display_corners
from gazebot.apps.sim.simulation import HandoverSimulation

W, H = 320, 240


def _pixel(sim: HandoverSimulation, point: np.ndarray) -> tuple[int, int]:
    """Row and column of a world point in the observer image."""
    cam = sim.model.camera("observer")
    pos, rot = sim.data.cam_xpos[cam.id], sim.data.cam_xmat[cam.id].reshape(3, 3)
    v = rot.T @ (point - pos)
    f = (H / 2) / np.tan(np.radians(sim.model.cam_fovy[cam.id]) / 2)
    return int(round(H / 2 - f * v[1] / -v[2])), int(round(W / 2 + f * v[0] / -v[2]))


@pytest.fixture(scope="module")
def sim():
    s = HandoverSimulation("sawyer", "default", seed=0)
    yield s
    s.close()


def test_display_texture_changes_when_the_eyes_move(sim):
    # The screen's box in the image (its projected corners, a pixel of slack).
    rows, cols = zip(*(_pixel(sim, p) for p in display_corners(sim.model, sim.data)), strict=True)
    crop = (slice(min(rows) - 2, max(rows) + 3), slice(min(cols) - 2, max(cols) + 3))
    sim.apply_eyes(0.0, 0.0)
    center = sim.render(width=W, height=H)
    sim.apply_eyes(0.6, 0.0)
    left = sim.render(width=W, height=H)
    sim.apply_eyes(0.0, 0.0)
    again = sim.render(width=W, height=H)
    diff = np.abs(center.astype(int) - left.astype(int)).sum(axis=2)
    assert diff[crop].sum() > 2000  # the pupils moved on the display
    # ...and in the screen close-up, and nothing else in the frame changed.
    x0, y0, x1, y1 = sim.inset_rect(W, H)
    assert diff[y0:y1, x0:x1].sum() > 2000
    outside = diff.copy()
    outside[crop] = 0
    outside[y0:y1, x0:x1] = 0
    assert outside.sum() == 0
    np.testing.assert_array_equal(center, again)


def test_display_shows_a_set_image_and_a_blink(sim):
    row, col = _pixel(sim, sim.data.site("gaze").xpos)
    crop = (slice(row - 6, row + 7), slice(col - 8, col + 9))
    red = np.zeros((60, 100, 3), np.uint8)
    red[..., 0] = 255
    sim.set_display(red)
    np.testing.assert_array_equal(sim.display.read()[0, 0], [255, 0, 0])
    img = sim.render(width=W, height=H)
    patch = img[crop].reshape(-1, 3).astype(int)
    assert np.median(patch[:, 0]) > 150 and np.median(patch[:, 1]) < 60
    sim.apply_eyes(0.0, 0.0, blink=0.0)
    open_eyes = sim.render(width=W, height=H)
    sim.apply_eyes(0.0, 0.0, blink=1.0)
    closed = sim.render(width=W, height=H)
    assert np.abs(open_eyes[crop].astype(int) - closed[crop].astype(int)).sum() > 500


def test_display_rejects_a_non_rgb_image(sim):
    with pytest.raises(ValueError, match="uint8 RGB"):
        sim.set_display(np.zeros((10, 10), np.uint8))


def test_render_rejects_an_oversized_frame_and_an_unknown_camera(sim):
    with pytest.raises(ValueError, match="at most"):
        sim.render(width=5000, height=100)
    with pytest.raises(ValueError, match="unknown camera"):
        sim.render(camera="nope", width=W, height=H)


def test_dropping_one_renderer_leaves_another_intact():
    import gc

    from gazebot.apps.render.offscreen import OffscreenRenderer

    a = HandoverSimulation("sawyer", "default", seed=0)
    first = OffscreenRenderer(a.model, 64, 48)
    reference = first.render(a.data, "observer")
    second = OffscreenRenderer(a.model, 64, 48)
    del first  # GL ids are per context: freeing must not touch the second renderer's
    gc.collect()
    np.testing.assert_array_equal(second.render(a.data, "observer"), reference)
