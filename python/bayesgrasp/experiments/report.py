"""Tables (Markdown + CSV + JSON) and plots of the pose-uncertainty experiments."""
from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Dict, List, Optional, Sequence

import numpy as np

ATTEMPTS = 4


def _mpl():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


# ---- episodes ---------------------------------------------------------------------------------------
def episode_table(results: list, attempts: int = ATTEMPTS) -> List[dict]:
    """Per object and attempt k: cumulative success (by the run's criterion) by attempt k, and
    beside it lifted, stable (epsilon) and force closure by k; means over the runs that made
    attempt k of predicted stability, epsilon, plan time; pose error and KDE entropy of the belief
    after attempt k (carried forward once a run stopped)."""
    by_obj: Dict[str, list] = {}
    for key, r in results:
        by_obj.setdefault(key.object, []).append(r)
    rows = []
    for obj in sorted(by_obj):
        runs = by_obj[obj]
        for k in range(1, attempts + 1):
            made = [r["attempts"][k - 1] for r in runs if len(r["attempts"]) >= k]

            def after(r):
                a = r["attempts"][min(k, len(r["attempts"])) - 1]
                return a.get("belief_after", r["final_belief"])

            rows.append({
                "object": obj, "attempt": k, "runs": len(runs), "made": len(made),
                "success": float(np.mean([any(_success(a) for a in r["attempts"][:k]) for r in runs])),
                "lifted": float(np.mean([any(bool(a["lifted"]) for a in r["attempts"][:k]) for r in runs])),
                "stable": float(np.mean([any(a["stable"] for a in r["attempts"][:k]) for r in runs])),
                "force_closure": float(np.mean([any(a["force_closure"] for a in r["attempts"][:k]) for r in runs])),
                "success_at_attempt": float(np.mean([_success(a) for a in made])) if made else float("nan"),
                "explore_fraction": float(np.mean([a["kind"] == "explore" for a in made])) if made else float("nan"),
                "side_fraction": float(np.mean([a.get("family", "top") == "side" for a in made])) if made else float("nan"),
                "predicted_stability": float(np.mean([a["predicted_stability"] for a in made])) if made else float("nan"),
                "epsilon": float(np.mean([a["epsilon"] for a in made])) if made else float("nan"),
                "position_error_cm": 100 * float(np.mean([after(r)["position_error"] for r in runs])),
                "yaw_error_deg": float(np.degrees(np.mean([after(r)["yaw_error"] for r in runs]))),
                "entropy": float(np.mean([after(r)["kde_entropy"] for r in runs])),
                "plan_ms_median": 1e3 * float(np.median([a["plan_seconds"] for a in made])) if made else float("nan"),
            })
    return rows


def _success(attempt: dict) -> bool:
    """An attempt's success by its run's criterion (rows stored before the criterion was recorded
    per attempt used epsilon)."""
    return bool(attempt.get("success", attempt["stable"]))


def _average(rows: List[dict], attempts: int = ATTEMPTS) -> List[dict]:
    out = []
    for k in range(1, attempts + 1):
        rk = [r for r in rows if r["attempt"] == k]
        avg = {"object": "mean", "attempt": k, "runs": int(sum(r["runs"] for r in rk)),
               "made": int(sum(r["made"] for r in rk))}
        for f in rk[0]:
            if f not in avg:
                avg[f] = float(np.nanmean([r[f] for r in rk]))
        out.append(avg)
    return out


def _markdown(rows: List[dict], cols: Sequence[str]) -> str:
    def fmt(v):
        if isinstance(v, float):
            return "–" if np.isnan(v) else f"{v:.3f}"
        return str(v)

    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(fmt(r[c]) for c in cols) + " |" for r in rows]
    return "\n".join(lines)


def _write_csv(rows: List[dict], path: Path) -> None:
    if not rows:
        return
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


