"""pub1's prose (:mod:`.single_touch`): the Markdown tables and the thesis's findings, each a
yes/no with the figures behind it."""
from __future__ import annotations

from typing import Dict, List, Sequence

import numpy as np

from .single_touch_stats import CASES, case_rows, median_of, pooled, within


def cell(s, digits=1) -> str:
    if s is None:
        return "undefined (revolution)"
    if s["median"] is None:
        return "–"
    return f"{s['median']:.{digits}f} [{s['q25']:.{digits}f}, {s['q75']:.{digits}f}]"


def markdown_case(rows: List[dict], case: str, objects: Sequence[str], order: Sequence[str]) -> str:
    """One case's table: per optimiser (in ``order``) x object (in ``objects``), median [quartiles]."""
    head = ["optimizer", "object", "runs", "position mm", "orientation deg", "size %", "fitness", "evals", "CPU s",
            "position mm before", "orientation deg before"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in sorted(rows, key=lambda r: (list(objects).index(r["object"]) if r["object"] in objects else 99,
                                         order.index(r["optimizer"]) if r["optimizer"] in order else 99)):
        size = cell(r["size_pct_after"]) if case == "pose_and_scale" else "–"
        lines.append("| " + " | ".join([
            r["optimizer"], r["object"], str(r["runs"]),
            cell(r["position_mm_after"]) if case != "orientation" else "given",
            cell(r["orientation_deg_after"]), size, cell(r["fitness"], 3), f"{r['evaluations']['median']:.0f}",
            f"{r['cpu_seconds']['median']:.2f}", cell(r["position_mm_before"]) if case != "orientation" else "0",
            cell(r["orientation_deg_before"])]) + " |")
    return "\n".join(lines)


def findings(results: Dict[str, list], objects: Sequence[str]) -> List[dict]:
    """The thesis's findings, each a yes/no with the figures behind it (PSO unless stated); the
    objects in the order of ``objects``."""
    r3, r4, r1 = (case_rows(results, c) for c in CASES)     # 3 DoF, 4 DoF, 1 DoF
    objs = [o for o in objects if any(r["object"] == o for r in r3)] or sorted({r["object"] for r in r3})
    shaped = [o for o in objs if median_of(r3, "pso", o, "orientation_deg_after") is not None]
    out = []
    pso3 = pooled(results, "pso", "pose")
    close = float(np.mean([within(c) for c in pso3])) if pso3 else float("nan")
    ambiguous = float(np.mean([c["fitness"] < 1.0 and not within(c) for c in pso3])) if pso3 else float("nan")
    out.append({"finding": "one touch tells little (3 DoF)", "yes": bool(close < 0.5),
                "figures": f"{100 * close:.0f}% of PSO's estimates within 5 mm and 5 deg of the truth; "
                           f"{100 * ambiguous:.0f}% reproduce the readings (f < 1) yet are farther off"})
    pos = {o: (median_of(r3, "pso", o, "position_mm_after"), median_of(r3, "pso", o, "position_mm_before")) for o in objs}
    size = {o: median_of(r4, "pso", o, "size_pct_after") for o in objs}
    good_pos = [o for o, (a, b) in pos.items() if a is not None and b is not None and a < b / 3]
    good_size = [o for o, s in size.items() if s is not None and s < 3.0]
    out.append({"finding": "position and size come out well",
                "yes": bool(len(good_pos) >= 0.7 * len(objs) and len(good_size) >= 0.7 * len(objs)),
                "figures": "median position error mm (before -> after, 3 DoF): " +
                           ", ".join(f"{o} {b:.1f} -> {a:.1f}" for o, (a, b) in pos.items() if a is not None) +
                           "; median size error % (4 DoF): " +
                           ", ".join(f"{o} {s:.1f}" for o, s in size.items() if s is not None)})
    yaw3 = {o: median_of(r3, "pso", o, "orientation_deg_after") for o in shaped}
    spread = (max(yaw3.values()) / max(min(yaw3.values()), 1e-9)) if yaw3 else float("nan")
    revolution = [o for o in objs if o not in shaped]
    out.append({"finding": "orientation is object-dependent (and undefined for a body of revolution)",
                "yes": bool(spread >= 2.0),
                "figures": "median orientation error deg (3 DoF): " +
                           ", ".join(f"{o} {v:.1f}" for o, v in yaw3.items()) +
                           f"; worst/best {spread:.1f}x; undefined for {', '.join(revolution) or 'none'}"})
    ranks = {}
    for o in objs:
        f = {opt: median_of(r3, opt, o, "fitness") for opt in results}
        f = {k: v for k, v in f.items() if v is not None}
        ranks[o] = 1 + sum(v < f.get("pso", np.inf) for v in f.values()) if "pso" in f else None
    consistent = bool(ranks and all(r is not None and r <= 2 for r in ranks.values()))
    out.append({"finding": "PSO is consistently good", "yes": consistent,
                "figures": "PSO's rank by median final fitness (3 DoF) among " + ", ".join(results) + ": " +
                           ", ".join(f"{o} {r}" for o, r in ranks.items())})
    yaw1 = {o: median_of(r1, "pso", o, "orientation_deg_after") for o in shaped}
    better = [o for o in shaped if yaw1.get(o) is not None and yaw3.get(o) is not None and yaw1[o] < 0.5 * yaw3[o]]
    out.append({"finding": "given the exact position, orientation is found much more precisely",
                "yes": bool(shaped and len(better) > 0.5 * len(shaped)),
                "figures": "median orientation error deg, 3 DoF -> position given: " +
                           ", ".join(f"{o} {yaw3[o]:.1f} -> {yaw1[o]:.1f}" for o in shaped if yaw1.get(o) is not None)})
    return out
