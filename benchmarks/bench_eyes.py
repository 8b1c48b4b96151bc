"""Eye frames per second: drawing live (``EyeRenderer``) against playing pre-rendered JPEG frames
(``cv2.imread`` of an eye frame + ``cv2.resize`` to the display + BGR->RGB), measured in one run.

The JPEGs are written to a temporary folder at benchmark time: an HD 1280x720 eye frame (the kind
of asset a pre-rendered player ships, resized down to the screen) and, as the hardest peer, a frame
already at the screen's size. Both sides produce the same RGB display image. Also timed: encoding
a frame for a real head screen (JPEG against PNG).

Ours and the peer are timed in alternating rounds (medians), so load from other processes on a
shared machine hits both alike; OpenCV runs single-threaded here for a per-core comparison.
"""

from __future__ import annotations

import math
import statistics
import tempfile
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

from benchmarks.common import Result, median_time
from gazebot.render import BlinkModel, EyeRenderer, encode_frame

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


def _live(renderer: EyeRenderer, poses) -> Callable[[], None]:
    def frames() -> None:
        for yaw, pitch, blink, dist in poses:
            renderer.render(yaw, pitch, blink, dist)

    return frames


def _pipeline(renderer: EyeRenderer, poses) -> Callable[[], None]:
    """Blink model + render, as the simulation/driver loop runs it at 60 Hz."""
    model = BlinkModel(seed=0)
    state = {"t": 0.0, "prev": (0.0, 0.0)}

    def frames() -> None:
        for yaw, pitch, _, dist in poses:
            state["t"] += 1.0 / 60.0
            shift = math.hypot(yaw - state["prev"][0], pitch - state["prev"][1])
            state["prev"] = (yaw, pitch)
            renderer.render(yaw, pitch, model.update(state["t"], shift), dist)

    return frames


def _jpeg(path: Path, width: int, height: int) -> Callable[[], None]:
    def frames() -> None:
        for _ in range(N):
            bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
            resized = cv2.resize(bgr, (width, height), interpolation=cv2.INTER_LINEAR)
            cv2.cvtColor(resized, cv2.COLOR_BGR2RGB)

    return frames


def _encode(frame: np.ndarray, fmt: str, quality: int, n: int) -> Callable[[], None]:
    def frames() -> None:
        for _ in range(n):
            encode_frame(frame, fmt, quality)

    return frames


def run() -> list[Result]:
    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        return _run()
    finally:
        cv2.setNumThreads(threads)


def _run() -> list[Result]:
    poses = _poses(N)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        hd = Path(tmp) / "eyes_1280x720.jpg"
        img = EyeRenderer(1280, 720, "sawyer").render(0.2, 0.1)
        cv2.imwrite(str(hd), img[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, 90])
        native = Path(tmp) / "eyes_1024x600.jpg"
        frame = EyeRenderer.for_robot("sawyer").render(0.2, 0.1)
        cv2.imwrite(str(native), frame[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, 90])
        hd_name = "pre-rendered JPEG 1280x720: imread + resize"
        for robot, style in (("sawyer", None), ("jaco2", None), ("sawyer", "cartoon")):
            r = EyeRenderer.for_robot(robot, style=style)
            ours, peer = _paired_fps(_live(r, poses), _jpeg(hd, r.width, r.height), N)
            name = f"live eyes {r.width}x{r.height} ({r.style.name})"
            results.append(Result(name, ours, peer, "frames/s", hd_name, higher_is_better=True))
        r = EyeRenderer.for_robot("sawyer")
        ours, peer = _paired_fps(_live(r, poses), _jpeg(native, r.width, r.height), N)
        results.append(
            Result(
                "live eyes 1024x600 (sawyer) vs a screen-size JPEG",
                ours,
                peer,
                "frames/s",
                "pre-rendered JPEG 1024x600: imread + resize (same size)",
                higher_is_better=True,
            )
        )
        ours, peer = _paired_fps(_pipeline(r, poses), _jpeg(hd, r.width, r.height), N)
        results.append(
            Result(
                "blink model + live eyes 1024x600 (sawyer)",
                ours,
                peer,
                "frames/s",
                hd_name,
                higher_is_better=True,
            )
        )
    n = 10
    ours, peer = _paired_fps(_encode(frame, "jpeg", 85, n), _encode(frame, "png", 90, n), n)
    results.append(
        Result(
            "encode_frame JPEG q85 1024x600 (to a real head screen)",
            ours,
            peer,
            "frames/s",
            "encode_frame PNG (zlib level 1)",
            higher_is_better=True,
            note=f"{len(encode_frame(frame, 'jpeg', 85)) / 1024:.0f} kB per JPEG frame",
        )
    )
    return results
