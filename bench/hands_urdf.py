"""Top grasps per second with hands from URDF (issue 31), one core: the BH8 from its hand file and
from its URDF + sidecar (the same model after conversion), and the parallel-jaw gripper (prismatic
jaws, convex mesh fingers), on the built-in mug (2,322 triangles), the same grasp set for every
hand. Also the Robotiq 3F both ways, the 2F-85-like four-bar gripper (issue 55: a linkage) and the
Allegro-like hand (four fingers of three joints, one motor each, a rolled thumb), and the jaw
with the hand offset along its pads' width about the mug's axis (0, 5, 15, 30 mm). Medians of
repeated batches, ratios in the same run.

    OMP_NUM_THREADS=1 python bench/hands_urdf.py [--grasps 256] [--repeats 7] [--out bench/results/hands_urdf.json]
"""
import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from bayesgrasp.hand import Hand
from bayesgrasp.objects import load_object
from bayesgrasp.sim import GraspSimulator

HANDS = {"bh8_json": "barrett_bh8", "bh8_urdf": "barrett_bh8.urdf", "robotiq_json": "robotiq_3f",
         "robotiq_urdf": "robotiq_3f.urdf", "parallel_jaw_urdf": "parallel_jaw.urdf",
         "robotiq_2f85_urdf": "robotiq_2f85.urdf", "allegro_like_urdf": "allegro_like.urdf"}


def rate(hand: Hand, mug, xyyaw: np.ndarray, repeats: int) -> dict:
    """Grasps/s of one-thread top-grasp batches (load and simulator set-up excluded)."""
    sim = GraspSimulator(hand, mug.vertices, mug.faces)
    spread = float(hand.core.spread_default)
    sim.top_grasp_batch(xyyaw[:16], spread=spread)   # warm-up
    times, touching = [], 0
    for _ in range(repeats):
        t = time.perf_counter()
        b = sim.top_grasp_batch(xyyaw, spread=spread, threads=1)
        times.append(time.perf_counter() - t)
    off = np.asarray(b.contacts.offsets)
    touching = int(np.sum(np.diff(off) > 0))
    return {"grasps_per_s": len(xyyaw) / float(np.median(times)), "median_s": float(np.median(times)),
            "queries_per_grasp": float(np.mean(b.distance_queries)), "grasps_touching": touching}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--grasps", type=int, default=256)
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--out", default="bench/results/hands_urdf.json")
    a = p.parse_args(argv)
    mug = load_object("mug")
    lo, hi = np.asarray(mug.bounds)
    rng = np.random.default_rng(0)
    xyyaw = np.c_[rng.uniform(lo[0], hi[0], a.grasps), rng.uniform(lo[1], hi[1], a.grasps),
                  rng.uniform(-np.pi, np.pi, a.grasps)]
    out = {"object": "mug", "triangles": int(len(mug.faces)), "grasps": a.grasps, "repeats": a.repeats, "hands": {}}
    for key, name in HANDS.items():
        t = time.perf_counter()
        hand = Hand.load(name)
        r = rate(hand, mug, xyyaw, a.repeats)
        r["load_s"] = time.perf_counter() - t - r["median_s"] * a.repeats
        out["hands"][key] = r
        print(f"{key:18s} {r['grasps_per_s']:8.0f} grasps/s  {r['queries_per_grasp']:5.1f} queries/grasp  "
              f"{r['grasps_touching']}/{a.grasps} touch", file=sys.stderr)
    # the jaw with the hand offset along its pads' width about the mug's axis (where its time goes)
    jaw = Hand.load(HANDS["parallel_jaw_urdf"])
    yaw = rng.uniform(-np.pi, np.pi, a.grasps)
    out["parallel_jaw_offsets"] = {}
    for off in (0.0, 0.005, 0.015, 0.03):
        r = rate(jaw, mug, np.c_[off * np.cos(yaw), off * np.sin(yaw), yaw], a.repeats)
        out["parallel_jaw_offsets"][f"{off * 1000:.0f}mm"] = r
        print(f"jaw offset {off * 1000:4.0f} mm  {r['grasps_per_s']:8.0f} grasps/s  {r['queries_per_grasp']:6.1f} queries/grasp",
              file=sys.stderr)
    h = out["hands"]
    out["ratio_bh8_urdf_to_json"] = h["bh8_urdf"]["grasps_per_s"] / h["bh8_json"]["grasps_per_s"]
    out["ratio_robotiq_urdf_to_json"] = h["robotiq_urdf"]["grasps_per_s"] / h["robotiq_json"]["grasps_per_s"]
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(out, indent=1))
    print(json.dumps({k: v for k, v in out.items() if k.startswith("ratio")}), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
