"""The robot's head display: eye images go into the model's ``display`` texture.

Images are written into ``model.tex_data`` in image order (row 0 = top row, as MuJoCo stores a PNG
file's texture), then uploaded to each renderer's GL context before it draws.
"""

from __future__ import annotations

import cv2
import mujoco
import numpy as np

DISPLAY_TEXTURE = "display"


class DisplayTexture:
    """Handle on the robot's ``display`` texture (RGB, ``height`` x ``width``)."""

    def __init__(self, model: mujoco.MjModel, name: str = DISPLAY_TEXTURE) -> None:
        try:
            tex = model.texture(name)
        except KeyError as exc:
            raise ValueError(
                f"the robot model has no texture named {name!r} for its display"
            ) from exc
        self.model = model
        self.id = int(tex.id)
        self.height = int(model.tex_height[self.id])
        self.width = int(model.tex_width[self.id])
        self.channels = int(model.tex_nchannel[self.id])
        adr = int(model.tex_adr[self.id])
        size = self.height * self.width * self.channels
        self._view = model.tex_data[adr : adr + size].reshape(
            self.height, self.width, self.channels
        )
        self.version = 0  # bumps on every write; renderers upload when theirs is older

    def write(self, image: np.ndarray) -> None:
        """Show ``image`` ((H, W, 3) uint8 RGB, any size: resized to the texture) on the display."""
        img = np.asarray(image)
        if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8:
            raise ValueError(
                f"display image must be (H, W, 3) uint8 RGB, got {img.shape} {img.dtype}"
            )
        if img.shape[:2] != (self.height, self.width):
            img = cv2.resize(img, (self.width, self.height), interpolation=cv2.INTER_AREA)
        self._view[..., :3] = img
        if self.channels == 4:
            self._view[..., 3] = 255
        self.version += 1

    def read(self) -> np.ndarray:
        """The current display image ((H, W, 3) uint8)."""
        return self._view[..., :3].copy()

    def upload(self, context: mujoco.MjrContext) -> None:
        """Push the texture to the GL context (which must be current)."""
        mujoco.mjr_uploadTexture(self.model, context, self.id)