EPISODE_COLS = ("object", "attempt", "runs", "success", "lifted", "stable", "force_closure", "success_at_attempt",
                "explore_fraction", "side_fraction", "predicted_stability", "epsilon", "position_error_cm", "yaw_error_deg", "entropy",
                "plan_ms_median")


def plot_per_attempt(tables: Dict[str, List[dict]], path: Path, title: str) -> Path:
    """Success, predicted stability, epsilon, pose error and entropy vs attempt, one line per
    method (averaged over objects) or per object when there is one method."""
    plt = _mpl()
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
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_belief_evolution(snapshots, true_pose, path: Path, title: str = "", attempts: Optional[list] = None) -> Path:
    """Particles (x, y; marker size = weight) before each attempt and at the end - thesis Figs. 3.3
    and 3.5. Colour: each particle's yaw error against the true yaw, wrapped to +-180 deg, on a
    diverging map centred at 0 (white = right yaw), scaled to the initial belief's spread. Legend:
    the true pose (red cross), its heading (red arrow) and the executed grasp (black triangle);
    each panel says whether its grasp lifted the object."""
    plt = _mpl()
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
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


# ---- entropy experiments ------------------------------------------------------------------------------
def plot_landscape(r: dict, path: Path, title: str) -> Path:
    """Fig. 3.6: the predicted expected-entropy landscape over grasp positions with the best,
    good and worst grasps marked."""
    plt = _mpl()
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
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_weight_vs_kernel(r: dict, path: Path, title: str) -> Path:
    plt = _mpl()
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
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_one_dof(r: dict, path: Path) -> Path:
    plt = _mpl()
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
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


# ---- per experiment -------------------------------------------------------------------------------------
def _start(name: str, out) -> tuple:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return out, [f"# Experiment `{name}`", ""], {"experiment": name}


def _finish(out: Path, md: list, summary: dict) -> dict:
    (out / "summary.md").write_text("\n".join(md))
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    return summary


def write_episodes(exp, results: Dict[str, list], out: Path) -> dict:
    """Closed-loop experiments (pub2, baselines, pub4): per-attempt tables per method and a plot."""
    out, md, summary = _start(exp.name, out)
    name = exp.name
    tables = {}
    for method, res in results.items():
        rows = episode_table(res)
        rows += _average(rows)
        tables[method] = rows
        _write_csv(rows, out / f"{method}.csv")
        md += [f"## method `{method}` ({len(res)} runs)", "", _markdown(rows, EPISODE_COLS), ""]
        last = [r for r in rows if r["object"] == "mean"]
        summary[method] = {"success_by_attempt": [r["success"] for r in last],
                           "stable_by_attempt": [r["stable"] for r in last],
                           "force_closure_by_attempt": [r["force_closure"] for r in last],
                           "lifted_by_attempt": [r["lifted"] for r in last],
                           "entropy_by_attempt": [r["entropy"] for r in last],
                           "position_error_cm_by_attempt": [r["position_error_cm"] for r in last],
                           "epsilon_by_attempt": [r["epsilon"] for r in last],
                           "plan_ms_median": float(np.median([a["plan_seconds"] * 1e3 for _, x in res
                                                              for a in x["attempts"]])),
                           "runs": len(res)}
    md += ["Columns (per attempt k, over the runs): success - a successful grasp by attempt k, by the run's "
           "criterion (default: held in the lift test; with --success epsilon: epsilon above the models' "
           "eps_stable, 0.01); lifted - held in the lift test by attempt k (with --success epsilon it runs on "
           "stable grasps only); stable - epsilon above eps_stable by attempt k; force_closure - epsilon > 0 by "
           "attempt k; success_at_attempt, explore_fraction, side_fraction (the share of side grasps), "
           "predicted_stability (the belief-weighted P(S) of the executed grasp), epsilon - over the runs "
           "that made attempt k; position_error_cm, yaw_error_deg, entropy (KDE, nats) - the belief after "
           "attempt k (carried forward once a run stopped); plan_ms_median - wall time of one decision.", ""]
    plot_per_attempt(tables, out / "per_attempt.png", f"{name}: per attempt")
    md += ["![per attempt](per_attempt.png)", ""]
    return _finish(out, md, summary)


