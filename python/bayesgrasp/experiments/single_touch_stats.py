"""pub1's statistics (:mod:`.single_touch`): per optimiser and object, the quartiles of the
errors before and after the touch, of the fitness, evaluations and time; Fig. 2.1's second-grasp
success rates."""
from __future__ import annotations

from typing import Dict, List

import numpy as np

from .report import by_object

#: pub1's three cases (Pub. I's unknowns): 3 DoF pose, pose and scale, orientation.
CASES = ("pose", "pose_and_scale", "orientation")


def quartiles(values) -> dict:
    v = np.asarray([x for x in values if x is not None], dtype=float)
    if v.size == 0:
        return {"median": None, "q25": None, "q75": None}
    q = np.percentile(v, [25, 50, 75])
    return {"median": float(q[1]), "q25": float(q[0]), "q75": float(q[2])}


def case_rows(results: Dict[str, list], case: str) -> List[dict]:
    """Per optimiser x object: median and quartiles of the errors after (and before) the touch,
    the final fitness, evaluations and time."""
    rows = []
    for opt, res in results.items():
        for obj, runs in by_object(res).items():
            recs = [r["cases"][case] for r in runs]
            row = {"optimizer": opt, "object": obj, "runs": len(recs),
                   "no_contact": int(sum(c["status"] != "estimated" for c in recs))}
            for when in ("before", "after"):
                row[f"position_mm_{when}"] = scaled(quartiles(c[when]["position_error"] for c in recs), 1e3)
                yaw = [c[when]["orientation_error"] for c in recs]
                row[f"orientation_deg_{when}"] = (None if all(y is None for y in yaw)
                                                  else scaled(quartiles(yaw), 180 / np.pi))
                row[f"size_pct_{when}"] = scaled(quartiles(c[when]["size_error"] for c in recs), 100)
            row["fitness"] = quartiles(c["fitness"] for c in recs)
            row["evaluations"] = quartiles(c["evaluations"] for c in recs)
            row["seconds"] = quartiles(c["seconds"] for c in recs)
            row["cpu_seconds"] = quartiles(c.get("cpu_seconds", c["seconds"]) for c in recs)
            rows.append(row)
    return rows


def scaled(s: dict, k: float) -> dict:
    return {a: (None if v is None else v * k) for a, v in s.items()}


def median_of(rows, opt, obj, field):
    for r in rows:
        if r["optimizer"] == opt and r["object"] == obj:
            s = r[field]
            return None if s is None else s["median"]
    return None


def pooled(results: Dict[str, list], opt: str, case: str) -> List[dict]:
    return [r["cases"][case] for _, r in results.get(opt, [])]


def within(c: dict, mm: float = 5.0, deg: float = 5.0) -> bool:
    a = c["after"]
    yaw_ok = a["orientation_error"] is None or a["orientation_error"] <= np.radians(deg)
    return a["position_error"] <= mm * 1e-3 and yaw_ok


def second_grasp_rows(results: Dict[str, list]) -> List[dict]:
    """Fig. 2.1: success of the grasp planned on the initial guess vs on the updated model."""
    rows = []
    for opt, res in results.items():
        for obj, runs in by_object(res).items():
            recs = [r["second_grasp"] for r in runs]
            rows.append({"optimizer": opt, "object": obj, "runs": len(recs),
                         "success_initial": float(np.mean([g["initial"]["success"] for g in recs])),
                         "success_updated": float(np.mean([g["updated"]["success"] for g in recs]))})
    return rows
