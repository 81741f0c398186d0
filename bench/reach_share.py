"""How many of pub2's grasps the shipped arm cannot reach, and what planning over the reachable
ones does to them (issue 57). One attempt per run: pub2's objects and hidden true poses (the
experiment's own seeds, run indices 0..runs-1), the stability planner (Eq. 3.1) on pub2's shipped
models, executed at the true pose with the lift test. Each run twice: the free-floating hand as the
thesis plans it, then the same run with the planner's reach set to the KUKA LBR4+ at --robot-base
(BH8 mounted by default). Every executed grasp is checked with the arm (its grasp, pre-grasp and
approach, links against the table and the object at the true pose).

    OMP_NUM_THREADS=1 python bench/reach_share.py [--runs 4] [--robot-base=-0.6,0,0,0]
"""
import argparse
import sys
import time

import numpy as np

from bayesgrasp.arm import Arm, ReachOptions, check_reach, default_mount
from bayesgrasp.experiments.pose_uncertainty import FIVE, true_pose
from bayesgrasp.experiments.runner import run_seed
from bayesgrasp.loop.context import RunContext
from bayesgrasp.loop.episode import EpisodeSettings, run_episode
from bayesgrasp.planners.reach import ActionReach
from bayesgrasp.world import World


def arm_verdict(arm, obj, pose, hand_pose, hand) -> str:
    """"" when the arm reaches the executed palm pose ``hand_pose`` (4x4, table frame), else the
    reason: its grasp, pre-grasp and approach, links against the table and ``obj`` at ``pose``."""
    world = World.single(obj, pose=list(pose), hand=hand)
    r = check_reach(arm, np.asarray(hand_pose, dtype=float), (world.vertices, world.faces), ReachOptions())
    return r.reason[0]


def shipped_arm(base: str, hand_model) -> Arm:
    """The shipped KUKA LBR4+ at ``base`` ("X,Y,Z,YAW", table frame), the hand on its default mount."""
    return Arm.load("kuka_lbr4", base=[float(v) for v in base.split(",")], mount=default_mount(hand_model))


def share_row(name: str, rows, label: str, oks=("success",)) -> str:
    """One table row: of the runs' ``label`` plannings, those whose executed grasp the arm reaches,
    then for each verdict in ``oks`` (``rows[i][label][ok]``) those it holds for and those it holds
    for that the arm reaches, and the median seconds."""
    n = len(rows)
    cells = [f"{sum(r[label]['reason'] == '' for r in rows)} of {n}"]
    for ok in oks:
        cells += [f"{sum(bool(r[label][ok]) for r in rows)} of {n}",
                  f"{sum(bool(r[label][ok]) and r[label]['reason'] == '' for r in rows)} of {n}"]
    sec = float(np.median([r[label]["seconds"] for r in rows]))
    return f"| {name} | {' | '.join(cells)} | {sec:.1f} |"


def unreachable_reasons(rows, label: str = "free") -> dict:
    """How many of the runs' ``label`` grasps are out of the arm's reach, by reason."""
    reasons = {}
    for r in rows:
        if r[label]["reason"]:
            reasons[r[label]["reason"]] = reasons.get(r[label]["reason"], 0) + 1
    return reasons


#: The two plannings of every run: (key, the table's name).
PLANNINGS = (("free", "free-floating hand (thesis)"), ("arm", "over the arm's reachable grasps"))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=4)
    p.add_argument("--robot-base", default="-0.6,0,0,0")
    a = p.parse_args(argv)
    ctx = RunContext()
    arm = shipped_arm(a.robot_base, ctx.hand_model)
    rows = []
    for obj in FIVE:
        models = ctx.family_models(obj)
        for k in range(a.runs):
            seed = run_seed(ctx.seed, "pub2", obj, k)
            pose = true_pose(seed)
            out = {"object": obj, "run": k}
            for label, reach in (("free", None), ("arm", ActionReach(arm, obj, ctx.hand))):
                t = time.perf_counter()
                r = run_episode(obj, pose, EpisodeSettings(method="stability", attempts=1), ctx, seed=seed,
                                models=models, reach=reach)
                att = r.attempts[0]
                out[label] = {"reason": arm_verdict(arm, obj, pose, att.execution.hand_pose, ctx.hand),
                              "success": bool(att.success),
                              "predicted": float(att.plan.predicted_stability), "seconds": time.perf_counter() - t}
            print(f"{obj} run {k}: free {out['free']}, arm {out['arm']}", file=sys.stderr, flush=True)
            rows.append(out)
    n = len(rows)
    print(f"pub2, first attempt of the stability planner, {n} runs ({a.runs} per object), KUKA LBR4+ at "
          f"{a.robot_base}")
    print("| planning | executed grasps the arm reaches | lifted | lifted and reachable | median s per plan+grasp |")
    print("|---|---|---|---|---|")
    for label, name in PLANNINGS:
        print(share_row(name, rows, label))
    print(f"\nwhy the free-floating grasps are out of reach: {unreachable_reasons(rows)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