def _by_object(results: list) -> Dict[str, list]:
    """The stored (key, result) pairs grouped by object, objects sorted by name."""
    groups: Dict[str, list] = {}
    for k, r in results:
        groups.setdefault(k.object, []).append(r)
    return dict(sorted(groups.items()))


def write_entropy_order(exp, results: Dict[str, list], out: Path) -> dict:
    """Fig. 3.6: does the realised entropy keep the predicted order of three grasps?"""
    out, md, summary = _start(exp.name, out)
    groups = _by_object(results["explore"])
    rows = []
    for obj, rs in groups.items():
        rows.append({"object": obj, "runs": len(rs), "order_kept": float(np.mean([r["order_kept"] for r in rs])),
                     "best_below_worst": float(np.mean([r["best_below_worst"] for r in rs])),
                     "kendall_tau": float(np.mean([r["kendall_tau"] for r in rs])),
                     **{f"realised_{k}": float(np.mean([r["realised"][k] for r in rs])) for k in ("best", "good", "worst")},
                     **{f"predicted_{k}": float(np.mean([r["predicted"][k] for r in rs])) for k in ("best", "good", "worst")}})
    _write_csv(rows, out / "entropy_order.csv")
    md += [_markdown(rows, ("object", "runs", "order_kept", "best_below_worst", "kendall_tau", "predicted_best",
                            "predicted_good", "predicted_worst", "realised_best", "realised_good", "realised_worst")), "",
           "order_kept: the realised entropies of the best, good and worst predicted grasps are in the "
           "predicted order (chance: 1/6); best_below_worst: the best grasp's realised entropy is below the "
           "worst's (chance: 1/2); kendall_tau: rank agreement of the three; predicted_* / realised_*: mean "
           "expected and realised posterior weight entropies (nats; the prior's is log 500 = 6.21).", ""]
    summary["rows"] = rows
    for obj, rs in groups.items():
        p = plot_landscape(rs[0], out / f"landscape_{obj}.png", f"{obj}: expected entropy of grasps (Fig. 3.6)")
        md += [f"![{obj}]({p.name})", ""]
    return _finish(out, md, summary)


def write_landscapes(exp, results: Dict[str, list], out: Path) -> dict:
    """Weight vs kernel expected-entropy landscapes and the 1-DOF sample-count comparison."""
    out, md, summary = _start(exp.name, out)
    rows = []
    for obj, rs in _by_object(results["explore"]).items():
        row = {"object": obj, "runs": len(rs), "pearson": float(np.mean([r["pearson"] for r in rs])),
               "spearman": float(np.mean([r["spearman"] for r in rs]))}
        rows.append(row)
        p = plot_weight_vs_kernel(rs[0], out / f"weight_vs_kernel_{obj}.png", obj)
        md += [f"![{obj}]({p.name})", ""]
        if "one_dof" in rs[0]:
            d = [r["one_dof"] for r in rs]
            summary["one_dof"] = {k: float(np.mean([x[k] for x in d]))
                                  for k in ("roughness_1000", "roughness_10000", "argmin_gap", "correlation")}
            p = plot_one_dof(rs[0], out / "one_dof_samples.png")
            md += [f"![1-DOF]({p.name})", ""]
    _write_csv(rows, out / "landscapes.csv")
    md = md[:2] + [_markdown(rows, ("object", "runs", "pearson", "spearman")), ""] + md[2:]
    if "one_dof" in summary:
        o = summary["one_dof"]
        md += [f"1-DOF cube: roughness (mean |second difference|) {o['roughness_1000']:.4f} with 1,000 samples vs "
               f"{o['roughness_10000']:.4f} with 10,000; argmin {100 * o['argmin_gap']:.2f} cm apart; "
               f"correlation {o['correlation']:.3f}.", ""]
    summary["rows"] = rows
    return _finish(out, md, summary)
