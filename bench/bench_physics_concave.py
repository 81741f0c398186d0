"""Lift test on the built-in concave objects: the convex decomposition (CoACD pieces, shape
'auto') against one tetrahedron per triangle (shape 'tetrahedra') on the same grasps.

Top grasps on a grid over each object are closed by the contact simulator; those where a hand
link starts inside the object's hull (Auto then needs a concave shape: the hand reaches into
the opening or the handle) and the hand does not start in collision are lift-tested with
both shapes, one thread. Prints per object: grasps, verdict agreement, lifted counts, and
lift tests per second (CPU time) of each shape; writes bench/results/physics_concave.json.

    BAYESGRASP_CORE_DIR=build/dev/bayesgrasp_core PYTHONPATH=python python bench/bench_physics_concave.py
"""
import argparse
import json
import os
import time

import numpy as np

from bayesgrasp import physics
from bayesgrasp.world import World


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--objects", default="mug,mug2,pitcher")
    ap.add_argument("--max-grasps", type=int, default=24, help="per object")
    ap.add_argument("--out", default="bench/results/physics_concave.json")
    a = ap.parse_args()
    rows = []
    for name in a.objects.split(","):
        w = World.single(name)
        obj = w.object
        lo, hi = obj.vertices.min(0), obj.vertices.max(0)
        xs = np.linspace(lo[0], hi[0], 9)
        ys = np.linspace(lo[1], hi[1], 7)
        yaws = np.radians([0.0, 45.0, 90.0, 135.0])
        g = np.array([[x, y, t] for x in xs for y in ys for t in yaws])
        b = w.grasp_batch(g, threads=1)
        t0 = time.process_time()
        dec = w.lift_tester()  # auto, with the CoACD pieces (decomposed or read from the cache)
        t_prep = time.process_time() - t0
        ok = ~np.asarray(b.collision_at_start, bool)
        poses, joints = b.hand_pose[ok], b.joint_angles[ok]
        r_all = dec.run_batch(poses, joints, threads=1)
        inside = np.array([s == "decomposition" for s in r_all.shape])
        idx = np.flatnonzero(inside)[: a.max_grasps]
        P, J = poses[idx], joints[idx]
        t0 = time.process_time()
        rd = dec.run_batch(P, J, threads=1)
        t_dec = time.process_time() - t0
        tets = physics.LiftTester(w.hand.path, w.vertices, w.faces, shape="tetrahedra", mu=w.mu,
                                  density=obj.density)
        t0 = time.process_time()
        rt = tets.run_batch(P, J, threads=1)
        t_tet = time.process_time() - t0
        hull = physics.LiftTester(w.hand.path, w.vertices, w.faces, shape="hull", mu=w.mu, density=obj.density)
        rh = hull.run_batch(P, J, threads=1)
        n = len(idx)
        agree = int(np.sum(rd.lifted == rt.lifted))
        row = dict(object=name, triangles=int(len(w.faces)), pieces=dec.num_pieces, grasps_grid=int(len(g)),
                   grasps_inside_hull=int(inside.sum()), tested=n, agree=agree,
                   lifted_decomposition=int(rd.lifted.sum()), lifted_tetrahedra=int(rt.lifted.sum()),
                   agree_hull=int(np.sum(rh.lifted == rt.lifted)),
                   median_abs_displacement_diff_m=float(np.median(np.abs(rd.displacement - rt.displacement))),
                   tests_per_s_decomposition=n / t_dec, tests_per_s_tetrahedra=n / t_tet,
                   decomposition_prep_s=t_prep)
        rows.append(row)
        print(f"{name}: {row['triangles']} triangles, {row['pieces']} pieces; {n} grasps into the hull: "
              f"verdicts agree {agree}/{n} (hull shape {row['agree_hull']}/{n}), lifted dec {row['lifted_decomposition']} "
              f"tet {row['lifted_tetrahedra']}; tests/s dec {row['tests_per_s_decomposition']:.1f} "
              f"tet {row['tests_per_s_tetrahedra']:.2f}", flush=True)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with open(a.out, "w") as f:
        json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
