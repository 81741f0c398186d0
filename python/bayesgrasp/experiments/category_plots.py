"""The category experiments' figures (:mod:`.category_grasping`)."""
from __future__ import annotations

from pathlib import Path
from typing import List

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
