"""The learned reach as a video: one trial of a trained global policy against the tester, rendered
off-screen (the one entry point a demo command or a controller registry calls)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gazebot.apps.gps.badmm import policy_act
from gazebot.apps.gps.policy_store import load
from gazebot.apps.gps.reach_scene import HandoverScene
from gazebot.apps.gps.shell import shell_grid
from gazebot.apps.gps.state import state_vector
from gazebot.apps.gps.tester import motion_to
from gazebot.apps.render.video_settings import VIDEO


@dataclass(frozen=True)
class DemoResult:
    video: Path
    frames: int
    target_m: tuple[float, float, float]
    error_m: float  # the seed's error: mean gripper-to-hand distance over the last 0.5 s


def run_demo(policy_dir: str | Path, out: str | Path, moving: bool = True,
             target: np.ndarray | None = None, width: int = VIDEO.width,
             height: int = VIDEO.height) -> DemoResult:
    """Render the policy in ``policy_dir`` reaching for the tester's hand (default target: the
    middle of the test shell) to the MP4 file ``out``."""
    import imageio.v2 as imageio

    from gazebot.apps.render.offscreen import OffscreenRenderer

    trained = load(policy_dir)
    cfg = trained.cfg
    if target is None:
        grid = shell_grid(cfg.shell, 3)
        target = grid[len(grid) // 2]
    scene = HandoverScene(cfg.scene)
    act = policy_act(trained.policy)
    motion = motion_to(np.asarray(target, dtype=float), moving, cfg.scene.tester)
    renderer = OffscreenRenderer(scene.model, width, height)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    obs = scene.reset(motion)
    gaps = [np.linalg.norm(obs.p_r - obs.p_h)]
    fps = int(round(1.0 / cfg.scene.control_dt_s))
    try:
        with imageio.get_writer(out, fps=fps, macro_block_size=1) as writer:
            writer.append_data(renderer.render(scene.data, "side"))
            for t in range(cfg.scene.horizon):
                obs = scene.step(act(t, state_vector(obs, trained.kind)))
                gaps.append(np.linalg.norm(obs.p_r - obs.p_h))
                writer.append_data(renderer.render(scene.data, "side"))
    finally:
        renderer.close()
    last = np.arange(len(gaps)) * cfg.scene.control_dt_s >= cfg.scene.trial_s - 0.5 - 1e-9
    return DemoResult(out, len(gaps), tuple(float(v) for v in target),
                      float(np.mean(np.array(gaps)[last])))
