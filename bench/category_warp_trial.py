"""The warped category method's variants beside part-aware on the same mug views (issue 53).

Each held-out mug (leave-one-out over the 7) is seen from ``--views`` seeded views (pub5's view
distribution); on each view and task every variant plans on the same registrations and the plan is
executed on the held-out mug. Success = lifted in the lift test with the contacts on the task's
parts (as pub5). Variants of `warped`:
  fc          force closure on the warped models decides, weights phi (the first trial's method)
  residual    the warps weighed by their fit (warp_residual_scale 2 mm)
  lift        the lift test on the warped models decides among the 4 best candidates
  lift+resid  both (the method's defaults)
Usage: OMP_NUM_THREADS=1 python bench/category_warp_trial.py [--views 2] [--out bench/results/warp_trial.json]
Progress on stderr; the results file is rewritten after each view (an interrupted run keeps them).
"""
import argparse
import json
import os
import sys
import time


from bayesgrasp.experiments.category_grasping import view
from bayesgrasp.experiments.category_stats import wilson
from bayesgrasp.loop.category import plan_and_execute, see
from bayesgrasp.loop.context import RunContext
from bayesgrasp.planners.category import CategorySettings

BIG = 1e9    # a residual scale under which every warp weighs its phi
VARIANTS = {
    "part-aware": CategorySettings(method="part-aware"),
    "warped fc": CategorySettings(method="warped", warp_lift_top=0, warp_residual_scale=BIG),
    "warped residual": CategorySettings(method="warped", warp_lift_top=0),
    "warped lift": CategorySettings(method="warped", warp_residual_scale=BIG),
    "warped lift+resid": CategorySettings(method="warped"),
}
TASKS = ("top", "side", "handle")


def run_view(obj: str, k: int, ctx: RunContext) -> dict:
    seed = 5300 + 10 * int(obj.split("/")[1]) + k
    pose, eye = view(seed)
    ep = see(obj, pose, "mug", exclude=(obj,), eye_offset=eye, seed=seed)
    out = {}
    for task in TASKS:
        for name, s in VARIANTS.items():
            t0 = time.perf_counter()
            r = plan_and_execute(ep, "mug", task, s.method, ctx, settings=s, seed=seed).to_dict()
            out[f"{task}/{name}"] = {"success": bool(r["success"]), "lifted": bool(r.get("lifted")),
                                     "task_ok": bool(r.get("task_ok")), "failure": r.get("failure"),
                                     "seconds": time.perf_counter() - t0}
    return {"object": obj, "view": k, "seed": seed, "results": out}


def table(rows: list) -> str:
    lines = ["| mug task | " + " | ".join(VARIANTS) + " |", "|---" * (len(VARIANTS) + 1) + "|"]
    for task in TASKS:
        cells = []
        for name in VARIANTS:
            r = [v["results"][f"{task}/{name}"] for v in rows]
            n, s = len(r), sum(x["success"] for x in r)
            lo, hi = wilson(s, n)
            slip = sum(x["task_ok"] and not x["lifted"] for x in r)
            wrong = sum(not x["task_ok"] for x in r)
            cells.append(f"{s}/{n} = {s / max(n, 1):.2f} [{lo:.2f}, {hi:.2f}]; {slip} / {wrong}")
        lines.append(f"| {task} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--views", type=int, default=2)
    ap.add_argument("--objects", nargs="*", default=[f"mug/{i}" for i in range(7)])
    ap.add_argument("--out", default="bench/results/warp_trial.json")
    a = ap.parse_args()
    ctx = RunContext()
    rows = []
    if os.path.exists(a.out):
        rows = json.load(open(a.out))["views"]
    done = {(r["object"], r["view"]) for r in rows}
    for obj in a.objects:
        for k in range(a.views):
            if (obj, k) in done:
                continue
            t0 = time.perf_counter()
            rows.append(run_view(obj, k, ctx))
            print(f"  {obj} view {k}: {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
            os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
            with open(a.out + ".tmp", "w") as f:
                json.dump({"views": rows}, f, indent=1)
            os.replace(a.out + ".tmp", a.out)
    print("Success = lifted with the contacts on the task's parts, 95% Wilson interval; slipped / wrong part.")
    print(table(rows))


if __name__ == "__main__":
    main()
