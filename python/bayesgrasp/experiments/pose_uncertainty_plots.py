"""The pose-uncertainty experiments' figures (:mod:`.pose_uncertainty`): success per attempt, the
belief's evolution (Figs. 3.3 / 3.5), expected-entropy landscapes (Fig. 3.6), weight vs kernel
entropy, the 1-DOF sample-count comparison."""
from __future__ import annotations

from pathlib import Path
from typing import Dict, List, Optional

import numpy as np

from .pose_uncertainty_stats import ATTEMPTS
from .report import mpl, save_figure


def plot_per_attempt(tables: Dict[str, List[dict]], path: Path, title: str) -> Path:
    """Success, predicted stability, epsilon, pose error and entropy vs attempt, one line per
    method (averaged over objects) or per object when there is one method."""
    plt = mpl()
    fields = [("success", "success by attempt (dashed: epsilon-stable)"), ("predicted_stability", "predicted P(S)"),
              ("epsilon", "epsilon"), ("position_error_cm", "posterior mean error (cm)"),
              ("entropy", "belief entropy (KDE, nats)")]
    fig, axes = plt.subplots(1, len(fields), figsize=(4.0 * len(fields), 3.4))
    lines = {}
    if len(tables) == 1:
        rows = next(iter(tables.values()))
        for obj in sorted({r["object"] for r in rows}):
            lines[obj] = [r for r in rows if r["object"] == obj]
    else:
        for method, rows in tables.items():
            lines[method] = [r for r in rows if r["object"] == "mean"]
    for ax, (f, label) in zip(axes, fields):
        for name, rs in lines.items():
            (ln,) = ax.plot([r["attempt"] for r in rs], [r[f] for r in rs], marker="o", label=name,
                            lw=2.5 if name == "mean" else 1.5)
            if f == "success":  # dashed: the thesis's simulation criterion, epsilon > eps_stable
                ax.plot([r["attempt"] for r in rs], [r["stable"] for r in rs], ls="--", marker=".",
                        color=ln.get_color(), lw=1.0)
        ax.set_xlabel("attempt")
        ax.set_title(label, fontsize=10)
        ax.set_xticks(range(1, ATTEMPTS + 1))
        ax.grid(alpha=0.3)
    axes[0].set_ylim(0, 1.02)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    return save_figure(fig, path)


