"""pub1's statistics (:mod:`.single_touch`): per optimiser and object, the quartiles of the
errors before and after the touch, of the fitness, evaluations and time; Fig. 2.1's second-grasp
success rates."""
from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Dict, List, Optional

import numpy as np

from .report import by_object

#: pub1's three cases (Pub. I's unknowns): 3 DoF pose, pose and scale, orientation.
CASES = ("pose", "pose_and_scale", "orientation")


@dataclass(frozen=True)
class Quartiles:
    """The median and the 25th and 75th percentiles of some values (all None: no values)."""

    median: Optional[float]
    q25: Optional[float]
    q75: Optional[float]

    def scaled(self, k: float) -> "Quartiles":
        """The same quartiles in other units (each times ``k``)."""
        return Quartiles(*(None if v is None else v * k for v in (self.median, self.q25, self.q75)))

    def to_dict(self) -> dict:
        return asdict(self)


def quartiles(values) -> Quartiles:
    """The quartiles of ``values``, None entries left out."""
    v = np.asarray([x for x in values if x is not None], dtype=float)
    if v.size == 0:
        return Quartiles(None, None, None)
    q = np.percentile(v, [25, 50, 75])
    return Quartiles(float(q[1]), float(q[0]), float(q[2]))


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
                row[f"position_mm_{when}"] = quartiles(c[when]["position_error"] for c in recs).scaled(1e3).to_dict()
                yaw = [c[when]["orientation_error"] for c in recs]
                row[f"orientation_deg_{when}"] = (None if all(y is None for y in yaw)
                                                  else quartiles(yaw).scaled(180 / np.pi).to_dict())
                row[f"size_pct_{when}"] = quartiles(c[when]["size_error"] for c in recs).scaled(100).to_dict()
            row["fitness"] = quartiles(c["fitness"] for c in recs).to_dict()
            row["evaluations"] = quartiles(c["evaluations"] for c in recs).to_dict()
            row["seconds"] = quartiles(c["seconds"] for c in recs).to_dict()
            row["cpu_seconds"] = quartiles(c.get("cpu_seconds", c["seconds"]) for c in recs).to_dict()
            rows.append(row)
    return rows


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
