"""The benchmark peer of gazebot's eye drawing: the robot's eyes drawn with pygame-ce (SDL)
straight onto a surface. ``benchmarks/bench_eyes.py`` times it against the OpenCV drawing of
:class:`gazebot.apps.render.EyeRenderer` (which won, so it draws everywhere; this one is kept only
as
the measured alternative).

Same geometry, style and static layers as :class:`gazebot.apps.render.eyes.EyeRenderer` (the
background, the sclera coverage and the brows are computed once by it); per frame the eye boxes
are filled with the sclera color, iris and pupil are drawn as filled polygons with antialiased
outlines, highlights as antialiased circles, the lids as polygons, and a precomputed overlay
(the background outside the sclera, alpha = 1 - coverage) clips all of it to the eye.
"""

from __future__ import annotations

import math
import os

import numpy as np

from gazebot.apps.render.eyes import EyeRenderer, _check_finite, _stroke

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
import pygame  # noqa: E402

_ELLIPSE_POINTS = 40
_COS = np.cos(np.linspace(0.0, 2.0 * math.pi, _ELLIPSE_POINTS, endpoint=False))
_SIN = np.sin(np.linspace(0.0, 2.0 * math.pi, _ELLIPSE_POINTS, endpoint=False))


def _surface(rgba: np.ndarray) -> pygame.Surface:
    """A per-pixel-alpha surface in SDL's native 32-bit layout (ARGB): blits from it onto
    32-bit surfaces take SDL's fast path (a byte-order mismatch would be ~30x slower)."""
    h, w = rgba.shape[:2]
    surf = pygame.Surface((w, h), pygame.SRCALPHA, 32)
    pygame.surfarray.pixels3d(surf)[:] = rgba[..., :3].swapaxes(0, 1)
    pygame.surfarray.pixels_alpha(surf)[:] = rgba[..., 3].swapaxes(0, 1)
    return surf


