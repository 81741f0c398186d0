"""How many of a fixed set of force-closure top grasps the lift test holds as the finger torque
rises, per solver setting (issue 30's metamorphic check: the held count must not fall as the
torque rises, with a slack of 2 in 80).

The grasp set: an 11 x 11 x 8 grid of top grasps (x, y in +-5 cm, 8 yaws) in the object frame, the
first ``--grasps`` with epsilon > 0, closed once by the contact simulator; each setting lift-tests
the same closed grasps at every torque. One thread; seconds per setting and torque are printed.
Usage: python bench/lift_torque_sweep.py [--object cube] [--grasps 80]
       [--settings default,iter50,iter100,iter200,dt/3,dt/3+iter100]
"""
import argparse
import json
import time

import numpy as np

from bayesgrasp import physics
from bayesgrasp.world import World

TORQUES = (0.25, 0.5, 1.0, 1.5, 2.0, 3.0)
SETTINGS = {"default": {}, "iter50": {"solver_iterations": 50}, "iter100": {"solver_iterations": 100},
            "iter200": {"solver_iterations": 200}, "dt/3": {"time_step": 1 / 1440},
            "dt/3+iter100": {"time_step": 1 / 1440, "solver_iterations": 100}}


def grasp_set(world: World, n: int):
    g = np.linspace(-0.05, 0.05, 11)
    X, Y, T = np.meshgrid(g, g, np.linspace(-np.pi / 2, np.pi / 2, 8, endpoint=False), indexing="ij")
    b = world.grasp_batch(np.c_[X.ravel(), Y.ravel(), T.ravel()], threads=1)
    idx = np.flatnonzero(b.epsilon > 0)[:n]
    return b.hand_pose[idx], b.joint_angles[idx]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--object", default="cube")
    ap.add_argument("--grasps", type=int, default=80)
    ap.add_argument("--settings", default="default,iter100,dt/3")
    a = ap.parse_args()
    w = World.single(a.object)
    H, Q = grasp_set(w, a.grasps)
    pieces = None
    if physics.is_concave(w.vertices, w.faces, w.hand.path):
        o, T = w.object, w.scene.object_pose(0)
        pieces = [p @ T[:3, :3].T + T[:3, 3] for p in physics.convex_decomposition(o.vertices, o.faces)]
    out = {"object": a.object, "grasps": len(H), "torques": TORQUES, "held": {}, "seconds": {}}
    for name in a.settings.split(","):
        held, secs = [], []
        for t in TORQUES:
            lt = physics.LiftTester(w.hand.path, w.vertices, w.faces, convex_pieces=pieces, mu=w.mu,
                                    density=w.object.density, table=w.table, finger_torque=t, **SETTINGS[name])
            t0 = time.perf_counter()
            held.append(int(np.sum(lt.run_batch(H, Q, threads=1).lifted)))
            secs.append(round(time.perf_counter() - t0, 2))
        out["held"][name], out["seconds"][name] = held, secs
        print(f"{name:>14}: held {held} of {len(H)} at {list(TORQUES)} N m ({sum(secs):.0f} s)", flush=True)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
