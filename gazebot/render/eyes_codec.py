"""Carrying eyes to a real head screen: encoded frames (JPEG/PNG bytes) or the eye state as JSON.

The drivers publish either (over Zenoh); a screen-side process decodes the frame, or renders the
state itself with :class:`gazebot.render.EyeRenderer` (a few hundred bytes instead of ~50 kB).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass

import cv2
import numpy as np

_FORMATS = {"jpeg": ".jpg", "jpg": ".jpg", "png": ".png"}


def encode_frame(img: np.ndarray, fmt: str = "jpeg", quality: int = 90) -> bytes:
    """Encode an RGB (H, W, 3) or gray (H, W) uint8 image as JPEG or PNG bytes.

    ``quality`` is the JPEG quality (1..100); for PNG it maps to the zlib level
    (100 -> 0 = fastest/largest, 1 -> 9 = smallest).
    """
    ext = _FORMATS.get(str(fmt).lower())
    if ext is None:
        raise ValueError(f"fmt must be 'jpeg' or 'png', got {fmt!r}")
    if (
        isinstance(quality, bool)
        or not isinstance(quality, (int, np.integer))
        or not 1 <= quality <= 100
    ):
        raise ValueError(f"quality must be an integer in 1..100, got {quality!r}")
    if not isinstance(img, np.ndarray) or img.dtype != np.uint8:
        raise ValueError("img must be a uint8 numpy array")
    if img.ndim == 3 and img.shape[2] == 3:
        bgr = cv2.cvtColor(img, cv2.COLOR_RGB2BGR)
    elif img.ndim == 2:
        bgr = img
    else:
        raise ValueError(f"img must be (H, W, 3) RGB or (H, W) gray, got shape {img.shape}")
    if ext == ".jpg":
        params = [cv2.IMWRITE_JPEG_QUALITY, int(quality)]
    else:
        params = [cv2.IMWRITE_PNG_COMPRESSION, int(round(9 * (100 - quality) / 99))]
    ok, buf = cv2.imencode(ext, bgr, params)
    if not ok:  # pragma: no cover - OpenCV only fails on impossible inputs
        raise ValueError(f"could not encode the image as {fmt}")
    return buf.tobytes()


def decode_frame(data: bytes) -> np.ndarray:
    """Decode JPEG/PNG bytes into an (H, W, 3) uint8 RGB image."""
    arr = np.frombuffer(bytes(data), np.uint8)
    bgr = cv2.imdecode(arr, cv2.IMREAD_COLOR) if arr.size else None
    if bgr is None:
        raise ValueError("data is not a JPEG or PNG image")
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)


@dataclass(frozen=True)
class EyeState:
    """What the eyes show at time ``t``: angles in rad (gaze-frame convention), blink 0..1,
    target distance in m (``None`` = far, no vergence)."""

    t: float
    eye_yaw: float
    eye_pitch: float
    blink: float = 0.0
    distance: float | None = None
    robot: str = ""

    def __post_init__(self) -> None:
        for name in ("t", "eye_yaw", "eye_pitch", "blink"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ValueError(f"EyeState.{name} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise ValueError(f"EyeState.{name} must be finite, got {value}")
        if not 0.0 <= self.blink <= 1.0:
            raise ValueError(f"EyeState.blink must be in 0..1, got {self.blink}")
        if self.distance is not None:
            d = self.distance
            if isinstance(d, bool) or not isinstance(d, (int, float)) or math.isnan(d) or d <= 0:
                raise ValueError(f"EyeState.distance must be > 0 m or None, got {d!r}")
        if not isinstance(self.robot, str):
            raise ValueError(f"EyeState.robot must be a string, got {self.robot!r}")

    def to_dict(self) -> dict:
        d = asdict(self)
        if d["distance"] is not None and math.isinf(d["distance"]):
            d["distance"] = None  # JSON has no infinity; None means the same (parallel eyes)
        return d

    def to_json(self) -> str:
        """One-line JSON: ``{"t": .., "eye_yaw": .., "eye_pitch": .., "blink": .., ...}``."""
        return json.dumps(self.to_dict(), allow_nan=False, separators=(",", ":"))

    @classmethod
    def from_json(cls, text: str | bytes) -> EyeState:
        """Parse :meth:`to_json` output; raises ``ValueError`` on malformed input."""
        try:
            data = json.loads(text)
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise ValueError(f"EyeState JSON is malformed: {exc}") from None
        if not isinstance(data, dict):
            raise ValueError("EyeState JSON must be an object")
        known = {"t", "eye_yaw", "eye_pitch", "blink", "distance", "robot"}
        unknown = set(data) - known
        if unknown:
            raise ValueError(f"EyeState JSON has unknown fields: {sorted(unknown)}")
        missing = {"t", "eye_yaw", "eye_pitch"} - set(data)
        if missing:
            raise ValueError(f"EyeState JSON lacks fields: {sorted(missing)}")
        return cls(**data)
