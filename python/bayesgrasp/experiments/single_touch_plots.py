"""pub1's figures (:mod:`.single_touch`): the errors after one touch as box plots."""
from __future__ import annotations

from typing import Dict, Sequence

import numpy as np

from .report import mpl, save_figure


def plot_errors(results: Dict[str, list], case: str, path, objects: Sequence[str]) -> None:
    """Box plots of the errors after the touch, per object (in the order of ``objects``) and
    optimiser (and the initial errors)."""
    plt = mpl()
    fields = [("position_error", 1e3, "position error (mm)"), ("orientation_error", 180 / np.pi,
                                                                "orientation error (deg, mod symmetry)")]
    if case == "pose_and_scale":
        fields.append(("size_error", 100, "relative size error (%)"))
    if case == "orientation":
        fields = fields[1:]
    objs = [o for o in objects if any(k.object == o for res in results.values() for k, _ in res)]
    series = ["initial"] + list(results)
    fig, axes = plt.subplots(len(fields), 1, figsize=(max(8, 1.6 * len(objs)), 3.2 * len(fields)), squeeze=False)
    for ax, (field, k, label) in zip(axes[:, 0], fields):
        data, pos, colors = [], [], []
        for i, o in enumerate(objs):
            for j, s in enumerate(series):
                res = results[series[1]] if s == "initial" else results[s]
                when = "before" if s == "initial" else "after"
                v = [r["cases"][case][when][field] for key, r in res if key.object == o]
                v = [k * x for x in v if x is not None]
                data.append(v if v else [np.nan])
                pos.append(i * (len(series) + 1) + j)
                colors.append(f"C{j}")
        bp = ax.boxplot(data, positions=pos, widths=0.8, patch_artist=True, showfliers=False)
        for patch, c in zip(bp["boxes"], colors):
            patch.set_facecolor(c)
        ax.set_xticks([i * (len(series) + 1) + (len(series) - 1) / 2 for i in range(len(objs))])
        ax.set_xticklabels(objs)
        ax.set_ylabel(label)
        ax.set_yscale("symlog", linthresh=1.0)
        ax.set_ylim(bottom=0.0)
    axes[0, 0].legend([plt.Rectangle((0, 0), 1, 1, color=f"C{j}") for j in range(len(series))], series,
                      ncol=len(series), fontsize=8)
    axes[0, 0].set_title(f"pub1, case {case}: errors after one touch (initial: before it)")
    save_figure(fig, path)
