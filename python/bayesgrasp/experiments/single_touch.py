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

from ..planners.touch import (TouchModel, TouchPlanner, TouchSettings, orientation_error, read, symmetry_order,
                              touch_world)
from ..world import World
from . import report
from .context import RunContext
from .episode import execute
from .registry import Experiment, register
from .runner import ResultStore, run_seed

OBJECTS = ("cube", "cylinder", "bottle/0", "mug", "mug2", "pitcher", "hammer/0")
OPTIMIZERS = ("descent", "sa", "pso", "firefly")
CASES = ("pose", "pose_and_scale", "orientation")
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


def _errors(obj: str, state, truth) -> dict:
    state, truth = np.asarray(state, dtype=float), np.asarray(truth, dtype=float)
    yaw = orientation_error(state[2], truth[2], symmetry_order(obj))
    return {"position_error": float(np.hypot(*(state[:2] - truth[:2]))), "orientation_error": yaw,
            "size_error": float(abs(state[3] - truth[3]) / truth[3])}


def _one_case(obj: str, case: str, optimizer: str, rng: np.random.Generator, seed: int, ctx: RunContext,
              contact_term: str = "flags", hand: Optional[str] = None):
    truth, initial = problem(case, rng)
    model = touch_model(obj, hand or ctx.hand)
    settings = TouchSettings(optimizer=optimizer, unknowns=case, budget=BUDGET, seed=seed,
                             box=(ERROR_XY, ERROR_YAW, SCALES[0], SCALES[1]), contact_term=contact_term)
    planner = TouchPlanner(model, initial, settings)
    grasp = planner.plan().touch
    readings = read(touch_world(obj, truth[:3], truth[3], model.hand), grasp)
    r = planner.observe(grasp, readings)
    rec = {"truth": truth.tolist(), "initial": initial.tolist(), "estimate": planner.estimate.tolist(),
           "status": r.status.name, "contacts": int(readings.contact_count), "fitness": r.fitness,
           "initial_fitness": r.initial_fitness, "evaluations": int(r.evaluations), "seconds": r.seconds,
           "cpu_seconds": r.cpu_seconds,
           "trace": [list(map(int, r.trace_evaluations[::10])), list(r.trace_fitness[::10])],
           "before": _errors(obj, initial, truth), "after": _errors(obj, planner.estimate, truth)}
    return rec, planner, truth


def _second_grasp(obj: str, planner: TouchPlanner, truth, ctx: RunContext) -> dict:
    """Fig. 2.1: the most stable grasp planned on the initial guess and on the updated model,
    each executed on the true object."""
    models = ctx.models(obj)
    world = World.single(obj, pose=truth[:3], hand=ctx.hand)
    out = {}
    for name, estimate in (("initial", planner.initial), ("updated", planner.estimate)):
        action = TouchPlanner(planner.model, estimate, planner.settings, models=models).plan().action
        ex = execute(world, models, action, truth[:3], ctx)
        out[name] = {"action": action.tolist(), "success": ex.success, "epsilon": ex.epsilon, "lifted": ex.lifted}
    return out


def touch_run(experiment: str, obj: str, run_index: int, seed: int, *, optimizer: str, ctx: RunContext) -> dict:
    """One run: the three cases on problems (and optimiser seeds) shared by every optimiser."""
    base = run_seed(ctx.seed, "pub1", obj, run_index)
    rng = np.random.default_rng(base)
    out = {"object": obj, "optimizer": optimizer, "cases": {}}
    for case in CASES:
        rec, planner, truth = _one_case(obj, case, optimizer, rng, base, ctx)
        out["cases"][case] = rec
        if case == "pose":
            out["second_grasp"] = _second_grasp(obj, planner, truth, ctx)
    return out


def _make_run(exp: Experiment, method: str, ctx: RunContext):
    return f"{exp.name}/{method}", partial(touch_run, optimizer=method, ctx=ctx)


# ---- report -----------------------------------------------------------------------------------------
def _stat(values) -> dict:
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
        by_obj: Dict[str, list] = {}
        for key, r in res:
            by_obj.setdefault(key.object, []).append(r["cases"][case])
        for obj, recs in by_obj.items():
            row = {"optimizer": opt, "object": obj, "runs": len(recs),
                   "no_contact": int(sum(c["status"] != "estimated" for c in recs))}
            for when in ("before", "after"):
                row[f"position_mm_{when}"] = _scaled(_stat(c[when]["position_error"] for c in recs), 1e3)
                yaw = [c[when]["orientation_error"] for c in recs]
                row[f"orientation_deg_{when}"] = (None if all(y is None for y in yaw)
                                                  else _scaled(_stat(yaw), 180 / np.pi))
                row[f"size_pct_{when}"] = _scaled(_stat(c[when]["size_error"] for c in recs), 100)
            row["fitness"] = _stat(c["fitness"] for c in recs)
            row["evaluations"] = _stat(c["evaluations"] for c in recs)
            row["seconds"] = _stat(c["seconds"] for c in recs)
            row["cpu_seconds"] = _stat(c.get("cpu_seconds", c["seconds"]) for c in recs)
            rows.append(row)
    return rows


