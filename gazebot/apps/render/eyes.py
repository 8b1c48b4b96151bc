"""Live, off-screen eye images for a robot's head screen, driven by the eye yaw/pitch of the gaze.

Conventions (the same as the kinematics' ``gaze`` frame, seen by a person facing the robot):

- positive ``eye_yaw`` = the robot looks to ITS left = the pupils move to the RIGHT of the image;
- positive ``eye_pitch`` = the robot looks DOWN = the pupils move LOWER in the image;
- ``distance`` (m) to the target converges the eyes: each eye turns inward by
  ``atan(baseline / 2 / distance)`` (``EyeStyle.vergence_baseline_m``); ``None``/``inf`` = parallel.

Angle-to-pixel model: the pupil is a disc on an eyeball "sphere" (an ellipsoid scaled to the
sclera) seen orthographically, so its center moves by ``u = Rx * cos(pitch) * sin(yaw)`` (right) and
``v = Ry * sin(pitch)`` (down). The radii are chosen so that the robot's eye range (``yaw_range``,
``pitch_range``, from the robot YAML) brings the iris to the edge of its travel
(``Ux = travel * (sclera half-width - iris radius)``, ``Rx = Ux / sin(yaw_range)``, same for y).
Angles beyond the range are clamped to it, and the center is kept inside the travel ellipse
``(u/Ux)^2 + (v/Uy)^2 <= 1``. Non-finite angles, blink or distance raise ``ValueError``; a blink
outside 0..1 is clamped. The disc narrows along the direction it turns (foreshortening).

Speed: everything static (background, gradient, cheeks, eye outlines and the antialiased sclera
coverage masks) is drawn once. Per frame only each eye's box is redrawn with OpenCV's antialiased
primitives at 1/16-px precision (iris, pupil, highlights), then composited over the copied
background through the precomputed sclera coverage, which also clips the pupil to the eye
(a masked copy outside, an integer blend on the 1-2 px rim); the lids are drawn over that and
clipped the same way to the eye with its outline, so a lowered lid hides the outline above it;
then the brows are filled as stroke polygons (much faster than thick antialiased polylines).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import cv2
import numpy as np

from gazebot.apps.render.eye_style import EyeStyle, load_eye_style
from gazebot.apps.render.eyes_display import robot_display
from gazebot.core.defaults import DEFAULT_ROBOT

if TYPE_CHECKING:
    from gazebot.core.kinematics.robot_config import RobotConfig

_SHIFT = 4  # fixed-point bits for OpenCV drawing: positions at 1/16 px
_ONE = 1 << _SHIFT


def superellipse_coverage(
    shape: tuple[int, int], center: tuple[float, float], axes: tuple[float, float], exponent: float
) -> np.ndarray:
    """Antialiased coverage (float32 0..1) of ``|x/a|^n + |y/b|^n <= 1`` on a pixel grid.

    Pixel ``(i, j)`` has its center at ``(x=j, y=i)`` (OpenCV's convention); the coverage is
    ``clip(0.5 - d, 0, 1)`` with ``d`` the first-order signed distance to the boundary in pixels.
    """
    h, w = shape
    a, b = max(axes[0], 1e-6), max(axes[1], 1e-6)
    x = np.abs(np.arange(w, dtype=np.float64) - center[0])[None, :] / a
    y = np.abs(np.arange(h, dtype=np.float64) - center[1])[:, None] / b
    n = exponent
    g = x**n + y**n
    gn = np.maximum(g, 1e-12)
    f = gn ** (1.0 / n) - 1.0
    # Gradient of f = g^(1/n) - 1 (a degree-1 homogeneous "radius"), in 1/px.
    k = gn ** (1.0 / n - 1.0)
    fx = k * x ** (n - 1.0) / a
    fy = k * y ** (n - 1.0) / b
    grad = np.sqrt(fx**2 + fy**2)
    d = np.where(g < 1e-12, -np.inf, f / np.maximum(grad, 1e-12))
    return np.clip(0.5 - d, 0.0, 1.0).astype(np.float32)


def _fixed(v: float) -> int:
    return int(round(v * _ONE))


def _check_finite(name: str, value: float) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(out):
        raise ValueError(f"{name} must be finite, got {out}")
    return out


@dataclass(frozen=True)
class EyeGeometry:
    """Pixel geometry of one eye in frame coordinates (``x`` right, ``y`` down)."""

    cx: float
    cy: float
    a: float  # sclera half-width (px)
    b: float  # sclera half-height (px)
    side: int  # -1 = image-left eye (the robot's right eye), +1 = image-right eye


class _EyeLayer:
    """Per-eye box: the static background under it, the sclera coverage and a scratch layer.

    Compositing is split by the (static) coverage: pixels fully outside the sclera get the
    background with one masked copy, pixels fully inside keep the drawn layer, and only the thin
    antialiased rim is blended, in integer arithmetic on precomputed indices.
    """

    def __init__(
        self,
        geom: EyeGeometry,
        pad: float,
        frame_shape: tuple[int, int],
        exponent: float,
        sclera_color: tuple[int, int, int],
        outline: float = 0.0,
    ):
        h, w = frame_shape
        self.geom = geom
        self.x0 = max(int(math.floor(geom.cx - geom.a - pad)), 0)
        self.y0 = max(int(math.floor(geom.cy - geom.b - pad)), 0)
        self.x1 = min(int(math.ceil(geom.cx + geom.a + pad)) + 1, w)
        self.y1 = min(int(math.ceil(geom.cy + geom.b + pad)) + 1, h)
        self.empty = self.x1 <= self.x0 or self.y1 <= self.y0
        bh, bw = max(self.y1 - self.y0, 1), max(self.x1 - self.x0, 1)
        self.ex = geom.cx - self.x0  # eye center in box coordinates
        self.ey = geom.cy - self.y0
        alpha = superellipse_coverage((bh, bw), (self.ex, self.ey), (geom.a, geom.b), exponent)
        a8 = np.rint(alpha * 256.0).astype(np.uint16).ravel()
        self.outside = (a8 == 0).reshape(bh, bw).astype(np.uint8)
        self.rim = np.nonzero((a8 > 0) & (a8 < 256))[0]
        self.rim_a = a8[self.rim][:, None]
        self.template = np.empty((bh, bw, 3), np.uint8)
        self.template[:] = sclera_color
        self.layer = self.template.copy()
        self.bg = np.zeros((bh, bw, 3), np.uint8)
        self.rim_bg = np.zeros((self.rim.size, 3), np.uint16)
        # The eye with its outline: lids cover the outline too (a lowered lid hides the ring),
        # to a pixel beyond it, so the ring's antialiased edge does not show as a faint line.
        grow = outline + 1.0 if outline > 0 else 0.0
        outer = superellipse_coverage(
            (bh, bw), (self.ex, self.ey), (geom.a + grow, geom.b + grow), exponent
        )
        o8 = np.rint(outer * 256.0).astype(np.uint16).ravel()
        self.outer_outside = (o8 == 0).reshape(bh, bw).astype(np.uint8)
        self.outer_rim = np.nonzero((o8 > 0) & (o8 < 256))[0]
        self.outer_rim_a = o8[self.outer_rim][:, None]
        self.lidded = self.template.copy()

    def set_background(self, frame_bg: np.ndarray) -> None:
        if self.empty:  # the eye lies outside the frame: nothing to composite
            return
        self.bg = np.ascontiguousarray(frame_bg[self.y0 : self.y1, self.x0 : self.x1])
        self.rim_bg = self.bg.reshape(-1, 3)[self.rim].astype(np.uint16) * (256 - self.rim_a)

    def composite(self) -> np.ndarray:
        """The drawn layer clipped to the sclera over the background (in place, returned)."""
        cv2.copyTo(self.bg, self.outside, self.layer)
        flat = self.layer.reshape(-1, 3)
        mixed = flat[self.rim].astype(np.uint16) * self.rim_a + self.rim_bg
        flat[self.rim] = (mixed >> 8).astype(np.uint8)
        return self.layer

    def clip_outer(self, drawn: np.ndarray, under: np.ndarray) -> np.ndarray:
        """``drawn`` (lids drawn over ``under``) clipped to the eye and its outline, over
        ``under`` (``drawn`` in place, returned)."""
        cv2.copyTo(under, self.outer_outside, drawn)
        a = self.outer_rim_a
        top, low = drawn.reshape(-1, 3), under.reshape(-1, 3)
        mixed = top[self.outer_rim].astype(np.uint16) * a + low[self.outer_rim] * (256 - a)
        top[self.outer_rim] = (mixed >> 8).astype(np.uint8)
        return drawn


class _Sprite:
    """A static antialiased shape in one color, painted over a frame at a vertical offset."""

    def __init__(self, x0: int, y0: int, alpha: np.ndarray, color: tuple[int, int, int]):
        self.x0, self.y0 = x0, y0
        a = np.repeat(np.clip(alpha, 0.0, 1.0).astype(np.float32)[..., None], 3, axis=2)
        self.inv = np.ascontiguousarray(1.0 - a)
        # + 0.5: the float -> uint8 conversion truncates.
        self.color_term = a * np.asarray(color, np.float32) + np.float32(0.5)

    @classmethod
    def stroke(cls, points: np.ndarray, width: float, color: tuple[int, int, int]) -> _Sprite:
        """A polyline stroked ``width`` px wide with round ends (exact distance coverage)."""
        r = 0.5 * width
        lo = np.floor(points.min(axis=0) - r - 2).astype(int)
        hi = np.ceil(points.max(axis=0) + r + 2).astype(int)
        ys, xs = np.mgrid[lo[1] : hi[1] + 1, lo[0] : hi[0] + 1].astype(np.float64)
        dist = np.full(xs.shape, np.inf)
        for p, q in zip(points[:-1], points[1:], strict=True):
            d = q - p
            t = np.clip(((xs - p[0]) * d[0] + (ys - p[1]) * d[1]) / max(d @ d, 1e-12), 0.0, 1.0)
            dist = np.minimum(dist, np.hypot(xs - p[0] - t * d[0], ys - p[1] - t * d[1]))
        return cls(int(lo[0]), int(lo[1]), r - dist + 0.5, color)

    def paint(self, frame: np.ndarray, dy: int = 0) -> None:
        h, w = self.inv.shape[:2]
        fy0, fx0 = self.y0 + dy, self.x0
        ya, yb = max(fy0, 0), min(fy0 + h, frame.shape[0])
        xa, xb = max(fx0, 0), min(fx0 + w, frame.shape[1])
        if ya >= yb or xa >= xb:
            return
        sl = (slice(ya - fy0, yb - fy0), slice(xa - fx0, xb - fx0))
        roi = frame[ya:yb, xa:xb]
        mixed = cv2.multiply(roi, self.inv[sl], dtype=cv2.CV_32F)
        cv2.add(mixed, self.color_term[sl], dst=mixed)
        roi[:] = mixed.astype(np.uint8)


def _stroke(points: np.ndarray, width: float) -> np.ndarray:
    """The outline polygon of a polyline stroked ``width`` px wide (butt ends).

    Filling this polygon is several times faster than OpenCV's thick antialiased polylines.
    """
    d = np.gradient(points, axis=0)
    n = np.column_stack([-d[:, 1], d[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-9)
    half = 0.5 * width * n
    return np.vstack([points + half, (points - half)[::-1]])


class EyeRenderer:
    """Draws a pair of eyes for a head screen of ``width`` x ``height`` pixels.

    >>> r = EyeRenderer.for_robot(DEFAULT_ROBOT)
    >>> img = r.render(eye_yaw=0.2, eye_pitch=-0.1, blink=0.0, distance=1.0)  # (600, 1024, 3) RGB
    """

    def __init__(
        self,
        width: int,
        height: int,
        style: EyeStyle | str | Path | None = None,
        *,
        yaw_range: float = math.radians(35.0),
        pitch_range: float = math.radians(25.0),
    ):
        for name, v in (("width", width), ("height", height)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 8 <= v <= 8192:
                raise ValueError(
                    f"{name} must be an integer number of pixels in 8..8192, got {v!r}"
                )
        for name, v in (("yaw_range", yaw_range), ("pitch_range", pitch_range)):
            v = _check_finite(name, v)
            if not 0.0 < v < math.pi / 2:
                raise ValueError(f"{name} must be in (0, pi/2) rad, got {v}")
        self.width = int(width)
        self.height = int(height)
        self.style = load_eye_style(style)
        self.yaw_range = float(yaw_range)
        self.pitch_range = float(pitch_range)
        self._build()

    @classmethod
    def for_robot(
        cls,
        robot: str | Path | RobotConfig = DEFAULT_ROBOT,
        *,
        width: int | None = None,
        height: int | None = None,
        style: EyeStyle | str | Path | None = None,
    ) -> EyeRenderer:
        """The renderer for a robot's head screen; ``robot`` is a name (``"sawyer"``), a robot
        YAML path or a parsed :class:`~gazebot.core.kinematics.RobotConfig`. Size, style and
        eye range come from its config; keyword arguments override."""
        info = robot_display(robot)
        return cls(
            width if width is not None else info.width,
            height if height is not None else info.height,
            style if style is not None else info.style,
            yaw_range=info.yaw_range,
            pitch_range=info.pitch_range,
        )

    @property
    def travel_px(self) -> tuple[float, float]:
        """Semi-axes ``(Ux, Uy)`` (px) of the ellipse the pupil centers stay within."""
        return (self._ux, self._uy)

    @property
    def shape(self) -> tuple[int, int, int]:
        """Shape of the rendered images: ``(height, width, 3)``."""
        return (self.height, self.width, 3)

    # -- static layers --------------------------------------------------------------------------

    def _build(self) -> None:
        s, H, W = self.style, float(self.height), self.width
        a = 0.5 * s.sclera.width * H
        b = 0.5 * s.sclera.height * H
        cy = 0.5 * (self.height - 1) + s.sclera.center_dy * H
        half = 0.5 * s.sclera.spacing * H
        xc = 0.5 * (W - 1)
        self.eyes = (
            EyeGeometry(xc - half, cy, a, b, side=-1),
            EyeGeometry(xc + half, cy, a, b, side=+1),
        )
        self._outline = s.sclera.outline_width * H
        r_out = max(s.pupil.pupil_radius, s.pupil.iris_radius) * H
        self._ux = s.pupil.travel * max(a - r_out, 0.0)
        self._uy = s.pupil.travel * max(b - r_out, 0.0)
        # Eyeball radii: the eye range maps to the edge of the travel.
        self._rx = self._ux / math.sin(self.yaw_range)
        self._ry = self._uy / math.sin(self.pitch_range)

        bg = np.empty((self.height, W, 3), np.float32)
        top = np.asarray(s.face.background, np.float32)
        bottom = np.asarray(s.face.background_bottom or s.face.background, np.float32)
        ramp = np.linspace(0.0, 1.0, self.height, dtype=np.float32)[:, None, None]
        bg[:] = top * (1.0 - ramp) + bottom * ramp
        if s.face.blush_radius > 0 and s.face.blush_opacity > 0:
            self._paint_blush(bg, H)
        pad = self._outline + 3.0
        self._layers = [
            _EyeLayer(g, pad, (self.height, W), s.sclera.exponent, s.sclera.color, self._outline)
            for g in self.eyes
        ]
        if self._outline > 0:
            color = np.asarray(s.sclera.outline_color, np.float32)
            for lay in self._layers:
                if lay.empty:
                    continue
                box = bg[lay.y0 : lay.y1, lay.x0 : lay.x1]
                axes = (lay.geom.a + self._outline, lay.geom.b + self._outline)
                alpha = superellipse_coverage(
                    box.shape[:2], (lay.ex, lay.ey), axes, s.sclera.exponent
                )[..., None]
                box[:] = box * (1.0 - alpha) + color * alpha
        self._bg = np.clip(np.rint(bg), 0, 255).astype(np.uint8)
        for lay in self._layers:
            lay.set_background(self._bg)
        self._build_brows(H)

    def _paint_blush(self, bg: np.ndarray, H: float) -> None:
        f = self.style.face
        sigma = 0.5 * f.blush_radius * H
        color = np.asarray(f.blush_color, np.float32)
        reach = 3.5 * sigma  # the Gaussian is negligible beyond
        for g in self.eyes:
            cy = g.cy + f.blush_dy * H
            cx = g.cx + 0.25 * g.side * g.a
            y0, y1 = max(int(cy - reach), 0), min(int(cy + reach) + 1, self.height)
            x0, x1 = max(int(cx - reach), 0), min(int(cx + reach) + 1, self.width)
            if y0 >= y1 or x0 >= x1:
                continue
            ys = np.arange(y0, y1, dtype=np.float32)[:, None]
            xs = np.arange(x0, x1, dtype=np.float32)[None, :]
            alpha = f.blush_opacity * np.exp(-((xs - cx) ** 2 + (ys - cy) ** 2) / (2 * sigma**2))
            box = bg[y0:y1, x0:x1]
            box[:] = box * (1.0 - alpha[..., None]) + color * alpha[..., None]

    def _build_brows(self, H: float) -> None:
        # Brows only move up and down, so each is drawn once as an exact capsule-stroke coverage
        # (far smoother than OpenCV's antialiased polygons) and shifted by whole pixels per frame.
        br = self.style.brows
        width = br.width * H
        self._brows: list[_Sprite] = []
        if width < 0.5:
            return
        t = np.linspace(-1.0, 1.0, 33)
        tilt = math.radians(br.tilt_deg)
        for g in self.eyes:
            x = t * br.length * g.a
            # Middle above the ends; the outer end (away from the nose) up for a positive tilt.
            y = -br.arc * H * (1.0 - t**2) - g.side * x * math.sin(tilt)
            base_y = g.cy - g.b - self._outline - br.gap * H - 0.5 * width
            line = np.stack([g.cx + x * math.cos(tilt), base_y + y], axis=1)
            self._brows.append(_Sprite.stroke(line, width, br.color))

    # -- per frame ------------------------------------------------------------------------------

    def pupil_offsets(
        self, eye_yaw: float, eye_pitch: float, distance: float | None = None
    ) -> tuple[tuple[float, float], tuple[float, float]]:
        """Pupil-center offsets ``((u, v) image-left eye, (u, v) image-right eye)`` in px from each
        eye's center (u right, v down), after vergence and clamping."""
        yaw = _check_finite("eye_yaw", eye_yaw)
        pitch = _check_finite("eye_pitch", eye_pitch)
        verg = self._vergence(distance)
        return tuple(self._offset(yaw - g.side * verg, pitch) for g in self.eyes)  # type: ignore[return-value]

    def _vergence(self, distance: float | None) -> float:
        if distance is None:
            return 0.0
        try:
            d = float(distance)
        except (TypeError, ValueError):
            raise ValueError(
                f"distance must be a number of metres or None, got {distance!r}"
            ) from None
        if math.isnan(d) or d <= 0.0:
            raise ValueError(f"distance must be > 0 m (or None / inf for parallel eyes), got {d}")
        if math.isinf(d):
            return 0.0
        return math.atan2(0.5 * self.style.vergence_baseline_m, d)

    def _offset(self, yaw: float, pitch: float) -> tuple[float, float]:
        yaw = min(max(yaw, -self.yaw_range), self.yaw_range)
        pitch = min(max(pitch, -self.pitch_range), self.pitch_range)
        u = self._rx * math.cos(pitch) * math.sin(yaw)
        v = self._ry * math.sin(pitch)
        if self._ux > 0 and self._uy > 0:
            n = math.hypot(u / self._ux, v / self._uy)
            if n > 1.0:
                u, v = u / n, v / n
        else:
            u = v = 0.0
        return u, v

    def render(
        self,
        eye_yaw: float,
        eye_pitch: float,
        blink: float = 0.0,
        distance: float | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """Draw the eyes looking at ``(eye_yaw, eye_pitch)`` (rad) with lids closed by ``blink``
        (0 open .. 1 closed) and converged for a target ``distance`` m away.

        Returns an ``(height, width, 3)`` uint8 RGB image (``out`` if given, filled in place).
        """
        yaw = _check_finite("eye_yaw", eye_yaw)
        pitch = _check_finite("eye_pitch", eye_pitch)
        blink = min(max(_check_finite("blink", blink), 0.0), 1.0)
        verg = self._vergence(distance)
        if out is None:
            frame = self._bg.copy()
        else:
            if out.shape != self.shape or out.dtype != np.uint8:
                raise ValueError(
                    f"out must be a {self.shape} uint8 array, got {out.shape} {out.dtype}"
                )
            frame = out
            np.copyto(frame, self._bg)
        v_mean = 0.0
        for lay in self._layers:
            # Vergence: each eye turns toward the nose (image-left eye to +yaw, right eye to -yaw).
            u, v = self._offset(yaw - lay.geom.side * verg, pitch)
            v_mean += 0.5 * v
            if not lay.empty:
                frame[lay.y0 : lay.y1, lay.x0 : lay.x1] = self._draw_eye(lay, u, v, blink)
        if self._brows:
            br = self.style.brows
            dy = int(round(br.follow * v_mean + br.blink_drop * self.height * blink))
            for sprite in self._brows:
                sprite.paint(frame, dy)
        return frame

    def lid_curves(
        self, g: EyeGeometry, ex: float, ey: float, v: float, blink: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """The upper and lower lid edges ``(25, 2)`` (x, y px) of eye ``g`` centred at
        ``(ex, ey)``, for a pupil ``v`` px below the centre and a ``blink`` (0..1).

        The upper lid follows the pupil's vertical offset; a blink brings both lids to
        ``closed_at`` (overlapping by a pixel so a closed eye has no antialiasing seam).
        """
        lids, b = self.style.lids, g.b
        y_close = ey + lids.closed_at * b
        y_up = ey - lids.upper_open * b + lids.follow * v
        y_up = min(y_up, y_close - 1.0)
        y_up += (y_close + 1.5 - y_up) * blink
        y_lo = ey + lids.lower_open * b + lids.lower_follow * v
        y_lo = max(y_lo, y_close + 1.0)
        y_lo += (y_close - 1.5 - y_lo) * blink
        curve = (lids.curve_open + (lids.curve_closed - lids.curve_open) * blink) * b
        xs = np.linspace(-g.a - self._outline - 3.0, g.a + self._outline + 3.0, 25)
        rel = (xs / g.a) ** 2
        upper = np.column_stack([ex + xs, y_up + curve * rel])
        lower = np.column_stack([ex + xs, y_lo - lids.lower_curve * b * rel])
        return upper, lower

    def _draw_eye(self, lay: _EyeLayer, u: float, v: float, blink: float) -> np.ndarray:
        """The eye's box: iris and pupil clipped to the sclera, lids clipped to the eye and
        its outline (so a lowered lid hides the outline above it)."""
        s, H = self.style, float(self.height)
        img = lay.layer
        np.copyto(img, lay.template)
        px, py = lay.ex + u, lay.ey + v
        center = (_fixed(px), _fixed(py))
        # Foreshortening: the disc narrows by the cosine of its turn on the eyeball.
        squash, angle = 1.0, 0.0
        if s.pupil.foreshorten and self._rx > 0 and self._ry > 0:
            q = (u / self._rx) ** 2 + (v / self._ry) ** 2
            squash = max(math.sqrt(max(1.0 - q, 0.0)), 0.6)
            angle = math.degrees(math.atan2(v, u)) if q > 0 else 0.0
        for radius, color in (
            (s.pupil.iris_radius * H, s.pupil.iris_color),
            (s.pupil.pupil_radius * H, s.pupil.pupil_color),
        ):
            if radius > 0.25:
                axes = (_fixed(radius * squash), _fixed(radius))
                cv2.ellipse(img, center, axes, angle, 0, 360, color, -1, cv2.LINE_AA, _SHIFT)
        r_p = s.pupil.pupil_radius * H
        for radius, (ox, oy) in (
            (s.pupil.highlight_radius * H, s.pupil.highlight_offset),
            (s.pupil.highlight2_radius * H, s.pupil.highlight2_offset),
        ):
            if radius > 0.25:
                c = (_fixed(px + ox * r_p * squash), _fixed(py + oy * r_p))
                cv2.circle(img, c, _fixed(radius), s.pupil.highlight_color, -1, cv2.LINE_AA, _SHIFT)
        if self._outline <= 0:  # the eye is the sclera: one clip for pupil and lids
            self._draw_lids(img, lay, v, blink)
            return lay.composite()
        eye = lay.composite()
        np.copyto(lay.lidded, eye)
        self._draw_lids(lay.lidded, lay, v, blink)
        return lay.clip_outer(lay.lidded, eye)

    def _draw_lids(self, img: np.ndarray, lay: _EyeLayer, v: float, blink: float) -> None:
        s, H, g = self.style, float(self.height), lay.geom
        lids = s.lids
        upper, lower = self.lid_curves(g, lay.ex, lay.ey, v, blink)
        top, bottom = -8.0, img.shape[0] + 8.0
        upper_poly = np.vstack([upper, [[upper[-1, 0], top], [upper[0, 0], top]]])
        lower_poly = np.vstack([lower, [[lower[-1, 0], bottom], [lower[0, 0], bottom]]])
        # Two calls: one call with overlapping polygons would leave the overlap unfilled.
        for poly in (lower_poly, upper_poly):
            pts = np.rint(poly * _ONE).astype(np.int32)
            cv2.fillPoly(img, [pts], lids.color, cv2.LINE_AA, _SHIFT)
        lw = lids.line_width * H
        if lw >= 0.5:
            line = np.rint(_stroke(upper, lw) * _ONE).astype(np.int32)
            cv2.fillPoly(img, [line], lids.line_color, cv2.LINE_AA, _SHIFT)


class LazyEyeRenderer:
    """A robot's :class:`EyeRenderer`, built on first use: a node that renders eye frames only
    while someone subscribes to them pays nothing otherwise."""

    def __init__(self, robot: str) -> None:
        self.robot = robot
        self._renderer: EyeRenderer | None = None

    def render(
        self, yaw: float, pitch: float, blink: float = 0.0, distance: float | None = None
    ) -> np.ndarray:
        """The eye image for ``yaw``, ``pitch`` (rad), ``blink`` (0 open .. 1 closed) and the
        vergence ``distance`` (m, ``None``: far)."""
        if self._renderer is None:
            self._renderer = EyeRenderer.for_robot(self.robot)
        return self._renderer.render(yaw, pitch, blink=blink, distance=distance)
