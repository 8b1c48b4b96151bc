"""Eye drawing: OpenCV (``gazebot.apps.render.EyeRenderer``, what gazebot draws with everywhere)
against the same eyes drawn with pygame-ce (``benchmarks/eyes_pygame_peer.py``: same geometry,
style and precomputed static layers, per-frame drawing with SDL primitives), in one run:

* onto the head screen (a 32-bit pygame surface, what ``gazebot display`` shows): OpenCV renders
  an RGB array that is blitted onto the screen; pygame draws onto the screen directly;
* into an RGB array (the MuJoCo display texture, ``gazebot render eyes``, eye frames on the bus).

Also: live drawing against playing pre-rendered JPEG eye frames (``cv2.imread`` + resize to the
screen + BGR->RGB), the alternative of shipping rendered assets.

Ours and the peer are timed in alternating rounds (medians), so load from other processes on a
shared machine hits both alike; OpenCV runs single-threaded here for a per-core comparison.
"""

from __future__ import annotations

import os
import statistics
import tempfile
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

from benchmarks.common import Result, median_time
from gazebot.apps.render import EyeRenderer

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

N = 60  # frames per timed round
ROUNDS = 9


def _poses(n: int) -> list[tuple[float, float, float, float]]:
    rng = np.random.default_rng(0)
    yaw = rng.uniform(-0.5, 0.5, n)
    pitch = rng.uniform(-0.35, 0.35, n)
    blink = np.where(rng.random(n) < 0.2, rng.random(n), 0.0)
    dist = rng.choice([0.4, 1.0, 2.0], n)
    return [
        (float(a), float(b), float(c), float(d))
        for a, b, c, d in zip(yaw, pitch, blink, dist, strict=True)
    ]


def _paired_fps(ours: Callable[[], None], peer: Callable[[], None], n: int) -> tuple[float, float]:
    """Frames/s of ``ours`` and ``peer`` (each call = ``n`` frames), timed in alternating rounds."""
    ours(), peer()  # warm up
    t_ours, t_peer = [], []
    for _ in range(ROUNDS):
        t_ours.append(median_time(ours, repeat=1, warmup=0))
        t_peer.append(median_time(peer, repeat=1, warmup=0))
    return n / statistics.median(t_ours), n / statistics.median(t_peer)


def _cv_array(renderer: EyeRenderer, poses) -> Callable[[], None]:
    def frames() -> None:
        for yaw, pitch, blink, dist in poses:
            renderer.render(yaw, pitch, blink, dist)

    return frames


def _cv_screen(renderer: EyeRenderer, screen, poses) -> Callable[[], None]:
    import pygame

    # As gazebot display does it: render into one array that backs a surface, blit that.
    img = np.zeros(renderer.shape, np.uint8)
    frame = pygame.image.frombuffer(img, (renderer.width, renderer.height), "RGB")

    def frames() -> None:
        for yaw, pitch, blink, dist in poses:
            renderer.render(yaw, pitch, blink, dist, out=img)
            screen.blit(frame, (0, 0))

    return frames


def _pg_screen(renderer, screen, poses) -> Callable[[], None]:
    def frames() -> None:
        for yaw, pitch, blink, dist in poses:
            renderer.draw(screen, yaw, pitch, blink, dist)

    return frames


def _pg_array(renderer, poses) -> Callable[[], None]:
    def frames() -> None:
        for yaw, pitch, blink, dist in poses:
            renderer.render(yaw, pitch, blink, dist)

    return frames


def _jpeg(path: Path, width: int, height: int) -> Callable[[], None]:
    def frames() -> None:
        for _ in range(N):
            bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
            resized = cv2.resize(bgr, (width, height), interpolation=cv2.INTER_LINEAR)
            cv2.cvtColor(resized, cv2.COLOR_BGR2RGB)

    return frames


def _head_screen(poses) -> Result:
    """One ``gazebot display`` frame, headless: animator + OpenCV eyes + blit + status line +
    flip (no bus, no pacing), against the same with the eyes drawn by pygame."""
    from types import SimpleNamespace

    from benchmarks.eyes_pygame_peer import PygameEyeRenderer
    from gazebot.apps.render.head_display import EyeAnimator, HeadScreen, status_text

    screen = HeadScreen(EyeRenderer.for_robot("sawyer"))
    pg = PygameEyeRenderer.for_robot("sawyer")
    anim = EyeAnimator()
    clock = {"t": 0.0}
    states = [SimpleNamespace(yaw=y, pitch=p, blink=b, distance=d) for y, p, b, d in poses]

    def ours() -> None:
        for st in states:
            clock["t"] += 1 / 60
            pose = anim.update(clock["t"], st, 0.01)
            screen.show(pose, status_text("sawyer", "gazebot/sim/eyes", pose, 0.01))

    def peer() -> None:
        for st in states:
            clock["t"] += 1 / 60
            pose = anim.update(clock["t"], st, 0.01)
            pg.draw(screen.screen, pose.yaw, pose.pitch, pose.blink, pose.distance)
            text = screen._font.render(status_text("sawyer", "k", pose, 0.01), True, (0, 0, 0))
            screen.screen.blit(text, (8, 570))
            screen.pg.display.flip()

    try:
        o, p = _paired_fps(ours, peer, len(states))
    finally:
        screen.close()
    return Result("gazebot display frame, headless 1024x600 (sawyer): OpenCV eyes", o, p,
                  "frames/s", "the same frame with pygame-ce eyes", higher_is_better=True)


def run() -> list[Result]:
    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        return _run()
    finally:
        cv2.setNumThreads(threads)


def _run() -> list[Result]:
    import pygame

    from benchmarks.eyes_pygame_peer import PygameEyeRenderer

    poses = _poses(N)
    results = []
    for robot, style in (("sawyer", None), ("jaco2", None), ("sawyer", "cartoon")):
        cv = EyeRenderer.for_robot(robot, style=style)
        pg = PygameEyeRenderer.for_robot(robot, style=style)
        screen = pygame.Surface((cv.width, cv.height), 0, 32)
        label = f"{cv.width}x{cv.height} ({cv.style.name})"
        ours, peer = _paired_fps(_cv_screen(cv, screen, poses), _pg_screen(pg, screen, poses), N)
        results.append(Result(f"eyes onto the head screen {label}: OpenCV + blit", ours, peer,
                              "frames/s", "pygame-ce drawing onto the screen",
                              higher_is_better=True))
        ours, peer = _paired_fps(_cv_array(cv, poses), _pg_array(pg, poses), N)
        results.append(Result(f"eyes into an RGB array {label}: OpenCV", ours, peer,
                              "frames/s", "pygame-ce drawing + tobytes",
                              higher_is_better=True))
    results.append(_head_screen(poses))
    with tempfile.TemporaryDirectory() as tmp:
        hd = Path(tmp) / "eyes_1280x720.jpg"
        img = EyeRenderer(1280, 720, "sawyer").render(0.2, 0.1)
        cv2.imwrite(str(hd), img[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, 90])
        r = EyeRenderer.for_robot("sawyer")
        ours, peer = _paired_fps(_cv_array(r, poses), _jpeg(hd, r.width, r.height), N)
        results.append(Result("live eyes 1024x600 (sawyer)", ours, peer, "frames/s",
                              "pre-rendered JPEG 1280x720: imread + resize",
                              higher_is_better=True))
    return results
