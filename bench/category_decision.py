"""One category decision and one tactile round, one core (targets: <= 250 ms and <= 300 ms median).

Decision (Eq. 4.1): a held-out mug's view registered against the 6 other mugs (prepared once, as
a robot would) and the laplace plan for the task. Round (Eqs. 4.4-4.6): the update of the 6
models' poses and weights from one grasp's joint angles and the next grasp's optimisation.
Models and task grasps come from the cache (built by `bayesgrasp experiment pub5` / `pub6`, or
here on first use). Writes bench/results/category_decision.json.
Usage: OMP_NUM_THREADS=1 python bench/category_decision.py [--views 10]
"""
import argparse
import json
import os
import time

import numpy as np

from bayesgrasp.experiments.category import demonstrated, observe, register_models, training_models
from bayesgrasp.experiments.category_grasping import view
from bayesgrasp.experiments.context import RunContext
from bayesgrasp.experiments.tactile_fusion import FusionTrial
from bayesgrasp.models.tasks import task_rule
from bayesgrasp.planners.category import CategoryPlanner, CategorySettings
from bayesgrasp.planners.fusion import FusionPlanner


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--views", type=int, default=10)
    ap.add_argument("--task", default="handle")
    ap.add_argument("--out", default="bench/results/category_decision.json")
    a = ap.parse_args()
    ctx = RunContext()
    register_t, plan_t, decision_t, update_t, replan_t = [], [], [], [], []
    for k in range(a.views):
        obj = f"mug/{k % 7}"
        models = training_models("mug", [obj])
        grasps = demonstrated(models, task_rule("mug", a.task), ctx)
        pose, eye = view(1000 + k)
        o = observe(obj, pose, eye, seed=k)
        register_models(o, models, seed=k)              # prepares the models once (not timed)
        t0 = time.perf_counter()
        regs = register_models(o, models, seed=k)
        t1 = time.perf_counter()
        CategoryPlanner(ctx.hand, grasps, regs, cloud=o.cloud, settings=CategorySettings(method="laplace"), seed=k).plan()
        t2 = time.perf_counter()
        register_t.append(t1 - t0), plan_t.append(t2 - t1), decision_t.append(t2 - t0)
        trial = FusionTrial(obj, pose, ctx, eye_offset=eye, seed=k)
        belief = trial.belief()
        planner = FusionPlanner(belief, trial.task_grasps, seed=k)
        g0 = planner.plan().action
        m = trial._execute(g0)["measurement"]
        t3 = time.perf_counter()
        belief.update(g0, m)
        t4 = time.perf_counter()
        planner.plan()
        t5 = time.perf_counter()
        update_t.append(t4 - t3), replan_t.append(t5 - t4)
    med = lambda v: float(np.median(v))  # noqa: E731
    out = {"threads": os.environ.get("OMP_NUM_THREADS"), "views": a.views, "task": a.task,
           "decision_median_s": med(decision_t), "registration_median_s": med(register_t), "plan_median_s": med(plan_t),
           "round_median_s": med(np.add(update_t, replan_t)), "update_median_s": med(update_t),
           "fusion_plan_median_s": med(replan_t)}
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
