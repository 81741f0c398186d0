"""One planning decision against the belief's size (issue 34), one thread: the stability and the
exploration planners at 500 / 5,000 / 50,000 particles, searching the whole belief
(plan_particles=0) and a compressed one (plan_particles=500, the default: at most 500 systematic
draws, duplicates merged). Beliefs: the initial one (uniform, +-4 cm / +-45 deg) and the one after
a failed first grasp from the real loop, as in bench/planner_decision.py. Quality: both planners
share the seed, so their full beliefs are the same; each chosen action is scored on that full
belief - expected stability (Eq. 3.1) for the stability planner, the expected posterior weight
entropy (Eq. 3.2, 50 samples, one seed) for an exploration plan - and the compressed plan's score is
compared with the whole-belief plan's.

    OMP_NUM_THREADS=1 .venv/bin/python bench/planner_belief_size.py [--objects cube,mug] [--reps 3]
"""
import argparse
import json
import sys
import time

import numpy as np

from bayesgrasp.planners import ExplorationPlanner, PlannerSettings, StabilityPlanner, get_models

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from planner_decision import problem  # noqa: E402

SIZES = (500, 5000, 50000)


def planner(cls, models, est, seed, n, k, observe):
    p = cls(models, est, PlannerSettings(threads=1, n_particles=n, plan_particles=k), seed=seed)
    if observe is not None:
        p.observe(*observe)
    return p


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--objects", default="cube,mug")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    rng = np.random.default_rng(0)
    rows = []   # (object, planner, belief, N, k, seconds, score)
    for obj in a.objects.split(","):
        models = get_models(obj)
        for r in range(a.reps):
            est, obs = problem(obj, models, rng, r)
            for belief, observe in (("initial", None), ("after a failed grasp", obs)):
                for n in SIZES:
                    for name, cls in (("stability", StabilityPlanner), ("explore", ExplorationPlanner)):
                        plans = {}
                        for k in (0, 500):
                            p = planner(cls, models, est, r, n, k, observe)
                            t0 = time.process_time()
                            plan = p.plan()
                            plans[k] = (time.process_time() - t0, plan, p)
                        judge = plans[0][2]   # the full belief (the same for both)
                        for k, (sec, plan, _) in plans.items():
                            if plan.kind == "explore":
                                score = float(judge.expected_entropy(plan.action[None, :], seed=99)[0][0])
                            else:
                                score = judge.expected_stability(plan.action)
                            rows.append((obj, name, belief, n, k, sec, plan.kind, score))
                    print(f"{obj} rep {r + 1}/{a.reps}, {belief}, N = {n}", file=sys.stderr, flush=True)
    print("| planner | belief | N | ms, whole belief | ms, compressed (500) | same kind of plan | "
          "score, whole -> compressed (median) |")
    print("|---|---|---|---|---|---|---|")
    out = []
    for name in ("stability", "explore"):
        for belief in ("initial", "after a failed grasp"):
            for n in SIZES:
                sel = [x for x in rows if x[1] == name and x[2] == belief and x[3] == n]
                whole = [x for x in sel if x[4] == 0]
                comp = [x for x in sel if x[4] == 500]
                same = sum(w[6] == c[6] for w, c in zip(whole, comp))
                sw = np.median([x[7] for x in whole])
                sc = np.median([x[7] for x in comp])
                tw, tc = 1e3 * np.median([x[5] for x in whole]), 1e3 * np.median([x[5] for x in comp])
                out.append({"planner": name, "belief": belief, "N": n, "ms_whole": tw, "ms_compressed": tc,
                            "same_kind": same, "decisions": len(whole), "score_whole": sw, "score_compressed": sc})
                print(f"| {name} | {belief} | {n:,} | {tw:.0f} | {tc:.0f} | {same} of {len(whole)} | "
                      f"{sw:.3f} -> {sc:.3f} |")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"rows": out, "raw": rows}, f, indent=1, default=str)


if __name__ == "__main__":
    main()
