"""How many of pub5's category task grasps the shipped arm cannot reach, and what planning over the
reachable ones does to them (issue 57; pub2's are bench/reach_share.py). Pub. V's experiment
(experiments/category_grasping.py): each held-out mug seen once from its run's table pose and camera
(the experiment's own seeds, run indices 0..runs-1, leave-one-out training), Eq. 4.1 planned for each
task with --method, executed at the true pose with the lift test. Each task twice on the same view and
registrations: the free-floating hand as the thesis plans it, then with the planner's reach set to
the KUKA LBR4+ at --robot-base against the table (as ``category --robot`` plans:
loop/reach.py's table_reach; the new object's mesh is unknown to the planner). Every executed grasp
is checked with the arm (grasp, pre-grasp and approach, links against the table and the object at
the true pose).

    OMP_NUM_THREADS=1 python bench/reach_share_pub5.py [--objects mug/0,...] [--tasks handle,top]
        [--runs 1] [--robot-base=-0.6,0,0,0]
"""
import argparse
import sys
import time

from reach_share import PLANNINGS, arm_verdict, share_row, shipped_arm, unreachable_reasons

from bayesgrasp.experiments.category_grasping import view
from bayesgrasp.experiments.runner import run_seed
from bayesgrasp.loop.category import plan_and_execute, see
from bayesgrasp.loop.context import RunContext
from bayesgrasp.loop.reach import table_reach


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--objects", default=",".join(f"mug/{i}" for i in range(7)))
    p.add_argument("--tasks", default="handle,top")
    p.add_argument("--method", default="laplace")
    p.add_argument("--runs", type=int, default=1)
    p.add_argument("--robot-base", default="-0.6,0,0,0")
    a = p.parse_args(argv)
    ctx = RunContext()
    arm = shipped_arm(a.robot_base, ctx.hand_model)
    objects, tasks = a.objects.split(","), a.tasks.split(",")
    rows = {t: [] for t in tasks}
    for obj in objects:
        cat = obj.split("/")[0]
        for k in range(a.runs):
            seed = run_seed(ctx.seed, "pub5", obj, k)
            pose, eye = view(seed)
            ep = see(obj, pose, cat, exclude=(obj,), eye_offset=eye, seed=seed % (2**31))
            for task in tasks:
                out = {"object": obj, "run": k}
                for label, reach in (("free", None), ("arm", table_reach(arm))):
                    t = time.perf_counter()
                    o = plan_and_execute(ep, cat, task, a.method, ctx, seed=seed % (2**31), reach=reach).outcome
                    reason = (arm_verdict(arm, obj, pose, o.hand_pose, ctx.hand) if o.executed
                              else f"not executed: {o.reason}")
                    out[label] = {"reason": reason, "lifted": bool(o.lifted), "success": bool(o.success),
                                  "failure": o.failure, "seconds": time.perf_counter() - t}
                print(f"{obj} run {k} {task}: free {out['free']}, arm {out['arm']}", file=sys.stderr, flush=True)
                rows[task].append(out)
    print(f"pub5 ({a.method}), {len(objects)} held-out objects x {a.runs} view(s), KUKA LBR4+ at {a.robot_base}")
    print("| task | planning | executed grasps the arm reaches | lifted | lifted and reachable | success "
          "(lifted, task's parts) | success and reachable | median s per plan+grasp |")
    print("|---|---|---|---|---|---|---|---|")
    for task in tasks:
        for label, name in PLANNINGS:
            print(f"| {task} " + share_row(name, rows[task], label, oks=("lifted", "success")))
    for task in tasks:
        print(f"\n{task}: why the free-floating grasps are out of reach: {unreachable_reasons(rows[task])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
