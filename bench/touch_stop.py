"""One touch's estimate with and without the stop level (issue 34): PSO, a 2,000-evaluation budget,
one thread. For each object, `--pairs` seeded (truth, guess) pairs in 3 DoF (the truth within
+-1 cm, the guess 1.5-3 cm and up to 20 degrees off; pub1 draws wider errors), or in 4 DoF with
``--size`` (the true scale uniform in [0.9, 1.1], guessed 1). Per stop level: the median CPU time
of the search, the evaluations it spent and the median position, yaw and scale errors, the same
pairs and seeds for every level. One model per object serves all pairs (its per-scale simulators
are built by the first 4-DoF search and kept).

    OMP_NUM_THREADS=1 .venv/bin/python bench/touch_stop.py [--pairs 20] [--size] [--stops 0,0.001,0.003]"""
import argparse
import json
import sys

import numpy as np

from bayesgrasp.planners import touch as T


def pairs(n: int, seed: int):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        truth = np.array([*rng.uniform(-0.01, 0.01, 2), rng.uniform(-np.pi, np.pi)])
        r, a = rng.uniform(0.015, 0.03), rng.uniform(-np.pi, np.pi)
        guess = truth + np.array([r * np.cos(a), r * np.sin(a), np.deg2rad(rng.uniform(-20, 20))])
        yield truth, guess, rng.uniform(0.9, 1.1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pairs", type=int, default=10)
    ap.add_argument("--objects", default="cube,cylinder,mug")
    ap.add_argument("--stops", default="0,0.01,0.05")
    ap.add_argument("--size", action="store_true", help="4 DoF: the scale is unknown too")
    ap.add_argument("--json", default=None, help="write the rows here too")
    a = ap.parse_args()
    stops = [float(s) for s in a.stops.split(",")]
    rows = []
    for obj in a.objects.split(","):
        model = T.TouchModel(obj)
        order = T.symmetry_order(obj)
        per = {s: {"cpu": [], "evals": [], "pos": [], "yaw": [], "scale": []} for s in stops}
        for k, (truth, guess, scale) in enumerate(pairs(a.pairs, seed=7)):
            scale = scale if a.size else 1.0
            world = T.touch_world(obj, truth, scale)
            grasp = T.top_grasp(*guess)
            m = T.read(world, grasp)
            if m.contact_count == 0:
                continue
            for s in stops:
                r = model.estimate(grasp, m, guess, optimizer="pso", budget=2000, seed=k, stop_fitness=s,
                                   unknowns="pose_and_scale" if a.size else "pose")
                d = per[s]
                d["cpu"].append(1e3 * r.cpu_seconds)
                d["evals"].append(r.evaluations)
                d["pos"].append(1e3 * np.hypot(*(np.asarray(r.state[:2]) - truth[:2])))
                e = T.orientation_error(r.state[2], truth[2], order)
                d["yaw"].append(np.nan if e is None else np.rad2deg(e))
                d["scale"].append(100 * abs(r.state[3] - scale) / scale)
            print(f"{obj}: pair {k + 1}/{a.pairs}", file=sys.stderr)
        for s in stops:
            d = per[s]
            rows.append({"object": obj, "dof": 4 if a.size else 3, "stop_fitness": s, "pairs": len(d["cpu"]),
                         "cpu_ms_median": float(np.median(d["cpu"])),
                         "evaluations_median": float(np.median(d["evals"])),
                         "position_error_mm_median": float(np.median(d["pos"])),
                         "scale_error_pct_median": float(np.median(d["scale"])),
                         "yaw_error_deg_median": float(np.nanmedian(d["yaw"])) if np.isfinite(d["yaw"]).any() else None})
    print("| object | DoF | stop_fitness | pairs | CPU ms (median) | evaluations (median) | position error mm | "
          "yaw error deg | scale error % |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        yaw = "undefined" if r["yaw_error_deg_median"] is None else f"{r['yaw_error_deg_median']:.1f}"
        print(f"| {r['object']} | {r['dof']} | {r['stop_fitness']:g} | {r['pairs']} | {r['cpu_ms_median']:.0f} | "
              f"{r['evaluations_median']:.0f} | {r['position_error_mm_median']:.1f} | {yaw} | "
              f"{r['scale_error_pct_median']:.1f} |")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
