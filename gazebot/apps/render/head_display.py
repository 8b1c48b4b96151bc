"""The robot's head screen: the eyes drawn locally from the engine's eye state, kept alive between
updates, neutral when the engine goes silent.

:class:`EyeAnimator` decides what the eyes show at each screen refresh (pure, clock passed in):

* **live** (an eye state younger than ``silent_after``): the engine's yaw, pitch, blink and
  vergence distance, plus small fixational motion (a slow random drift of ``drift_deg``, as
  human eyes never hold perfectly still between gaze shifts);
* **silent** (the last eye state is older than ``silent_after``) or **waiting** (none yet):
  the eyes ease to the neutral state (straight ahead, parallel, open) over ``neutral_s`` and
  blink on their own (:class:`~gazebot.core.runtime.blink.BlinkModel` at the human rate), with the
  same drift; when eye states return, the eyes follow the engine again.

:class:`HeadScreen` draws the chosen pose with :class:`~gazebot.apps.render.eyes.EyeRenderer` (the
one eye drawing, also used for the simulator's display texture and ``gazebot render eyes``) onto a
pygame-ce window (or SDL's dummy/offscreen driver, headless), with a status line.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from gazebot.apps.render.eyes import EyeRenderer
from gazebot.core.runtime.blink import BlinkModel


@dataclass(frozen=True)
class EyeAnimatorConfig:
    """Timing (s) and motion (deg at this surface, rad inside) of the head screen's eyes."""

    silent_after: float = 0.5
    neutral_s: float = 0.4
    drift_deg: float = 0.4
    drift_tau: float = 0.6

    def __post_init__(self) -> None:
        for name in ("silent_after", "neutral_s", "drift_tau"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"EyeAnimatorConfig.{name} must be > 0, got {v!r}")
        if not (math.isfinite(self.drift_deg) and 0 <= self.drift_deg <= 5):
            raise ValueError(f"EyeAnimatorConfig.drift_deg must be in 0..5, got {self.drift_deg}")


@dataclass(frozen=True)
class EyePose:
    """What the screen shows: eye yaw and pitch (rad), blink (0..1), distance (m or None) and
    the link state (``live``, ``silent``, ``waiting``)."""

    yaw: float
    pitch: float
    blink: float
    distance: float | None
    state: str


def _smoothstep(x: float) -> float:
    x = min(max(x, 0.0), 1.0)
    return x * x * (3.0 - 2.0 * x)


class EyeAnimator:
    """``update(now, state, age) -> EyePose``; deterministic for a seed and the same calls.

    ``state`` is the newest eye state (anything with ``yaw``, ``pitch``, ``blink``, ``distance``)
    or ``None``; ``age`` how long ago (s) it arrived; ``now`` the screen's clock (s, never going
    back). """

    def __init__(self, config: EyeAnimatorConfig | None = None, seed: int = 0) -> None:
        self.config = config or EyeAnimatorConfig()
        self._rng = np.random.default_rng(seed)
        self.blinks = BlinkModel(seed)
        self._drift = np.zeros(2)
        self._t: float | None = None
        self._silent_since: float | None = None
        self._from = (0.0, 0.0)  # the pose the eyes ease to neutral from

    def _advance_drift(self, now: float) -> None:
        dt = 0.0 if self._t is None else max(now - self._t, 0.0)
        self._t = now
        if dt <= 0.0:
            return
        c = self.config
        # Ornstein-Uhlenbeck: exact discretisation, stationary spread = drift_deg.
        a = math.exp(-dt / c.drift_tau)
        sigma = math.radians(c.drift_deg) * math.sqrt(1.0 - a * a)
        self._drift = a * self._drift + sigma * self._rng.standard_normal(2)

    def update(self, now: float, state: Any | None, age: float) -> EyePose:
        self._advance_drift(now)
        dy, dp = float(self._drift[0]), float(self._drift[1])
        live = state is not None and age < self.config.silent_after
        if live:
            self._silent_since = None
            self._from = (float(state.yaw), float(state.pitch))
            # The engine's blink stream stands; the own blink line restarts when it goes silent.
            self.blinks.reset()
            return EyePose(float(state.yaw) + dy, float(state.pitch) + dp,
                           min(max(float(state.blink), 0.0), 1.0), state.distance, "live")
        if self._silent_since is None:
            self._silent_since = now
        s = 1.0 - _smoothstep((now - self._silent_since) / self.config.neutral_s)
        blink = self.blinks.update(now)
        return EyePose(self._from[0] * s + dy, self._from[1] * s + dp, blink, None,
                       "waiting" if state is None else "silent")


