"""pub6's figures (:mod:`.tactile_fusion`)."""
from __future__ import annotations

from pathlib import Path

from .report import mpl, save_figure


def plot_cumulative_success(t, path: Path, title: str) -> Path:
    """Trials lifted by round (cumulative, from ``t``: a :class:`~.tactile_fusion_stats.Transitions`) with the vision-only baseline and the thesis's 78 of 100
    after round 3 scaled to our trial count."""
    plt = mpl()
    n, c = t.trials, t.cumulative_success_by_round
    fig, ax = plt.subplots(figsize=(4.8, 3.6))
    ax.plot(range(len(c)), c, "o-", label="ours: lifted by round (cumulative)")
    ax.axhline(t.vision_only_success, color="0.5", ls="--", label="ours: vision only")
    ax.plot([len(c) - 1], [0.78 * n], "r*", ms=12, label="thesis: 78 of 100 after round 3 (scaled)")
    ax.set_xticks(range(len(c)))
    ax.set_xlabel("round (0 = the vision grasp)")
    ax.set_ylabel(f"trials lifted (of {n})")
    ax.set_ylim(0, n * 1.05)
    ax.legend(fontsize=7, loc="lower right")
    ax.set_title(title, fontsize=10)
    return save_figure(fig, path)
