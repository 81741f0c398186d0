"""The pose-uncertainty experiments' reports (:mod:`.pose_uncertainty`): the tables with what each
column means, written as summary.md / summary.json / CSV beside the figures."""
from __future__ import annotations

from pathlib import Path
from typing import Dict

import numpy as np

from .pose_uncertainty_plots import (plot_landscape, plot_one_dof, plot_per_attempt,
                                     plot_weight_vs_kernel)
from .pose_uncertainty_stats import average_rows, episode_table
from .report import Report, by_object, finish, markdown, start, write_csv


EPISODE_COLS = ("object", "attempt", "runs", "success", "lifted", "stable", "force_closure", "success_at_attempt",
                "explore_fraction", "side_fraction", "predicted_stability", "epsilon", "position_error_cm", "yaw_error_deg", "entropy",
                "plan_ms_median")


def write_episodes(exp, results: Dict[str, list], out: Path) -> Report:
    """Closed-loop experiments (pub2, baselines, pub4): per-attempt tables per method and a plot."""
    out, md, summary = start(exp.name, out)
    name = exp.name
    tables = {}
    for method, res in results.items():
        rows = episode_table(res)
        rows += average_rows(rows)
        tables[method] = rows
        write_csv(rows, out / f"{method}.csv")
        md += [f"## method `{method}` ({len(res)} runs)", "", markdown(rows, EPISODE_COLS), ""]
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
    return finish(out, md, summary)


def write_entropy_order(exp, results: Dict[str, list], out: Path) -> Report:
    """Fig. 3.6: does the realised entropy keep the predicted order of three grasps?"""
    out, md, summary = start(exp.name, out)
    groups = by_object(results["explore"])
    rows = []
    for obj, rs in groups.items():
        rows.append({"object": obj, "runs": len(rs), "order_kept": float(np.mean([r["order_kept"] for r in rs])),
                     "best_below_worst": float(np.mean([r["best_below_worst"] for r in rs])),
                     "kendall_tau": float(np.mean([r["kendall_tau"] for r in rs])),
                     **{f"realised_{k}": float(np.mean([r["realised"][k] for r in rs])) for k in ("best", "good", "worst")},
                     **{f"predicted_{k}": float(np.mean([r["predicted"][k] for r in rs])) for k in ("best", "good", "worst")}})
    write_csv(rows, out / "entropy_order.csv")
    md += [markdown(rows, ("object", "runs", "order_kept", "best_below_worst", "kendall_tau", "predicted_best",
                            "predicted_good", "predicted_worst", "realised_best", "realised_good", "realised_worst")), "",
           "order_kept: the realised entropies of the best, good and worst predicted grasps are in the "
           "predicted order (chance: 1/6); best_below_worst: the best grasp's realised entropy is below the "
           "worst's (chance: 1/2); kendall_tau: rank agreement of the three; predicted_* / realised_*: mean "
           "expected and realised posterior weight entropies (nats; the prior's is log 500 = 6.21).", ""]
    summary["rows"] = rows
    for obj, rs in groups.items():
        p = plot_landscape(rs[0], out / f"landscape_{obj}.png", f"{obj}: expected entropy of grasps (Fig. 3.6)")
        md += [f"![{obj}]({p.name})", ""]
    return finish(out, md, summary)


def write_landscapes(exp, results: Dict[str, list], out: Path) -> Report:
    """Weight vs kernel expected-entropy landscapes and the 1-DOF sample-count comparison."""
    out, md, summary = start(exp.name, out)
    rows = []
    for obj, rs in by_object(results["explore"]).items():
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
    write_csv(rows, out / "landscapes.csv")
    md = md[:2] + [markdown(rows, ("object", "runs", "pearson", "spearman")), ""] + md[2:]
    if "one_dof" in summary:
        o = summary["one_dof"]
        md += [f"1-DOF cube: roughness (mean |second difference|) {o['roughness_1000']:.4f} with 1,000 samples vs "
               f"{o['roughness_10000']:.4f} with 10,000; argmin {100 * o['argmin_gap']:.2f} cm apart; "
               f"correlation {o['correlation']:.3f}.", ""]
    summary["rows"] = rows
    return finish(out, md, summary)