def status_text(robot: str, key: str, pose: EyePose, age: float) -> str:
    """The status line: which robot, which key, and the link state (silence said plainly)."""
    if pose.state == "live":
        return f"{robot} | {key} | engine live"
    if pose.state == "waiting":
        return f"{robot} | {key} | waiting for the engine: neutral eyes"
    return f"{robot} | {key} | engine silent for {age:.1f} s: neutral eyes"


class HeadScreen:
    """A pygame-ce screen showing the eyes and a status line.

    Args:
        renderer: The robot's eye renderer (its size is the screen's).
        fullscreen: Fill the monitor (the image is centred, unscaled).
        caption: Window title.
        status_bar: Draw the status line at the bottom.
    """

    def __init__(
        self,
        renderer: EyeRenderer,
        fullscreen: bool = False,
        caption: str = "gazebot display",
        status_bar: bool = True,
    ) -> None:
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        import pygame

        self.pg = pygame
        self.renderer = renderer
        self.size = (renderer.width, renderer.height)
        pygame.display.init()
        pygame.font.init()
        flags = pygame.FULLSCREEN if fullscreen else 0
        try:
            self.screen = pygame.display.set_mode((0, 0) if fullscreen else self.size, flags)
        except pygame.error as exc:
            pygame.display.quit()
            raise OSError(f"cannot open the head screen ({exc}); for no screen set "
                          "SDL_VIDEODRIVER=dummy") from exc
        pygame.display.set_caption(caption)
        pygame.mouse.set_visible(not fullscreen)
        sw, sh = self.screen.get_size()
        self.offset = ((sw - self.size[0]) // 2, (sh - self.size[1]) // 2)
        # The eyes are rendered into one array that backs a surface: no per-frame allocation.
        self._img = np.zeros(renderer.shape, np.uint8)
        self._frame = pygame.image.frombuffer(self._img, self.size, "RGB")
        self._font = pygame.font.Font(None, max(14, renderer.height // 30)) if status_bar else None

    def show(self, pose: EyePose, status: str) -> None:
        """Draw ``pose`` and the ``status`` line and flip the screen."""
        self.renderer.render(pose.yaw, pose.pitch, pose.blink, pose.distance, out=self._img)
        self.screen.blit(self._frame, self.offset)
        if self._font is not None:
            color = (150, 200, 150) if pose.state == "live" else (230, 170, 90)
            text = self._font.render(status, True, color)
            x = self.offset[0] + 8
            y = self.offset[1] + self.size[1] - text.get_height() - 6
            self.screen.blit(text, (x, y))
        self.pg.display.flip()

    def image(self) -> np.ndarray:
        """What the eye area of the screen shows now, as an ``(height, width, 3)`` RGB array."""
        area = self.screen.subsurface((*self.offset, *self.size))
        raw = self.pg.image.tobytes(area, "RGB")
        return np.frombuffer(raw, np.uint8).reshape(self.size[1], self.size[0], 3)

    def closed(self) -> bool:
        """Whether the user closed the window (or pressed Esc / q)."""
        pg = self.pg
        for event in pg.event.get():
            if event.type == pg.QUIT:
                return True
            if event.type == pg.KEYDOWN and event.key in (pg.K_ESCAPE, pg.K_q):
                return True
        return False

    def close(self) -> None:
        self.pg.display.quit()
