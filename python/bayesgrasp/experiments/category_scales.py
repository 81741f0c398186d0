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
from typing import Dict

import numpy as np

from ..loop.category import plan_and_execute, see
from ..loop.context import RunContext
from ..planners.category import CategorySettings
from . import report
from .category_grasping import TASKS, prepare_task_grasps, view
from .category_plots import plot_scale_grid
from .category_stats import grid_rows, nested_rows
from .registry import Experiment, register
from .run_records import ScalesRun

MUGS = tuple(f"mug/{i}" for i in range(7))
TRANSLATION_CM = (0.5, 1.0, 2.0)
ROTATION_DEG = (5, 10, 20)
DENSITIES = ("laplace", "regularised", "gaussian", "baseline")
OURS = "t1cm_r10deg"


def series_name(t_cm: float, r_deg: float) -> str:
    return f"t{t_cm:g}cm_r{r_deg:g}deg"


GRID = {series_name(t, r): (t / 100.0, float(np.radians(r))) for t in TRANSLATION_CM for r in ROTATION_DEG}


def scales_run(experiment: str, obj: str, run_index: int, seed: int, *, ctx: RunContext, scales: tuple) -> ScalesRun:
    """One view of ``obj`` (the same for every grid point) and the four methods at ``scales``."""
    cat = obj.split("/")[0]
    pose, eye = view(seed)
    ep = see(obj, pose, cat, exclude=(obj,), eye_offset=eye, seed=seed % (2**31))
    t, r = scales
    tasks = {task: {m: plan_and_execute(ep, cat, task, m, ctx, seed=seed % (2**31),
                                        settings=CategorySettings(method=m, translation_scale=t, rotation_scale=r))
                    for m in DENSITIES} for task in TASKS[cat]}
    return ScalesRun(obj, cat, pose, (t, r), tasks)


def _make(exp: Experiment, method: str, ctx: RunContext):
    return method, partial(scales_run, ctx=ctx, scales=GRID[method])


def write_report(exp: Experiment, results: Dict[str, list], out: Path) -> report.Report:
    out, md, summary = report.start(exp.name, out)
    grid, nested = grid_rows(results, GRID, DENSITIES), nested_rows(results, MUGS, GRID, OURS)
    report.write_csv(grid, out / "grid.csv")
    report.write_csv(nested, out / "nested.csv")
    png = plot_scale_grid(grid, DENSITIES, out / "scales.png", f"{exp.name}: success over Eq. 4.1's density scales")
    md += ["Success = lifted and the contacts on the task's parts, pooled over the three mug tasks. The same "
           "views at every grid point.", "", report.markdown(grid, tuple(grid[0])), "",
           f"![success per density over the grid]({png.name})", "",
           "## The scales chosen without the held-out mug", "", report.markdown(nested, tuple(nested[0])), ""]
    summary.update({"grid": grid, "nested": nested})
    return report.finish(out, md, summary)


register(Experiment("pub5_scales", MUGS, 2, "Eq. 4.1's density scales s_t x s_R on a 3 x 3 grid (mugs, the same views)",
                    _make, write_report, tuple(GRID), prepare=prepare_task_grasps, reads=()))
