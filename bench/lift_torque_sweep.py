"""Issue 30: how many of a fixed set of force-closure top grasps the lift test holds as the
finger torque rises, before and after the fixes, and at the hand's own (published) strength.

The grasp set: an 11 x 11 x 8 grid of top grasps (x, y in +-5 cm, 8 yaws) in the object frame, the
first ``--grasps`` with epsilon > 0, closed once by the contact simulator; every setting lift-tests
the same closed grasps.

Settings:
  before   the lift test as it was: 20 solver iterations, a rigid worm lock (no backlash), no drive
           inertia, verdict "moved < 2 cm in the palm frame after the squeeze";
  after    the defaults now (100 iterations, 0.01 rad backlash, 1e-3 kg m^2 drive inertia),
           verdict "rose >= 8 cm and moved < 2 cm in the palm frame through the shake and hold".
Columns: each torque of ``--torques`` (N m, every driven joint) and ``hand``: the hand file's
torques (the BH8: 1.467 N m proximal, 1.1 N m distal; "before" used 0.5 N m there).
``--explain`` traces the grasps held at the lowest torque and dropped at the highest under
"before": how far they came up, and the largest contact force during the squeeze and lift.

Usage: python bench/lift_torque_sweep.py [--objects cube,cylinder,mug,mug2,pitcher] [--grasps 80]
       [--torques 0.25,0.5,1,2,3] [--settings before,after] [--explain] [--out FILE.json]
"""
import argparse
import json
import sys
import time

import numpy as np

from bayesgrasp import physics
from bayesgrasp.world import World

SETTINGS = {"before": {"solver_iterations": 20, "worm_backlash": 0.0, "drive_inertia": 0.0}, "after": {}}
BEFORE_HAND_TORQUE = 0.5  # N m, the old LiftOptions default


def top_grid() -> np.ndarray:
    """(968, 3) top grasps (x, y, yaw): x, y in +-5 cm (11 each), 8 yaws."""
    g = np.linspace(-0.05, 0.05, 11)
    X, Y, T = np.meshgrid(g, g, np.linspace(-np.pi / 2, np.pi / 2, 8, endpoint=False), indexing="ij")
    return np.c_[X.ravel(), Y.ravel(), T.ravel()]


def grid_grasps(world: World, threads: int = 0):
    """The top_grid() grasps, closed."""
    return world.grasp_batch(top_grid(), threads=threads)


def grasp_set(world: World, n: int):
    b = grid_grasps(world)
    idx = np.flatnonzero(b.epsilon > 0)[:n]
    return b.hand_pose[idx], b.joint_angles[idx]


def pieces_of(w: World):
    if not physics.is_concave(w.vertices, w.faces, w.hand.path):
        return None
    o, T = w.object, w.scene.object_pose(0)
    return [p @ T[:3, :3].T + T[:3, 3] for p in physics.convex_decomposition(o.vertices, o.faces)]


SUCCESS = physics.make_options().success_distance  # 2 cm


def verdict(setting: str, r) -> np.ndarray:
    if setting == "before":  # the old rule: < 2 cm in the palm frame after the squeeze
        return np.asarray(r.finite) & (np.asarray(r.displacement) < SUCCESS)
    return np.asarray(r.lifted)


def tester(w, pieces, setting, torque):
    opts = dict(SETTINGS[setting], mu=w.mu, density=w.object.density, table=w.table)
    if torque == "hand":
        opts["finger_torque"] = BEFORE_HAND_TORQUE if setting == "before" else 0.0
    else:
        opts["finger_torque"] = float(torque)
    return physics.LiftTester(w.hand.path, w.vertices, w.faces, convex_pieces=pieces, **opts)


def explain(w, pieces, H, Q, lo: float, hi: float):
    """Grasps held at `lo` and dropped at `hi` under "before": how far they rose, peak forces."""
    held = {}
    for t in (lo, hi):
        lt = tester(w, pieces, "before", t)
        held[t] = (verdict("before", lt.run_batch(H, Q, threads=0)), lt)
    idx = np.flatnonzero(held[lo][0] & ~held[hi][0])
    lt = held[hi][1]
    rose, peak = [], []
    for i in idx:
        r = lt.run(H[i], Q[i], trace_every=6)
        rose.append(r.height_gain)
        peak.append(float(np.max(r.trace.contact_force, initial=0.0)))
    rose, peak = np.asarray(rose), np.asarray(peak)
    return {"dropped_only_at_high": int(len(idx)), "came_up_8cm": int(np.sum(rose >= 0.08)),
            "height_gain_median_m": float(np.median(rose)) if len(idx) else None,
            "peak_contact_force_median_n": float(np.median(peak)) if len(idx) else None,
            "peak_contact_force_max_n": float(np.max(peak)) if len(idx) else None}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--objects", default="cube,cylinder,mug,mug2,pitcher")
    ap.add_argument("--grasps", type=int, default=80)
    ap.add_argument("--torques", default="0.25,0.5,1,2,3")
    ap.add_argument("--settings", default="before,after")
    ap.add_argument("--explain", action="store_true")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    torques = [float(t) for t in a.torques.split(",")] + ["hand"]
    out = {"grasps": a.grasps, "torques": torques, "objects": {}}
    for name in a.objects.split(","):
        w = World.single(name)
        H, Q = grasp_set(w, a.grasps)
        pieces = pieces_of(w)
        res = {"grasps": int(len(H)), "held": {}, "seconds": {}}
        for s in a.settings.split(","):
            held, secs = [], []
            for t in torques:
                lt = tester(w, pieces, s, t)
                t0 = time.perf_counter()
                held.append(int(verdict(s, lt.run_batch(H, Q, threads=0)).sum()))
                secs.append(round(time.perf_counter() - t0, 2))
            res["held"][s], res["seconds"][s] = held, secs
            print(f"{name:>9} {s:>7}: held {held} of {len(H)} at {torques} ({sum(secs):.0f} s)", file=sys.stderr,
                  flush=True)
        if a.explain:
            res["explain_before"] = explain(w, pieces, H, Q, torques[0], torques[-2])
            print(f"{name:>9} explain: {res['explain_before']}", file=sys.stderr, flush=True)
        out["objects"][name] = res
    text = json.dumps(out, indent=1)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    print(text)


if __name__ == "__main__":
    main()
