"""The category experiments' figures (:mod:`.category_grasping`)."""
from __future__ import annotations

from pathlib import Path
from typing import List, Sequence

import numpy as np

from ..planners.category import METHODS
from .report import mpl, save_figure


def plot_success(rows: List[dict], path: Path, title: str) -> Path:
    """Success per (category, task) and method, with the 95% Wilson intervals as error bars."""
    plt = mpl()
    groups = sorted({(r["category"], r["task"]) for r in rows})
    fig, ax = plt.subplots(figsize=(1.6 + 1.4 * len(groups), 3.6))
    width = 0.8 / len(METHODS)
    for j, m in enumerate(METHODS):
        ys = [next((r for r in rows if (r["category"], r["task"]) == g and r["method"] == m), None) for g in groups]
        x = np.arange(len(groups)) + (j - (len(METHODS) - 1) / 2) * width
        v = [r["success"] if r else np.nan for r in ys]
        err = np.array([[r["success"] - r["ci_low"], r["ci_high"] - r["success"]] if r else [0, 0] for r in ys]).T
        ax.bar(x, v, width, yerr=err, capsize=2, label=m)
    ax.set_xticks(np.arange(len(groups)))
    ax.set_xticklabels([f"{c}\n{t}" for c, t in groups])
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("success (lifted and task-compatible)")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, ncol=2)
    ax.grid(axis="y", alpha=0.3)
    return save_figure(fig, path)


def plot_scale_grid(rows: List[dict], densities: Sequence[str], path: Path, title: str) -> Path:
    """pub5_scales: one heat map per density of its success over the s_t x s_R grid
    (:func:`.category_stats.grid_rows`' rows), the value written in each cell."""
    plt = mpl()
    ts = sorted({r["s_t (cm)"] for r in rows})
    rs = sorted({r["s_R (deg)"] for r in rows})
    fig, axes = plt.subplots(1, len(densities), figsize=(0.6 + 2.6 * len(densities), 2.9), squeeze=False)
    for ax, m in zip(axes[0], densities):
        S = np.full((len(rs), len(ts)), np.nan)
        for r in rows:
            S[rs.index(r["s_R (deg)"]), ts.index(r["s_t (cm)"])] = r[m]
        im = ax.imshow(S, vmin=0.0, vmax=1.0, cmap="viridis", origin="lower")
        for (i, j), v in np.ndenumerate(S):
            ax.text(j, i, "-" if np.isnan(v) else f"{v:.2f}", ha="center", va="center", fontsize=8,
                    color="white" if np.isnan(v) or v < 0.6 else "black")
        ax.set_xticks(range(len(ts)))
        ax.set_xticklabels([f"{t:g}" for t in ts])
        ax.set_yticks(range(len(rs)))
        ax.set_yticklabels([f"{r:g}" for r in rs])
        ax.set_xlabel("s_t (cm)")
        if ax is axes[0][0]:
            ax.set_ylabel("s_R (deg)")
        ax.set_title(m, fontsize=9)
    fig.colorbar(im, ax=axes[0].tolist(), shrink=0.8, label="success")
    fig.suptitle(title, fontsize=10)
    return save_figure(fig, path, tight="bbox")
