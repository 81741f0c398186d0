"""One category decision and one tactile round, one core (targets: <= 250 ms and <= 300 ms median).

Decision (Eq. 4.1): a held-out mug's view registered against the 6 other mugs (prepared once, as
a robot would) and the plan for the task, per method: laplace (the thesis's) and part-aware (Eq.
4.1's candidates closed on the 6 registered models and re-ranked, the part check included) and warped
(the same check on the 6 models warped onto the view by CPD, the warps included). Round
(Eqs. 4.4-4.6): the update of the 6 models' poses and weights from one grasp's joint angles and the
next grasp's optimisation, with the thesis's task term and with the part-aware one.
Models and task grasps come from the cache (built by `bayesgrasp experiment pub5` / `pub6`, or
here on first use). Writes bench/results/category_decision.json.
Usage: OMP_NUM_THREADS=1 python bench/category_decision.py [--views 10]
"""
import argparse
import json
import os
import time

import numpy as np

from bayesgrasp.experiments.category_grasping import view
from bayesgrasp.loop.category import demonstrated, observe, register_models, training_models
from bayesgrasp.loop.context import RunContext
from bayesgrasp.loop.fusion_trial import FusionTrial, top_grasp
from bayesgrasp.models.tasks import task_rule
from bayesgrasp.planners.category import CategoryPlanner, CategorySettings
from bayesgrasp.planners.fusion import FusionSettings

METHODS = ("laplace", "part-aware", "warped")
TASK_TERMS = ("laplace", "part-aware")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--views", type=int, default=10)
    ap.add_argument("--task", default="handle")
    ap.add_argument("--out", default="bench/results/category_decision.json")
    a = ap.parse_args()
    ctx = RunContext()
    register_t = []
    plan_t = {m: [] for m in METHODS}
    update_t, replan_t = {t: [] for t in TASK_TERMS}, {t: [] for t in TASK_TERMS}
    rule = task_rule("mug", a.task)
    for k in range(a.views):
        obj = f"mug/{k % 7}"
        models = training_models("mug", [obj])
        grasps = demonstrated(models, rule, ctx)
        pose, eye = view(1000 + k)
        o = observe(obj, pose, eye, seed=k)
        register_models(o, models, seed=k)              # prepares the models once (not timed)
        t0 = time.perf_counter()
        regs = register_models(o, models, seed=k)
        register_t.append(time.perf_counter() - t0)
        for m in METHODS:
            if m == "part-aware":   # the models' worlds built once per process, as a robot would (not timed;
                # the warped method's worlds are of this view's warped shapes: built inside its timing)
                CategoryPlanner(ctx.hand, grasps, regs, cloud=o.cloud, settings=CategorySettings(method=m), seed=k,
                                rule=rule).plan()
            t1 = time.perf_counter()
            CategoryPlanner(ctx.hand, grasps, regs, cloud=o.cloud, settings=CategorySettings(method=m), seed=k,
                            rule=rule).plan()
            plan_t[m].append(time.perf_counter() - t1)
        for term in TASK_TERMS:
            trial = FusionTrial(obj, pose, ctx, eye_offset=eye, seed=k, settings=FusionSettings(task_term=term))
            _, planner = trial.start()
            g0 = planner.plan().action
            m = trial.measurement(top_grasp(trial.world, np.asarray(g0, float), trial.pose, trial.spread))
            t3 = time.perf_counter()
            planner.observe(g0, m)
            t4 = time.perf_counter()
            planner.plan()
            t5 = time.perf_counter()
            update_t[term].append(t4 - t3), replan_t[term].append(t5 - t4)
    med = lambda v: float(np.median(v))  # noqa: E731
    out = {"threads": os.environ.get("OMP_NUM_THREADS"), "views": a.views, "task": a.task,
           "registration_median_s": med(register_t)}
    for m in METHODS:
        out[m] = {"decision_median_s": med(np.add(register_t, plan_t[m])), "plan_median_s": med(plan_t[m])}
    for term in TASK_TERMS:
        out[f"round_{term}"] = {"round_median_s": med(np.add(update_t[term], replan_t[term])),
                                "update_median_s": med(update_t[term]), "fusion_plan_median_s": med(replan_t[term])}
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
