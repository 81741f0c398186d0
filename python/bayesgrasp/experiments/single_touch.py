"""What one touch tells about an object (thesis ch. 2, Pub. I): ``bayesgrasp experiment pub1``.

Each run draws, for each of Pub. I's three cases, a hidden true state and an initial guess, executes
the touch (a top grasp at the guessed object centre along the guessed yaw, at the hand's default
spread: :meth:`~bayesgrasp.planners.touch.TouchPlanner.plan` without models) on the true object and lets
one optimiser fit the touch model to the readings:

* ``pose`` (3 DoF): x, y, yaw unknown; scale 1.
* ``pose_and_scale`` (4 DoF): plus a uniform scale, the truth's uniform in [0.8, 1.2], guessed 1.
* ``orientation``: yaw unknown, the position given exactly; scale 1.

True poses: x, y uniform in +-5 cm, yaw uniform in [-pi, pi). Initial errors: uniform in +-3 cm
(x and y), +-30 deg; the search box is the guess +- those errors (and the scale range). Every
optimiser gets the same problems, budget (2,000 fitness evaluations) and seeds. Then Fig. 2.1's
loop in the 3-DoF case: the grasp models' most stable grasp planned on the initial guess and on
the updated estimate, each executed on the true object; success is the run context's criterion
(default: held in the lift test).

Orientation errors are taken modulo the object's symmetry (90 deg for the cube); for a body of
revolution (cylinder, bottle) the orientation is undefined and reported as such.
"""
from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Dict, List, Optional

import numpy as np

from ..loop.context import RunContext
from ..loop.episode import execute
from ..loop.touch_trial import pose_errors, touch_once
from ..planners.touch import TouchModel, TouchPlanner, TouchSettings
from ..world import World
from . import report
from .registry import Experiment, register
from .run_records import PlannedGrasp, SecondGrasp, TouchCase, TouchRun
from .runner import ResultStore
from .single_touch_plots import plot_errors
from .single_touch_prose import findings, markdown_case
from .single_touch_stats import CASES, case_rows, second_grasp_rows

OBJECTS = ("cube", "cylinder", "bottle/0", "mug", "mug2", "pitcher", "hammer/0")
OPTIMIZERS = ("descent", "sa", "pso", "firefly")
BUDGET = 2000
TRUE_XY = 0.05                      # true x, y uniform in +- this (m)
ERROR_XY = 0.03                     # initial x, y errors uniform in +- this (m)
ERROR_YAW = float(np.radians(30.0))  # initial yaw error uniform in +- this (rad)
SCALES = (0.8, 1.2)                 # the 4-DoF truth's scale range (the guess is 1)

_MODELS: Dict[tuple, TouchModel] = {}


def touch_model(obj: str, hand: str) -> TouchModel:
    """The touch model of an object (one per process: its simulators per scale are kept)."""
    if (obj, hand) not in _MODELS:
        _MODELS[(obj, hand)] = TouchModel(obj, hand)
    return _MODELS[(obj, hand)]


def problem(case: str, rng: np.random.Generator):
    """(truth, initial guess), each (x, y, yaw, scale), of one case."""
    truth = np.array([rng.uniform(-TRUE_XY, TRUE_XY), rng.uniform(-TRUE_XY, TRUE_XY), rng.uniform(-np.pi, np.pi), 1.0])
    err = np.array([rng.uniform(-ERROR_XY, ERROR_XY), rng.uniform(-ERROR_XY, ERROR_XY),
                    rng.uniform(-ERROR_YAW, ERROR_YAW)])
    scale = rng.uniform(*SCALES)
    if case == "pose_and_scale":
        truth[3] = scale
    if case == "orientation":
        err[:2] = 0.0
    initial = truth.copy()
    initial[:3] -= err
    initial[3] = 1.0
    return truth, initial


def _one_case(obj: str, case: str, optimizer: str, rng: np.random.Generator, seed: int, ctx: RunContext,
              contact_term: str = "flags", hand: Optional[str] = None) -> TouchCase:
    """One case's problem drawn from ``rng``, touched and fitted by ``optimizer``."""
    truth, initial = problem(case, rng)
    model = touch_model(obj, hand or ctx.hand)
    settings = TouchSettings(optimizer=optimizer, unknowns=case, budget=BUDGET, seed=seed,
                             box=(ERROR_XY, ERROR_YAW, SCALES[0], SCALES[1]), contact_term=contact_term)
    t = touch_once(TouchPlanner(model, initial, settings), obj, truth)
    return TouchCase(truth, initial, t, pose_errors(obj, initial, truth), pose_errors(obj, t.estimate, truth))


def _second_grasp(obj: str, planner: TouchPlanner, truth, ctx: RunContext) -> SecondGrasp:
    """Fig. 2.1: the most stable grasp planned on the initial guess and on the updated model,
    each executed on the true object."""
    models = ctx.models(obj)
    world = World.single(obj, pose=truth[:3], hand=ctx.hand_model)
    tried = []
    for estimate in (planner.initial, planner.estimate):
        action = TouchPlanner(planner.model, estimate, planner.settings, models=models).plan().action
        ex = execute(world, models, action, truth[:3], ctx)
        tried.append(PlannedGrasp(action, ex.success, ex.epsilon, ex.lifted))
    return SecondGrasp(*tried)


def touch_run(experiment: str, obj: str, run_index: int, seed: int, *, optimizer: str, ctx: RunContext) -> TouchRun:
    """One run: the three cases on problems (and optimiser seeds) shared by every optimiser."""
    rng = np.random.default_rng(seed)
    cases, second = {}, None
    for case in CASES:
        c = cases[case] = _one_case(obj, case, optimizer, rng, seed, ctx)
        if case == "pose":   # Fig. 2.1's loop on the 3-DoF problem
            second = _second_grasp(obj, c.trial.planner, c.truth, ctx)
    return TouchRun(obj, "optimizer", optimizer, cases, second)


