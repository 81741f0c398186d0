"""The thesis's category experiments (§4.2, Pub. V): leave-one-out over the mugs (tasks top,
side, handle) and the bottles (side); tools: trained on the hammers, tested on the knives
(handle). Each run is one held-out object seen from one random table pose and camera viewpoint;
all four methods (Laplace, regularised Gaussian, Gaussian, and the best-single-grasp baseline)
plan on the same view and registrations. Success = lifted and task-compatible (the contacts obey
the task's rule).

* ``pub5`` - the camera's partial view;
* ``pub5_complete`` - the held-out object's whole surface as the cloud (the thesis's simulated
  set-up, which it warns biases the results).
"""
from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Dict, List

import numpy as np

from ..loop.category import FAILURES, plan_and_execute, see
from ..loop.context import RunContext
from ..planners.category import METHODS
from . import report
from .category_plots import plot_success
from .category_stats import orderings, outcome_rows
from .registry import Experiment, register
from .run_records import CategoryRun

#: The tasks of each held-out category.
TASKS = {"mug": ("top", "side", "handle"), "bottle": ("side",), "knife": ("handle",)}
HELD_OUT = tuple([f"mug/{i}" for i in range(7)] + [f"bottle/{i}" for i in range(11)] + ["knife/0", "knife/1"])


def view(seed: int):
    """A run's table pose (x, y in +-5 cm, yaw uniform) and camera offset (azimuth uniform,
    elevation 30-60 deg, 0.55-0.75 m from the object's centre)."""
    rng = np.random.default_rng(seed)
    pose = (float(rng.uniform(-0.05, 0.05)), float(rng.uniform(-0.05, 0.05)), float(rng.uniform(-np.pi, np.pi)))
    az, el, r = rng.uniform(0, 2 * np.pi), np.radians(rng.uniform(30, 60)), rng.uniform(0.55, 0.75)
    eye = (float(r * np.cos(el) * np.cos(az)), float(r * np.cos(el) * np.sin(az)), float(r * np.sin(el)))
    return pose, eye


def category_run(experiment: str, obj: str, run_index: int, seed: int, *, ctx: RunContext,
                 complete: bool) -> CategoryRun:
    """One view of the held-out ``obj`` and every method (Eq. 4.1's densities, the baseline) planned
    and executed for each of its category's tasks."""
    cat = obj.split("/")[0]
    pose, eye = view(seed)
    ep = see(obj, pose, cat, exclude=(obj,), eye_offset=eye, seed=seed % (2**31), complete=complete)
    tasks = {t: {m: plan_and_execute(ep, cat, t, m, ctx, seed=seed % (2**31)) for m in METHODS}
             for t in TASKS[cat]}
    return CategoryRun(obj, cat, pose, eye, complete, int(len(ep.observation.cloud)), tuple(ep.registrations), tasks)


def prepare_task_grasps(exp: Experiment, objects: List[str], ctx: RunContext) -> None:
    """The demonstrated grasps of every training model for every task, generated (or loaded) once."""
    from ..loop.category import demonstrated, training_models
    from ..models.tasks import task_rule

    for cat in sorted({o.split("/")[0] for o in objects}):
        for task in TASKS[cat]:
            demonstrated(training_models(cat), task_rule(cat, task), ctx)


def _make(complete: bool):
    def make(exp: Experiment, method: str, ctx: RunContext):
        return exp.name, partial(category_run, ctx=ctx, complete=complete)
    return make


COLS = ("category", "task", "method", "runs", "success", "ci_low", "ci_high", "lifted", "task_ok", "force_closure",
        "epsilon") + FAILURES


def write_report(exp: Experiment, results: Dict[str, list], out: Path) -> report.Report:
    out, md, summary = report.start(exp.name, out)
    rows = outcome_rows(results["all"])
    report.write_csv(rows, out / "outcomes.csv")
    checks = orderings(rows, TASKS)
    md += ["Success = lifted in the lift test and the contacts on the task's parts (the task rules in "
           "`data/tasks/`); ci: 95% Wilson interval. Failure classes: collision at start, no contact, "
           "slipped in the lift (task-compatible but dropped), wrong part.", "",
           report.markdown(rows, COLS), "", "## The thesis's orderings", "",
           report.markdown(checks, ("claim", "holds", "figures")), ""]
    p = plot_success(rows, out / "success.png", exp.name)
    md += [f"![success]({p.name})", ""]
    summary.update({"rows": rows, "orderings": checks})
    return report.finish(out, md, summary)


register(Experiment("pub5", HELD_OUT, 10, "category task grasping, leave-one-out, partial views (Pub. V)",
                    _make(False), write_report, ("all",), prepare=prepare_task_grasps, reads=()))
register(Experiment("pub5_complete", HELD_OUT, 10, "category task grasping with the complete model as the cloud",
                    _make(True), write_report, ("all",), prepare=prepare_task_grasps, reads=()))
