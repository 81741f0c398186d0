"""The lift test's solver stop level (issue 34): the same grasps lift-tested with every solver
iteration run (solver_residual 0) and with iterations ending once Bullet's least-squares residual is
below a level; per level the verdicts that change, the largest change of displacement and the
median seconds per test on one thread. Grasps: lift_torque_sweep.py's set (an 11 x 11 x 8 grid of
top grasps, the first ``--grasps`` with epsilon > 0) and as many grasps with the hand left open
(the object stays on the table: the lift test's early-exit case).

    OMP_NUM_THREADS=1 .venv/bin/python bench/lift_residual.py [--levels 1e-10,1e-8] [--grasps 40]
"""
import argparse
import sys
import time

import numpy as np

from bayesgrasp import physics
from bayesgrasp.world import World

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from lift_torque_sweep import grasp_set, pieces_of  # noqa: E402


def run(w, pieces, residual: float, H, Q):
    lt = physics.LiftTester(w.hand.path, w.vertices, w.faces, convex_pieces=pieces, mu=w.mu,
                            density=w.object.density, table=w.table, solver_residual=residual)
    t0 = time.process_time()
    r = lt.run_batch(H, Q, threads=1)
    return np.asarray(r.lifted), np.asarray(r.displacement), (time.process_time() - t0) / max(len(H), 1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--objects", default="cube,cylinder,mug,mug2,pitcher")
    ap.add_argument("--grasps", type=int, default=40)
    ap.add_argument("--levels", default="1e-10,1e-8")
    a = ap.parse_args()
    levels = [float(x) for x in a.levels.split(",")]
    print("| object | grasps | level | verdicts changed | max displacement change (mm) | ms/test, all iterations -> level |")
    print("|---|---|---|---|---|---|")
    for name in a.objects.split(","):
        w = World.single(name)
        H, Q = grasp_set(w, a.grasps)
        open_q = np.array([w.hand.open_joints(q[0]) for q in Q])  # the open hand at the same poses
        pieces = pieces_of(w)
        for kind, q in (("closed", Q), ("open", open_q)):
            base = run(w, pieces, 0.0, H, q)
            for lv in levels:
                r = run(w, pieces, lv, H, q)
                changed = int(np.sum(r[0] != base[0]))
                dd = np.abs(r[1] - base[1])
                dd = float(np.max(dd[np.isfinite(dd)], initial=0.0))
                print(f"| {name} ({kind} hand) | {len(H)} | {lv:g} | {changed} | {1e3 * dd:.3f} | "
                      f"{1e3 * base[2]:.1f} -> {1e3 * r[2]:.1f} |", flush=True)


if __name__ == "__main__":
    main()