def plot_belief_evolution(snapshots, true_pose, path: Path, title: str = "", attempts: Optional[list] = None) -> Path:
    """Particles (x, y; marker size = weight) before each attempt and at the end - thesis Figs. 3.3
    and 3.5. Colour: each particle's yaw error against the true yaw, wrapped to +-180 deg, on a
    diverging map centred at 0 (white = right yaw), scaled to the initial belief's spread. Legend:
    the true pose (red cross), its heading (red arrow) and the executed grasp (black triangle);
    each panel says whether its grasp lifted the object."""
    plt = mpl()
    from matplotlib.lines import Line2D

    n = len(snapshots)
    fig, axes = plt.subplots(1, n, figsize=(3.3 * n, 3.9), squeeze=False)
    t = np.asarray(true_pose, dtype=float)
    P0 = snapshots[0][0]
    lo = P0[:, :2].min(axis=0) - 0.01
    hi = P0[:, :2].max(axis=0) + 0.01
    wrap = lambda a: np.degrees((a - t[2] + np.pi) % (2 * np.pi) - np.pi)  # noqa: E731
    span = max(5.0, float(np.ceil(np.abs(wrap(P0[:, 2])).max() / 5) * 5))
    for i, (ax, (P, w)) in enumerate(zip(axes[0], snapshots)):
        sc = ax.scatter(100 * P[:, 0], 100 * P[:, 1], c=wrap(P[:, 2]), s=4 + 400 * w, cmap="coolwarm",
                        vmin=-span, vmax=span, alpha=0.8, edgecolors="0.4", linewidths=0.2)
        ax.plot(100 * t[0], 100 * t[1], "r+", ms=16, mew=2.5)
        ax.arrow(100 * t[0], 100 * t[1], 2 * np.cos(t[2]), 2 * np.sin(t[2]), color="r", width=0.08)
        label = "final" if i == n - 1 else f"before attempt {i + 1}"
        if attempts is not None and i < len(attempts):
            a = attempts[i]
            ax.plot(100 * a["action"][0], 100 * a["action"][1], "k^", ms=8)
            verdict = {True: "lifted", False: "FAILED (not lifted)"}.get(a.get("lifted"), "lift not tested")
            label += f"\n{a['kind']}: P(S) {a['predicted_stability']:.2f}, eps {a['epsilon']:.3f}\n{verdict}"
        ax.set_title(label, fontsize=9)
        ax.set_xlim(100 * lo[0], 100 * hi[0])
        ax.set_ylim(100 * lo[1], 100 * hi[1])
        ax.set_aspect("equal")
        ax.set_xlabel("x (cm)")
    axes[0][0].set_ylabel("y (cm)")
    fig.colorbar(sc, ax=axes[0].tolist(), label="particle yaw - true yaw (deg)", shrink=0.8)
    handles = [Line2D([], [], ls="", marker="+", color="r", ms=12, mew=2.5, label="true pose"),
               Line2D([], [], color="r", lw=2, label="true heading"),
               Line2D([], [], ls="", marker="o", color="0.6", ms=6, label="particle (size = weight)")]
    if attempts:
        handles.append(Line2D([], [], ls="", marker="^", color="k", ms=8, label="executed grasp"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False,
               bbox_to_anchor=(0.45, -0.04))
    if title:
        fig.suptitle(title, fontsize=10)
    return save_figure(fig, path, tight="bbox")


def plot_landscape(r: dict, path: Path, title: str) -> Path:
    """Fig. 3.6: the predicted expected-entropy landscape over grasp positions with the best,
    good and worst grasps marked."""
    plt = mpl()
    g = r["grid"]
    C = np.asarray(r["candidates"]).reshape(g, g, 3)
    H = np.asarray(r["landscape"]).reshape(g, g)
    P = np.asarray(r["particles"])
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    im = ax.contourf(100 * C[:, :, 0], 100 * C[:, :, 1], H, levels=20, cmap="viridis")
    fig.colorbar(im, ax=ax, label="expected posterior entropy (weight-based)")
    ax.scatter(100 * P[:, 0], 100 * P[:, 1], s=1, c="w", alpha=0.3)
    marks = {"best": ("o", "red"), "good": ("^", "lime"), "worst": ("v", "magenta")}
    for k, (m, c) in marks.items():
        a = r["actions"][k]
        ax.plot(100 * a[0], 100 * a[1], m, color=c, ms=11, mec="k",
                label=f"{k}: predicted {r['predicted'][k]:.2f}, realised {r['realised'][k]:.2f}")
    t = r["true_pose"]
    ax.plot(100 * t[0], 100 * t[1], "r+", ms=14, mew=2)
    ax.set_xlabel("grasp x (cm)")
    ax.set_ylabel("grasp y (cm)")
    ax.legend(fontsize=7, loc="lower left")
    ax.set_title(title, fontsize=10)
    return save_figure(fig, path)


def plot_weight_vs_kernel(r: dict, path: Path, title: str) -> Path:
    plt = mpl()
    g = r["grid"]
    C = np.asarray(r["actions"]).reshape(g, g, 3)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, key in zip(axes, ("weight", "kernel")):
        H = np.asarray(r[key]).reshape(g, g)
        im = ax.contourf(100 * C[:, :, 0], 100 * C[:, :, 1], H, levels=20, cmap="viridis")
        fig.colorbar(im, ax=ax)
        ax.set_title(f"{key}-based expected entropy", fontsize=10)
        ax.set_xlabel("grasp x (cm)")
        ax.set_ylabel("grasp y (cm)")
    fig.suptitle(f"{title}: Pearson {r['pearson']:.2f}, Spearman {r['spearman']:.2f}", fontsize=10)
    return save_figure(fig, path)


def plot_one_dof(r: dict, path: Path) -> Path:
    plt = mpl()
    d = r["one_dof"]
    fig, ax = plt.subplots(figsize=(6, 3.6))
    x = 100 * np.asarray(d["x"])
    ax.plot(x, d["h1000"], label=f"1,000 samples (roughness {d['roughness_1000']:.4f})")
    ax.plot(x, d["h10000"], label=f"10,000 samples (roughness {d['roughness_10000']:.4f})")
    ax.axvline(100 * r["true_pose"][0], color="r", ls=":", label="true x")
    ax.set_xlabel("grasp x (cm)")
    ax.set_ylabel("expected posterior entropy")
    ax.set_title("cube, uncertainty in x only", fontsize=10)
    ax.legend(fontsize=8)
    return save_figure(fig, path)
