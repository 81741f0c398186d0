"""Our lift test's verdicts on exported grasps (bench/lift_heldset.py) again, with whatever core is
loaded (e.g. an older build: BAYESGRASP_CORE_DIR), and their agreement with a MuJoCo replay
(bench/lift_mujoco.py's JSON): before/after figures for a change of the lift test on the same grasps.

    BAYESGRASP_CORE_DIR=/path/to/old/bayesgrasp_core PYTHONPATH=python python bench/lift_reverdict.py \\
        bench/results/heldset bench/results/lift_mujoco.json
"""
import argparse
import glob
import json
import os

import numpy as np

from bayesgrasp import physics


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("heldset")
    ap.add_argument("mujoco_json")
    a = ap.parse_args()
    with open(a.mujoco_json) as f:
        mj = {(r["object"], r["source"], r["grasp"]): r for r in json.load(f)}
    n = agree = held = 0
    for path in sorted(glob.glob(os.path.join(a.heldset, "*.npz"))):
        with np.load(path, allow_pickle=False) as z:
            pieces = [z[f"piece_{i}"] for i in range(int(z["num_pieces"]))] or None
            t = physics.LiftTester(None, z["V"], z["F"], convex_pieces=pieces, mu=float(z["mu"]),
                                   density=float(z["density"]))
            r = t.run_batch(z["hand_pose"], z["joints"], threads=0)
            for g in range(len(r)):
                m = mj.get((str(z["name"]), str(z["source"][g]), g))
                if m is None:
                    continue
                n += 1
                held += bool(r.lifted[g])
                agree += bool(r.lifted[g]) == m["mujoco_lifted"]
    print(f"verdict agreement with MuJoCo: {agree}/{n} = {agree / max(1, n):.3f}; held {held}/{n}")


if __name__ == "__main__":
    main()
