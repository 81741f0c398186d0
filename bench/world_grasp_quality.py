"""Auto-grasp + epsilon throughput on the built-in mug, one core.

Times, on the same 256 seeded random top grasps around the mug (relative x, y in +-3 cm, yaw in
[0, pi), spread 0): the simulator alone (top_grasp_batch, 1 thread) and the simulator followed by
the GWS epsilon and volume of every grasp (World.grasp_batch, 1 thread). Medians of 5 runs.
Writes bench/results/world_grasp_quality.json.
"""
import json
import sys
import time
from pathlib import Path

import numpy as np

from bayesgrasp.world import World


def median_time(fn, reps=5):
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


def main(out_dir="bench/results"):
    world = World.single("mug")
    n = 256
    rng = np.random.default_rng(1)
    grasps = np.column_stack([rng.uniform(-0.03, 0.03, n), rng.uniform(-0.03, 0.03, n), rng.uniform(0, np.pi, n)])
    xy = world.to_world(grasps)
    t_sim = median_time(lambda: world.sim.top_grasp_batch(xy, spread=0.0, threads=1))
    t_all = median_time(lambda: world.grasp_batch(grasps, spread=0.0, threads=1))
    b = world.grasp_batch(grasps, spread=0.0, threads=1)
    counts = np.bincount(b.contacts.grasp[~b.contacts.on_table], minlength=n)
    res = {"triangles": int(len(world.faces)), "grasps": n,
           "sim_grasps_per_s": n / t_sim, "sim_plus_epsilon_grasps_per_s": n / t_all,
           "median_object_contacts": float(np.median(counts)),
           "force_closure_fraction": float(np.mean(b.epsilon > 0))}
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    Path(out_dir, "world_grasp_quality.json").write_text(json.dumps(res, indent=1))
    print(f"mug ({res['triangles']} triangles), {n} top grasps, one thread:")
    print(f"  auto-grasp:            {res['sim_grasps_per_s']:8.0f} grasps/s")
    print(f"  auto-grasp + epsilon:  {res['sim_plus_epsilon_grasps_per_s']:8.0f} grasps/s "
          f"(median {res['median_object_contacts']:.0f} object contacts, "
          f"{100 * res['force_closure_fraction']:.0f}% force closure)")


if __name__ == "__main__":
    main(*sys.argv[1:])
