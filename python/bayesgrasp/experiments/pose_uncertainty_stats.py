"""The pose-uncertainty experiments' statistics (:mod:`.pose_uncertainty`: pub2, baselines, pub4,
entropy_order, landscapes): per object and attempt, success, lifted, stable and force closure
by attempt k and the belief after it; their mean over the objects."""
from __future__ import annotations

from typing import List

import numpy as np

from .report import by_object


ATTEMPTS = 4


def episode_table(results: list, attempts: int = ATTEMPTS) -> List[dict]:
    """Per object and attempt k: cumulative success (by the run's criterion) by attempt k, and
    beside it lifted, stable (epsilon) and force closure by k; means over the runs that made
    attempt k of predicted stability, epsilon, plan time; pose error and KDE entropy of the belief
    after attempt k (carried forward once a run stopped)."""
    rows = []
    for obj, runs in by_object(results).items():
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


def average_rows(rows: List[dict], attempts: int = ATTEMPTS) -> List[dict]:
    out = []
    for k in range(1, attempts + 1):
        rk = [r for r in rows if r["attempt"] == k]
        avg = {"object": "mean", "attempt": k, "runs": int(sum(r["runs"] for r in rk)),
               "made": int(sum(r["made"] for r in rk))}
        for f in rk[0]:
            if f not in avg:       # the mean over the objects that have the figure (NaN: none has)
                known = [r[f] for r in rk if not np.isnan(r[f])]
                avg[f] = float(np.mean(known)) if known else float("nan")
        out.append(avg)
    return out
