"""Top grasps against mesh size, one thread (issue 34).

A 6 x 4 x 10 cm box whose faces are n x n grids (12 n^2 triangles, n = 1 ... 72: 12 to 62,208
triangles; a finger resting on a face is parallel to many triangles at once) and the built-in
mug. The same 256 seeded top grasps (x, y within +-2 cm, yaw in [0, pi), spread 0) on each,
timed with the simulator's default tie tolerance and with tie_tolerance = 0 (FCL's own
traversal, the code before), medians of 3 runs, in the same process. Also reports how many
grasps give the same joint angles (to 1e-9 rad) both ways. Writes bench/results/sim_mesh_size.json.

    .venv/bin/python bench/sim_mesh_size.py [OUT_DIR]
"""
import json
import sys
import time
from pathlib import Path

import numpy as np

from bayesgrasp.hand import Hand
from bayesgrasp.objects import library, primitives
from bayesgrasp.sim import GraspSimulator


def median_rate(fn, n, reps=3):
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return n / float(np.median(ts))


def main(out_dir="bench/results"):
    hand = Hand.load("barrett_bh8")
    n_grasps = 256
    rng = np.random.default_rng(4)
    g = np.column_stack([rng.uniform(-0.02, 0.02, n_grasps), rng.uniform(-0.02, 0.02, n_grasps),
                         rng.uniform(0, np.pi, n_grasps)])
    meshes = [(f"box n={n}", *primitives.grid_box((0, 0, 0.05), (0.03, 0.02, 0.05), n)) for n in (1, 9, 18, 36, 72)]
    mug = library.builtin("mug")
    meshes.append(("mug", np.asarray(mug.vertices), np.asarray(mug.faces)))
    rows = []
    for name, V, F in meshes:
        row = {"mesh": name, "triangles": int(len(F))}
        joints = {}
        for label, tie in (("tie", None), ("fcl", 0.0)):
            sim = GraspSimulator(hand, V, F) if tie is None else GraspSimulator(hand, V, F, tie_tolerance=tie)
            row[f"{label}_grasps_per_s"] = median_rate(lambda: sim.top_grasp_batch(g, spread=0.0, threads=1), n_grasps)
            joints[label] = np.asarray(sim.top_grasp_batch(g, spread=0.0, threads=1).joint_angles)
        row["same_joints"] = int(np.sum(np.all(np.abs(joints["tie"] - joints["fcl"]) <= 1e-9, axis=1)))
        row["max_joint_difference_rad"] = float(np.abs(joints["tie"] - joints["fcl"]).max())
        rows.append(row)
        print(f"{name:10s} {row['triangles']:7d} triangles: {row['tie_grasps_per_s']:7.0f} grasps/s "
              f"(FCL's traversal {row['fcl_grasps_per_s']:7.0f}/s), same joints {row['same_joints']}/{n_grasps}, "
              f"max difference {row['max_joint_difference_rad']:.2e} rad", flush=True)
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    Path(out_dir, "sim_mesh_size.json").write_text(json.dumps({"grasps": n_grasps, "rows": rows}, indent=1))


if __name__ == "__main__":
    main(*sys.argv[1:])
