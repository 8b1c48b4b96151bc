"""A small off-screen renderer that owns its GL context, so the display texture can be uploaded to
exactly the context that draws (``mujoco.Renderer`` keeps its context private)."""

from __future__ import annotations

import mujoco
import numpy as np

from gazebot.apps.render.gl_check import explain_failure


class OffscreenRenderer:
    """Renders RGB frames of ``model`` off-screen at ``width`` x ``height``.

    The back end is whatever ``MUJOCO_GL`` selects (``egl`` or ``osmesa`` on a server).
    """

    def __init__(
        self, model: mujoco.MjModel, width: int, height: int, max_geom: int = 2000
    ) -> None:
        buf_w, buf_h = model.vis.global_.offwidth, model.vis.global_.offheight
        if not (0 < width <= buf_w and 0 < height <= buf_h):
            raise ValueError(
                f"frame size {width}x{height} must be positive and at most {buf_w}x{buf_h}"
            )
        self.model = model
        self.width, self.height = int(width), int(height)
        self._gl = None
        try:
            self._gl = mujoco.GLContext(buf_w, buf_h)
            self._gl.make_current()
            self.context = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
        except Exception as exc:  # GL errors come as FatalError, RuntimeError, AttributeError...
            raise explain_failure(exc) from exc
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self.context)
        self.scene = mujoco.MjvScene(model, maxgeom=max_geom)
        self.option = mujoco.MjvOption()
        self.camera = mujoco.MjvCamera()
        self._rect = mujoco.MjrRect(0, 0, self.width, self.height)
        self._rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)
        self.texture_version: dict[int, int] = {}  # texture id -> version uploaded

    def make_current(self) -> None:
        self._gl.make_current()

    def render(self, data: mujoco.MjData, camera: str | int = -1) -> np.ndarray:
        """Draw ``data`` from the named fixed camera (``-1``: the free camera) and return RGB."""
        self._gl.make_current()
        cam = self.camera
        if camera == -1:
            cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        else:
            cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
            cam.fixedcamid = camera if isinstance(camera, int) else self._camera_id(camera)
        mujoco.mjv_updateScene(
            self.model, data, self.option, None, cam, mujoco.mjtCatBit.mjCAT_ALL, self.scene
        )
        mujoco.mjr_render(self._rect, self.scene, self.context)
        mujoco.mjr_readPixels(self._rgb, None, self._rect, self.context)
        return np.flipud(self._rgb).copy()

    def _camera_id(self, name: str) -> int:
        cam_id = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, name)
        if cam_id < 0:
            known = [self.model.camera(i).name for i in range(self.model.ncam)]
            raise ValueError(f"unknown camera {name!r} (known: {known})")
        return cam_id

    def close(self) -> None:
        """Free the GL resources with this renderer's own context current: GL object ids are per
        context, so freeing them under another renderer's context would delete that one's."""
        if self._gl is not None:
            self._gl.make_current()
            self.context.free()
            self._gl.free()
            self._gl = None

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown may have torn GL down already
            pass
