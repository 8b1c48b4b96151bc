"""Figures like the seed's Figure 6.3: chi-square per measure and win probabilities P_i."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import stats as sps

from gazebot.apps.study.analysis import MeasureResult


def plot_preferences(
    results: dict[str, MeasureResult], out_path: str | Path, title: str = "", alpha: float = 0.005
) -> Path:
    """Two panels: left, chi-square of each measure with the critical value at ``alpha`` (the
    seed's threshold, eq. 6.2 footnote); right, P_i of each behavior grouped by measure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if not results:
        raise ValueError("nothing to plot: no measures")
    measures = list(results)
    conditions = list(next(iter(results.values())).fit.conditions)
    fig, (ax_chi, ax_p) = plt.subplots(1, 2, figsize=(10, 4), gridspec_kw={"width_ratios": [1, 2]})
    chi = [results[m].chi2.chi2 for m in measures]
    df = results[measures[0]].chi2.df
    bars = ax_chi.bar(measures, chi, color="0.45")
    for bar, m in zip(bars, measures, strict=True):
        ax_chi.annotate(
            f"p={results[m].chi2.p_value:.2g}",
            (bar.get_x() + bar.get_width() / 2, bar.get_height()),
            ha="center",
            va="bottom",
            fontsize=8,
        )
    critical = sps.chi2.isf(alpha, df)
    ax_chi.axhline(critical, color="tab:red", ls="--", lw=1, label=f"alpha={alpha}")
    ax_chi.set_ylim(0, 1.3 * max(*chi, critical))  # room for the labels and the legend
    ax_chi.set_ylabel(f"chi-square (df={df})")
    ax_chi.legend(fontsize=8, loc="upper left")
    ax_chi.tick_params(axis="x", labelrotation=20)

    x = np.arange(len(measures))
    width = 0.8 / len(conditions)
    for c_idx, cond in enumerate(conditions):
        vals = [results[m].fit.p[c_idx] for m in measures]
        pos = x - 0.4 + width * (c_idx + 0.5)
        bars = ax_p.bar(pos, vals, width, label=cond)
        for b, v in zip(bars, vals, strict=True):
            ax_p.annotate(
                f"{v:.2f}", (b.get_x() + b.get_width() / 2, v), ha="center", va="bottom", fontsize=7
            )
    ax_p.set_xticks(x, measures)
    ax_p.set_ylabel("win probability P_i")
    ax_p.set_ylim(0, 1)
    ax_p.legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    out_path = Path(out_path)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out_path, dpi=120)
    plt.close(fig)
    return out_path
