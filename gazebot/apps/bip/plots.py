"""Figures like the seed's Fig. 7.9 (the training distributions: mean and one standard deviation
of each degree of freedom over the phase) and Fig. 7.10 (the giver's wrist distance: the training
mean, the observed test samples, and the predictions)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from gazebot.apps.bip.demos import DOF_NAMES, Demonstration
from gazebot.apps.bip.evaluate import Prediction
from gazebot.apps.bip.prior import PHASE_GRID, BipPrior

MODE_STYLES = {"none": ("red", ":"), "projection": ("purple", "-"), "filter": ("darkorange", "--")}


def bip_figure(
    prior: BipPrior,
    test: Demonstration,
    predictions: Mapping[str, Prediction],
    path: str | Path,
) -> Path:
    """Save the training distributions and the wrist-distance plot of one test (PNG)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = plt.figure(figsize=(14, 8))
    grid = fig.add_gridspec(4, 6)
    mean, sd = prior.curves.mean(axis=0), prior.curves.std(axis=0)
    for d, name in enumerate(DOF_NAMES):
        ax = fig.add_subplot(grid[d // 4, d % 4])
        ax.fill_between(PHASE_GRID, mean[:, d] - sd[:, d], mean[:, d] + sd[:, d],
                        color="tab:blue", alpha=0.3, lw=0)
        ax.plot(PHASE_GRID, mean[:, d], color="black", lw=1.2)
        ax.set_title(name, fontsize=8)
        ax.tick_params(labelsize=6)
    fig.text(0.02, 0.98, "Training distributions (mean, 1 sd) over the phase, m "
             "(like seed Fig. 7.9)", fontsize=9, va="top")

    ax = fig.add_subplot(grid[:, 4:])
    train_dist = prior.mean_giver_distance()
    ax.plot(PHASE_GRID * test.duration, train_dist, color="green", lw=2,
            label="training mean distance")
    true_dist = test.giver_distance()
    first = next(iter(predictions.values()))
    n_obs = int(np.searchsorted(test.t, first.observed_until, side="right"))
    ax.plot(test.t[:n_obs], true_dist[:n_obs], color="blue", lw=3,
            label=f"observed ({n_obs} samples)")
    ax.plot(test.t[n_obs:], true_dist[n_obs:], color="blue", lw=1, alpha=0.4,
            label="test (not observed)")
    for mode, pred in predictions.items():
        color, ls = MODE_STYLES.get(mode, ("gray", "-"))
        ax.plot(pred.t, pred.distance, color=color, ls=ls, lw=2,
                label=f"prediction, constraint {mode}")
    ax.axhline(test.width, color="black", lw=0.8, ls="-.", label=f"grip width {test.width:.3f} m")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("distance between the giver's wrists (m)")
    ax.set_title("Giver's wrist distance (like seed Fig. 7.10)", fontsize=10)
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