class PygameEyeRenderer(EyeRenderer):
    """Draws the eyes onto a pygame surface (:meth:`draw`) or into an RGB array (:meth:`render`)."""

    def _build(self) -> None:
        super()._build()
        h, w = self.height, self.width
        rgba = np.empty((h, w, 4), np.uint8)
        rgba[..., :3] = self._bg
        rgba[..., 3] = 255
        self._bg_surface = pygame.Surface((w, h), 0, 32)
        self._bg_surface.blit(_surface(rgba), (0, 0))
        self._overlays = []
        for lay in self._layers:
            if lay.empty:
                self._overlays.append(None)
                continue
            box = np.empty((*lay.outside.shape, 4), np.uint8)
            box[..., :3] = lay.bg
            a = np.full(lay.outside.size, 255, np.uint16)  # inside: transparent (0) below
            a[:] = np.where(lay.outside.ravel() > 0, 255, 0)
            a[lay.rim] = 256 - lay.rim_a[:, 0]
            inside = (lay.outside.ravel() == 0)
            inside[lay.rim] = False
            a[inside] = 0
            box[..., 3] = np.clip(a, 0, 255).reshape(lay.outside.shape).astype(np.uint8)
            self._overlays.append(_surface(box))
        self._brow_surfaces = []
        for sprite in self._brows:
            alpha = 1.0 - sprite.inv[..., 0]
            rgba = np.empty((*alpha.shape, 4), np.uint8)
            rgba[..., :3] = self.style.brows.color
            rgba[..., 3] = np.clip(np.rint(alpha * 255.0), 0, 255).astype(np.uint8)
            self._brow_surfaces.append((sprite.x0, sprite.y0, _surface(rgba)))
        self._target = pygame.Surface((w, h), 0, 32)

    def draw(
        self,
        surface: pygame.Surface,
        eye_yaw: float,
        eye_pitch: float,
        blink: float = 0.0,
        distance: float | None = None,
    ) -> None:
        """Draw the eyes onto ``surface`` (at least ``width`` x ``height``) at its top left."""
        yaw = _check_finite("eye_yaw", eye_yaw)
        pitch = _check_finite("eye_pitch", eye_pitch)
        blink = min(max(_check_finite("blink", blink), 0.0), 1.0)
        verg = self._vergence(distance)
        surface.blit(self._bg_surface, (0, 0))
        v_mean = 0.0
        for lay, overlay in zip(self._layers, self._overlays, strict=True):
            u, v = self._offset(yaw - lay.geom.side * verg, pitch)
            v_mean += 0.5 * v
            if overlay is None:
                continue
            rect = pygame.Rect(lay.x0, lay.y0, lay.x1 - lay.x0, lay.y1 - lay.y0)
            surface.fill(self.style.sclera.color, rect)
            clip = surface.get_clip()
            surface.set_clip(rect)
            self._draw_eye(surface, lay, u, v, blink)
            surface.set_clip(clip)
            surface.blit(overlay, rect.topleft)
        if self._brow_surfaces:
            br = self.style.brows
            dy = int(round(br.follow * v_mean + br.blink_drop * self.height * blink))
            for x0, y0, s in self._brow_surfaces:
                surface.blit(s, (x0, y0 + dy))

    def render(
        self,
        eye_yaw: float,
        eye_pitch: float,
        blink: float = 0.0,
        distance: float | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """The eyes as an ``(height, width, 3)`` uint8 RGB array (``out`` filled if given)."""
        self.draw(self._target, eye_yaw, eye_pitch, blink, distance)
        img = np.frombuffer(pygame.image.tobytes(self._target, "RGB"), np.uint8)
        img = img.reshape(self.height, self.width, 3)
        if out is None:
            return img.copy()
        np.copyto(out, img)
        return out

    def _draw_eye(self, surf: pygame.Surface, lay, u: float, v: float, blink: float) -> None:
        s, H, g = self.style, float(self.height), lay.geom
        px, py = g.cx + u, g.cy + v
        squash, angle = 1.0, 0.0
        if s.pupil.foreshorten and self._rx > 0 and self._ry > 0:
            q = (u / self._rx) ** 2 + (v / self._ry) ** 2
            squash = max(math.sqrt(max(1.0 - q, 0.0)), 0.6)
            angle = math.atan2(v, u) if q > 0 else 0.0
        ca, sa = math.cos(angle), math.sin(angle)
        for radius, color in (
            (s.pupil.iris_radius * H, s.pupil.iris_color),
            (s.pupil.pupil_radius * H, s.pupil.pupil_color),
        ):
            if radius > 0.25:
                x = radius * squash * _COS
                y = radius * _SIN
                pts = np.column_stack([px + ca * x - sa * y, py + sa * x + ca * y]).tolist()
                pygame.draw.polygon(surf, color, pts)
                pygame.draw.aalines(surf, color, True, pts)
        r_p = s.pupil.pupil_radius * H
        for radius, (ox, oy) in (
            (s.pupil.highlight_radius * H, s.pupil.highlight_offset),
            (s.pupil.highlight2_radius * H, s.pupil.highlight2_offset),
        ):
            if radius > 0.25:
                c = (px + ox * r_p * squash, py + oy * r_p)
                pygame.draw.aacircle(surf, s.pupil.highlight_color, c, radius)
        lids = s.lids
        upper, lower = self.lid_curves(g, g.cx, g.cy, v, blink)
        top, bottom = lay.y0 - 8.0, lay.y1 + 8.0
        for edge, end in ((lower, bottom), (upper, top)):
            poly = np.vstack([edge, [[edge[-1, 0], end], [edge[0, 0], end]]]).tolist()
            pygame.draw.polygon(surf, lids.color, poly)
            pygame.draw.aalines(surf, lids.color, False, edge.tolist())
        lw = lids.line_width * H
        if lw >= 0.5:
            line = _stroke(upper, lw).tolist()
            pygame.draw.polygon(surf, lids.line_color, line)
            pygame.draw.aalines(surf, lids.line_color, True, line)
