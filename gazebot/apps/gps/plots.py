"""Figures in the manner of the seed's Figs. 5.2-5.5 (matplotlib, off-screen)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gazebot.apps.gps.evaluate import Evaluation
from gazebot.apps.gps.policy_store import TrainedPolicy
from gazebot.core.config import ConfigError


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def shell_plot(ev: Evaluation, trained: TrainedPolicy, out: Path) -> None:
    """Fig. 5.2: each test location (the tester hand's final position) coloured by its error,
    clamped to [0, 0.3] m; training targets as black squares, the gripper's start as a circle."""
    from gazebot.apps.gps.reach_scene import HandoverScene
    from gazebot.apps.gps.tester import motion_to

    plt = _pyplot()
    scene = HandoverScene(trained.cfg.scene)
    start = scene.reset(motion_to(trained.targets[0], False, trained.cfg.scene.tester)).p_r
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    p = ev.points
    sc = ax.scatter(p[:, 0], p[:, 1], p[:, 2], c=np.clip(ev.errors, 0, 0.3), cmap="viridis",
                    vmin=0, vmax=0.3, s=8)
    t = trained.targets
    ax.scatter(t[:, 0], t[:, 1], t[:, 2], marker="s", c="k", s=40)
    ax.scatter(*start, marker="o", c="k", s=60)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    trainer = "moving" if trained.moving else "static"
    tester = "moving" if ev.moving else "static"
    ax.set_title(f"{trained.controllers} local controllers, {trainer} trainer, {tester} tester")
    fig.colorbar(sc, ax=ax, label="error [m]", shrink=0.7)
    fig.savefig(out, dpi=120, bbox_inches="tight")
    plt.close(fig)


def load_results(entries: list[tuple[str, Path]]) -> list[tuple[str, dict]]:
    out = []
    for label, path in entries:
        try:
            with np.load(path) as z:
                out.append((label, {k: z[k] for k in z.files}))
        except (OSError, ValueError) as exc:
            raise ConfigError(path, "<file>", "an .npz from `gazebot gps evaluate --save`",
                              str(exc)) from exc
    return out


def distributions_plot(results: list[tuple[str, dict]], out: Path) -> None:
    """Figs. 5.3 / 5.5: per scenario, the test errors (points), their mean and one std."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(1.6 * len(results) + 2, 4.5))
    rng = np.random.default_rng(0)
    for i, (_, r) in enumerate(results):
        e = r["errors"]
        ax.scatter(i + 0.15 * rng.standard_normal(e.size), e, s=3, alpha=0.3)
        ax.errorbar(i, e.mean(), yerr=e.std(), fmt="o", color="k", capsize=5)
        ax.scatter([i - 0.35] * r["train_errors"].size, r["train_errors"], marker="s", c="k",
                   s=10)
    ax.set_xticks(range(len(results)), [label for label, _ in results], rotation=20)
    ax.set_ylabel("error [m] (mean over the last 0.5 s)")
    fig.savefig(out, dpi=120, bbox_inches="tight")
    plt.close(fig)


def mass_plot(results: list[tuple[str, dict]], out: Path) -> None:
    """Fig. 5.4: mean error and mean torque norm against end-effector mass; LABEL groups series."""
    plt = _pyplot()
    fig, (ax_e, ax_t) = plt.subplots(2, 1, sharex=True, figsize=(6, 6))
    series: dict[str, list[tuple[float, float, float]]] = {}
    for label, r in results:
        series.setdefault(label, []).append(
            (float(r["mass_kg"]), float(r["errors"].mean()), float(r["torques"].mean())))
    for label, pts in series.items():
        pts.sort()
        m = [p[0] for p in pts]
        ax_e.plot(m, [p[1] for p in pts], "o-", label=label)
        ax_t.plot(m, [p[2] for p in pts], "s--", label=label)
    for ax in (ax_e, ax_t):
        ax.axvline(2.0, color="k", lw=0.8)
        ax.set_xscale("log", base=2)
    ax_e.set_ylabel("mean error [m]")
    ax_t.set_ylabel("mean torque norm [N m]")
    ax_t.set_xlabel("end-effector mass [kg]")
    ax_e.legend()
    fig.savefig(out, dpi=120, bbox_inches="tight")
    plt.close(fig)