def _make_run(exp: Experiment, method: str, ctx: RunContext):
    return f"{exp.name}/{method}", partial(touch_run, optimizer=method, ctx=ctx)


# ---- report: statistics (single_touch_stats), prose (single_touch_prose), figures (single_touch_plots) ----
def write_report(exp: Experiment, results: Dict[str, list], out) -> report.Report:
    out, md, summary = report.start(exp.name, out)
    md += [__doc__.strip().split("\n")[0], "",
           "Cells: median [25th, 75th percentile] over the runs; errors after the touch, then the initial ones.", ""]
    for case in CASES:
        rows = case_rows(results, case)
        summary[case] = rows
        plot_errors(results, case, out / f"errors_{case}.png", OBJECTS)
        md += [f"## Case `{case}`", "", markdown_case(rows, case, OBJECTS, OPTIMIZERS + tuple(VARIANTS)), "",
               f"![errors](errors_{case}.png)", ""]
    f = findings(results, OBJECTS)
    summary["findings"] = f
    md += ["## The thesis's findings", "", "| finding | yes/no | figures |", "|---|---|---|"]
    md += [f"| {x['finding']} | {'yes' if x['yes'] else 'no'} | {x['figures']} |" for x in f]
    g = second_grasp_rows(results)
    summary["second_grasp"] = g
    report.write_csv(g, out / "second_grasp.csv")
    md += ["", "## Fig. 2.1: the grasp planned on the initial guess vs on the updated model (3 DoF)", "",
           report.markdown(g, ("optimizer", "object", "runs", "success_initial", "success_updated"))]
    return report.finish(out, md, summary)


def planned_on_truth(exp: Experiment, objects: List[str], ctx: RunContext, out) -> None:
    """Fig. 2.1's reference: the same plan made on the true pose (what a perfect update would give),
    executed on the true object, for every stored run's 3-DoF problem (shared by the optimisers)."""
    store = ResultStore(Path(out) / "results.sqlite")
    try:
        stored = store.results(f"{exp.name}/{exp.methods[0]}")
    finally:
        store.close()
    rows = []
    for o in objects:
        truths = [np.asarray(r["cases"]["pose"]["truth"]) for key, r in stored if key.object == o]
        if not truths:
            continue
        models = ctx.models(o)
        wins = []
        for truth in truths:
            world = World.single(o, pose=truth[:3], hand=ctx.hand_model)
            action = TouchPlanner(touch_model(o, ctx.hand), truth, models=models).plan().action
            wins.append(execute(world, models, action, truth[:3], ctx).success)
        rows.append({"object": o, "runs": len(truths), "success_on_truth": float(np.mean(wins))})
    report.write_csv(rows, Path(out) / "second_grasp_on_truth.csv")
    with open(Path(out) / "summary.md", "a") as f:
        f.write("\n\nThe same plan made on the true pose (the most a perfect update can give):\n\n" +
                report.markdown(rows, ("object", "runs", "success_on_truth")) + "\n")


def prepare_models(exp: Experiment, obj: str, ctx: RunContext) -> None:
    """One object's grasp models (Fig. 2.1's second grasp plans on them), built once."""
    ctx.models(obj)


register(Experiment("pub1", OBJECTS, 30, "what one touch tells about an object: four optimisers (Pub. I)",
                    _make_run, write_report, OPTIMIZERS, planned_on_truth, prepare_object=prepare_models,
                    reads=("success", "lift", "models")))


# ---- variants: the continuous contact term, another hand ---------------------------------------
#: method -> (optimiser, contact term, hand or None for the run context's)
VARIANTS = {"pso/flags": ("pso", "flags", None), "pso/surface": ("pso", "surface", None),
            "descent/flags": ("descent", "flags", None), "descent/surface": ("descent", "surface", None),
            "pso/robotiq_3f": ("pso", "flags", "robotiq_3f")}


def variant_run(experiment: str, obj: str, run_index: int, seed: int, *, method: str, ctx: RunContext) -> TouchRun:
    """pub1's 3-DoF problem of the same run index, with another contact term or hand."""
    optimizer, term, hand = VARIANTS[method]
    case = _one_case(obj, "pose", optimizer, np.random.default_rng(seed), seed, ctx, term, hand)
    return TouchRun(obj, "method", method, {"pose": case})


def _make_variant(exp: Experiment, method: str, ctx: RunContext):
    return f"{exp.name}/{method}", partial(variant_run, method=method, ctx=ctx)


def write_variants(exp: Experiment, results: Dict[str, list], out) -> report.Report:
    out, md, summary = report.start(exp.name, out)
    md += ["pub1's 3-DoF problems with the continuous contact term (surface) and with the Robotiq 3F hand.",
           "Cells: median [25th, 75th percentile]; the method column is optimiser/contact term or hand.", ""]
    rows = case_rows(results, "pose")
    summary["pose"] = rows
    md += [markdown_case(rows, "pose", OBJECTS, OPTIMIZERS + tuple(VARIANTS)).replace("| optimizer |", "| method |")]
    return report.finish(out, md, summary)


register(Experiment("pub1_variants", ("cube", "mug", "hammer/0"), 10,
                    "pub1 (3 DoF) with the continuous contact term and with another hand", _make_variant,
                    write_variants, tuple(VARIANTS), reads=(), seed_name="pub1"))   # pub1's problems
