"""The densities' scales (issue 29): Eq. 4.1's s_t (translation, m) and s_R (rotation, rad) are our
choice; the thesis leaves them open. ``pub5_scales`` sweeps a small grid on the mugs: every grid
point sees the same views (a view depends on the object and the run index only), each run plans
the three densities and the baseline for the three mug tasks.

The report says, per grid point, whether the thesis's orderings appear (Laplace above the
baseline, the basic Gaussian the worst of the three densities), and a nested choice that never
looks at the held-out object: for each mug h, the scales that maximise Laplace's success on the
runs of the other mugs, and h's success at those scales beside its success at ours (1 cm, 10 deg).
"""
from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Dict, List

import numpy as np

from ..planners.category import CategorySettings
from . import report
from .category import plan_and_execute, see
from .category_grasping import TASKS, prepare_task_grasps, view
from .context import RunContext
from .registry import Experiment, register
from .runner import run_seed

MUGS = tuple(f"mug/{i}" for i in range(7))
TRANSLATION_CM = (0.5, 1.0, 2.0)
ROTATION_DEG = (5, 10, 20)
DENSITIES = ("laplace", "regularised", "gaussian", "baseline")
OURS = "t1cm_r10deg"


def series_name(t_cm: float, r_deg: float) -> str:
    return f"t{t_cm:g}cm_r{r_deg:g}deg"


GRID = {series_name(t, r): (t / 100.0, float(np.radians(r))) for t in TRANSLATION_CM for r in ROTATION_DEG}


def scales_run(experiment: str, obj: str, run_index: int, seed: int, *, ctx: RunContext, scales: tuple) -> dict:
    """One view of ``obj`` (the same for every grid point) and the four methods at ``scales``."""
    cat = obj.split("/")[0]
    view_seed = run_seed(ctx.seed, "pub5_scales", obj, run_index)
    pose, eye = view(view_seed)
    ep = see(obj, pose, cat, exclude=(obj,), eye_offset=eye, seed=view_seed % (2**31))
    t, r = scales
    tasks = {task: {m: plan_and_execute(ep, cat, task, m, ctx, seed=view_seed % (2**31),
                                        settings=CategorySettings(method=m, translation_scale=t, rotation_scale=r))
                    for m in DENSITIES} for task in TASKS[cat]}
    return {"object": obj, "category": cat, "pose": list(pose), "scales": [t, r], "tasks": tasks}


def _make(exp: Experiment, method: str, ctx: RunContext):
    return method, partial(scales_run, ctx=ctx, scales=GRID[method])


def _success(results: list, method: str, exclude: str = "", only: str = "") -> tuple:
    """(successes, trials) of ``method`` over runs and tasks, without object ``exclude`` / only ``only``."""
    k = n = 0
    for _, r in results:
        if (exclude and r["object"] == exclude) or (only and r["object"] != only):
            continue
        for outs in r["tasks"].values():
            k += bool(outs[method]["success"])
            n += 1
    return k, n


def grid_rows(results: Dict[str, list]) -> List[dict]:
    """Per grid point: each method's success over all runs and tasks, and the thesis's two orderings."""
    rows = []
    for name, (t, r) in GRID.items():
        res = results.get(name, [])
        rates = {}
        for m in DENSITIES:
            k, n = _success(res, m)
            rates[m] = k / n if n else float("nan")
        rows.append({"scales": name, "s_t (cm)": 100 * t, "s_R (deg)": round(float(np.degrees(r))),
                     **{m: round(rates[m], 3) for m in DENSITIES},
                     "laplace above baseline": rates["laplace"] > rates["baseline"],
                     "gaussian the worst density": rates["gaussian"] <= min(rates["laplace"], rates["regularised"])})
    return rows


def nested_rows(results: Dict[str, list]) -> List[dict]:
    """Per held-out mug h: the scales chosen on the other mugs' runs (Laplace's success), h's Laplace
    success there and at ours."""
    rows = []
    for h in MUGS:
        def inner(name):
            k, n = _success(results.get(name, []), "laplace", exclude=h)
            return k / n if n else -1.0
        best = max(GRID, key=inner)
        kb, nb = _success(results.get(best, []), "laplace", only=h)
        ko, no = _success(results.get(OURS, []), "laplace", only=h)
        rows.append({"held out": h, "chosen on the others": best, "their success": round(inner(best), 3),
                     "held-out success, chosen": f"{kb}/{nb}", "held-out success, ours (1 cm, 10 deg)": f"{ko}/{no}"})
    return rows


def write_report(exp: Experiment, results: Dict[str, list], out: Path) -> dict:
    out, md, summary = report._start(exp.name, out)
    grid, nested = grid_rows(results), nested_rows(results)
    report._write_csv(grid, out / "grid.csv")
    report._write_csv(nested, out / "nested.csv")
    md += ["Success = lifted and the contacts on the task's parts, pooled over the three mug tasks. The same "
           "views at every grid point.", "", report._markdown(grid, tuple(grid[0])), "",
           "## The scales chosen without the held-out mug", "", report._markdown(nested, tuple(nested[0])), ""]
    summary.update({"grid": grid, "nested": nested})
    return report._finish(out, md, summary)


register(Experiment("pub5_scales", MUGS, 2, "Eq. 4.1's density scales s_t x s_R on a 3 x 3 grid (mugs, the same views)",
                    _make, write_report, tuple(GRID), prepare=prepare_task_grasps))