def _scaled(s: dict, k: float) -> dict:
    return {a: (None if v is None else v * k) for a, v in s.items()}


def _cell(s, digits=1) -> str:
    if s is None:
        return "undefined (revolution)"
    if s["median"] is None:
        return "–"
    return f"{s['median']:.{digits}f} [{s['q25']:.{digits}f}, {s['q75']:.{digits}f}]"


def _markdown_case(rows: List[dict], case: str) -> str:
    head = ["optimizer", "object", "runs", "position mm", "orientation deg", "size %", "fitness", "evals", "CPU s",
            "position mm before", "orientation deg before"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    order = list(OPTIMIZERS) + list(VARIANTS)
    for r in sorted(rows, key=lambda r: (OBJECTS.index(r["object"]) if r["object"] in OBJECTS else 99,
                                         order.index(r["optimizer"]) if r["optimizer"] in order else 99)):
        size = _cell(r["size_pct_after"]) if case == "pose_and_scale" else "–"
        lines.append("| " + " | ".join([
            r["optimizer"], r["object"], str(r["runs"]),
            _cell(r["position_mm_after"]) if case != "orientation" else "given",
            _cell(r["orientation_deg_after"]), size, _cell(r["fitness"], 3), f"{r['evaluations']['median']:.0f}",
            f"{r['cpu_seconds']['median']:.2f}", _cell(r["position_mm_before"]) if case != "orientation" else "0",
            _cell(r["orientation_deg_before"])]) + " |")
    return "\n".join(lines)


def _median(rows, opt, obj, field):
    for r in rows:
        if r["optimizer"] == opt and r["object"] == obj:
            s = r[field]
            return None if s is None else s["median"]
    return None


def _pooled(results: Dict[str, list], opt: str, case: str) -> List[dict]:
    return [r["cases"][case] for _, r in results.get(opt, [])]


def _within(c: dict, mm: float = 5.0, deg: float = 5.0) -> bool:
    a = c["after"]
    yaw_ok = a["orientation_error"] is None or a["orientation_error"] <= np.radians(deg)
    return a["position_error"] <= mm * 1e-3 and yaw_ok


def findings(results: Dict[str, list]) -> List[dict]:
    """The thesis's findings, each a yes/no with the figures behind it (PSO unless stated)."""
    r3, r4, r1 = (case_rows(results, c) for c in CASES)
    objs = [o for o in OBJECTS if any(r["object"] == o for r in r3)] or sorted({r["object"] for r in r3})
    shaped = [o for o in objs if _median(r3, "pso", o, "orientation_deg_after") is not None]
    out = []
    pso3 = _pooled(results, "pso", "pose")
    within = float(np.mean([_within(c) for c in pso3])) if pso3 else float("nan")
    ambiguous = float(np.mean([c["fitness"] < 1.0 and not _within(c) for c in pso3])) if pso3 else float("nan")
    out.append({"finding": "one touch tells little (3 DoF)", "yes": bool(within < 0.5),
                "figures": f"{100 * within:.0f}% of PSO's estimates within 5 mm and 5 deg of the truth; "
                           f"{100 * ambiguous:.0f}% reproduce the readings (f < 1) yet are farther off"})
    pos = {o: (_median(r3, "pso", o, "position_mm_after"), _median(r3, "pso", o, "position_mm_before")) for o in objs}
    size = {o: _median(r4, "pso", o, "size_pct_after") for o in objs}
    good_pos = [o for o, (a, b) in pos.items() if a is not None and b is not None and a < b / 3]
    good_size = [o for o, s in size.items() if s is not None and s < 3.0]
    out.append({"finding": "position and size come out well",
                "yes": bool(len(good_pos) >= 0.7 * len(objs) and len(good_size) >= 0.7 * len(objs)),
                "figures": "median position error mm (before -> after, 3 DoF): " +
                           ", ".join(f"{o} {b:.1f} -> {a:.1f}" for o, (a, b) in pos.items() if a is not None) +
                           "; median size error % (4 DoF): " +
                           ", ".join(f"{o} {s:.1f}" for o, s in size.items() if s is not None)})
    yaw3 = {o: _median(r3, "pso", o, "orientation_deg_after") for o in shaped}
    spread = (max(yaw3.values()) / max(min(yaw3.values()), 1e-9)) if yaw3 else float("nan")
    revolution = [o for o in objs if o not in shaped]
    out.append({"finding": "orientation is object-dependent (and undefined for a body of revolution)",
                "yes": bool(spread >= 2.0),
                "figures": "median orientation error deg (3 DoF): " +
                           ", ".join(f"{o} {v:.1f}" for o, v in yaw3.items()) +
                           f"; worst/best {spread:.1f}x; undefined for {', '.join(revolution) or 'none'}"})
    ranks = {}
    for o in objs:
        f = {opt: _median(r3, opt, o, "fitness") for opt in results}
        f = {k: v for k, v in f.items() if v is not None}
        ranks[o] = 1 + sum(v < f.get("pso", np.inf) for v in f.values()) if "pso" in f else None
    consistent = bool(ranks and all(r is not None and r <= 2 for r in ranks.values()))
    out.append({"finding": "PSO is consistently good", "yes": consistent,
                "figures": "PSO's rank by median final fitness (3 DoF) among " + ", ".join(results) + ": " +
                           ", ".join(f"{o} {r}" for o, r in ranks.items())})
    yaw1 = {o: _median(r1, "pso", o, "orientation_deg_after") for o in shaped}
    better = [o for o in shaped if yaw1.get(o) is not None and yaw3.get(o) is not None and yaw1[o] < 0.5 * yaw3[o]]
    out.append({"finding": "given the exact position, orientation is found much more precisely",
                "yes": bool(shaped and len(better) > 0.5 * len(shaped)),
                "figures": "median orientation error deg, 3 DoF -> position given: " +
                           ", ".join(f"{o} {yaw3[o]:.1f} -> {yaw1[o]:.1f}" for o in shaped if yaw1.get(o) is not None)})
    return out


def second_grasp_rows(results: Dict[str, list]) -> List[dict]:
    """Fig. 2.1: success of the grasp planned on the initial guess vs on the updated model."""
    rows = []
    for opt, res in results.items():
        by_obj: Dict[str, list] = {}
        for key, r in res:
            by_obj.setdefault(key.object, []).append(r["second_grasp"])
        for obj, recs in by_obj.items():
            rows.append({"optimizer": opt, "object": obj, "runs": len(recs),
                         "success_initial": float(np.mean([g["initial"]["success"] for g in recs])),
                         "success_updated": float(np.mean([g["updated"]["success"] for g in recs]))})
    return rows


def plot_errors(results: Dict[str, list], case: str, path) -> None:
    """Box plots of the errors after the touch, per object and optimiser (and the initial errors)."""
    plt = report._mpl()
    fields = [("position_error", 1e3, "position error (mm)"), ("orientation_error", 180 / np.pi,
                                                                "orientation error (deg, mod symmetry)")]
    if case == "pose_and_scale":
        fields.append(("size_error", 100, "relative size error (%)"))
    if case == "orientation":
        fields = fields[1:]
    objs = [o for o in OBJECTS if any(k.object == o for res in results.values() for k, _ in res)]
    series = ["initial"] + list(results)
    fig, axes = plt.subplots(len(fields), 1, figsize=(max(8, 1.6 * len(objs)), 3.2 * len(fields)), squeeze=False)
    for ax, (field, k, label) in zip(axes[:, 0], fields):
        data, pos, colors = [], [], []
        for i, o in enumerate(objs):
            for j, s in enumerate(series):
                res = results[series[1]] if s == "initial" else results[s]
                when = "before" if s == "initial" else "after"
                v = [r["cases"][case][when][field] for key, r in res if key.object == o]
                v = [k * x for x in v if x is not None]
                data.append(v if v else [np.nan])
                pos.append(i * (len(series) + 1) + j)
                colors.append(f"C{j}")
        bp = ax.boxplot(data, positions=pos, widths=0.8, patch_artist=True, showfliers=False)
        for patch, c in zip(bp["boxes"], colors):
            patch.set_facecolor(c)
        ax.set_xticks([i * (len(series) + 1) + (len(series) - 1) / 2 for i in range(len(objs))])
        ax.set_xticklabels(objs)
        ax.set_ylabel(label)
        ax.set_yscale("symlog", linthresh=1.0)
        ax.set_ylim(bottom=0.0)
    axes[0, 0].legend([plt.Rectangle((0, 0), 1, 1, color=f"C{j}") for j in range(len(series))], series,
                      ncol=len(series), fontsize=8)
    axes[0, 0].set_title(f"pub1, case {case}: errors after one touch (initial: before it)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_report(exp: Experiment, results: Dict[str, list], out) -> dict:
    out, md, summary = report._start(exp.name, out)
    md += [__doc__.strip().split("\n")[0], "",
           "Cells: median [25th, 75th percentile] over the runs; errors after the touch, then the initial ones.", ""]
    for case in CASES:
        rows = case_rows(results, case)
        summary[case] = rows
        plot_errors(results, case, out / f"errors_{case}.png")
        md += [f"## Case `{case}`", "", _markdown_case(rows, case), "", f"![errors](errors_{case}.png)", ""]
    f = findings(results)
    summary["findings"] = f
    md += ["## The thesis's findings", "", "| finding | yes/no | figures |", "|---|---|---|"]
    md += [f"| {x['finding']} | {'yes' if x['yes'] else 'no'} | {x['figures']} |" for x in f]
    g = second_grasp_rows(results)
    summary["second_grasp"] = g
    report._write_csv(g, out / "second_grasp.csv")
    md += ["", "## Fig. 2.1: the grasp planned on the initial guess vs on the updated model (3 DoF)", "",
           report._markdown(g, ("optimizer", "object", "runs", "success_initial", "success_updated"))]
    return report._finish(out, md, summary)


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
            world = World.single(o, pose=truth[:3], hand=ctx.hand)
            action = TouchPlanner(touch_model(o, ctx.hand), truth, models=models).plan().action
            wins.append(execute(world, models, action, truth[:3], ctx).success)
        rows.append({"object": o, "runs": len(truths), "success_on_truth": float(np.mean(wins))})
    report._write_csv(rows, Path(out) / "second_grasp_on_truth.csv")
    with open(Path(out) / "summary.md", "a") as f:
        f.write("\n\nThe same plan made on the true pose (the most a perfect update can give):\n\n" +
                report._markdown(rows, ("object", "runs", "success_on_truth")) + "\n")


def prepare_models(exp: Experiment, obj: str, ctx: RunContext) -> None:
    """One object's grasp models (Fig. 2.1's second grasp plans on them), built once."""
    ctx.models(obj)


register(Experiment("pub1", OBJECTS, 30, "what one touch tells about an object: four optimisers (Pub. I)",
                    _make_run, write_report, OPTIMIZERS, planned_on_truth, prepare_object=prepare_models))


# ---- variants: the continuous contact term, another hand ---------------------------------------
#: method -> (optimiser, contact term, hand or None for the run context's)
VARIANTS = {"pso/flags": ("pso", "flags", None), "pso/surface": ("pso", "surface", None),
            "descent/flags": ("descent", "flags", None), "descent/surface": ("descent", "surface", None),
            "pso/robotiq_3f": ("pso", "flags", "robotiq_3f")}


def variant_run(experiment: str, obj: str, run_index: int, seed: int, *, method: str, ctx: RunContext) -> dict:
    """pub1's 3-DoF problem of the same run index, with another contact term or hand."""
    optimizer, term, hand = VARIANTS[method]
    base = run_seed(ctx.seed, "pub1", obj, run_index)
    rec, _, _ = _one_case(obj, "pose", optimizer, np.random.default_rng(base), base, ctx, term, hand)
    return {"object": obj, "method": method, "cases": {"pose": rec}}


def _make_variant(exp: Experiment, method: str, ctx: RunContext):
    return f"{exp.name}/{method}", partial(variant_run, method=method, ctx=ctx)


def write_variants(exp: Experiment, results: Dict[str, list], out) -> dict:
    out, md, summary = report._start(exp.name, out)
    md += ["pub1's 3-DoF problems with the continuous contact term (surface) and with the Robotiq 3F hand.",
           "Cells: median [25th, 75th percentile]; the method column is optimiser/contact term or hand.", ""]
    rows = case_rows(results, "pose")
    summary["pose"] = rows
    md += [_markdown_case(rows, "pose").replace("| optimizer |", "| method |")]
    return report._finish(out, md, summary)


register(Experiment("pub1_variants", ("cube", "mug", "hammer/0"), 10,
                    "pub1 (3 DoF) with the continuous contact term and with another hand", _make_variant,
                    write_variants, tuple(VARIANTS)))
