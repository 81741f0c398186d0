"""Registration from depth images against from the simulated camera, on the same views.

Each of the benchmark's library objects (bench/vision_make_views.py's MODELS) stands at a random
table pose and is seen from N random viewpoints (azimuth any, elevation 30-60 deg, 0.6-0.8 m).
Each view is registered against all the models three ways:
  sim       our simulated camera (structured-light noise) and PCL table segmentation, as before;
  depth     a Kinect-like depth scan (bayesgrasp.io.scan: Gaussian depth noise growing with z^2,
            grazing pixels dropped), quantised to a 16-bit mm PNG, back-projected and cut out
            by bayesgrasp.io with the camera-to-table extrinsic;
  ransac    the same depth image, the table found by RANSAC (no extrinsic); the pose is mapped
            back to the world through the extrinsic for scoring.
A view succeeds when the true model has the highest weight and its pose is within 1 cm and
10 deg (about the axis of revolution ignored for bodies of revolution).

Usage: python bench/camera_registration.py [--views-per-object 20] [--out bench/results/camera_registration.json]"""
import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from vision_common import errors  # noqa: E402
from vision_make_views import MODELS, REVOLUTION  # noqa: E402

from bayesgrasp.io import KINECT, cloud_from_depth, look_at, render_scan, to_table_frame  # noqa: E402
from bayesgrasp.objects import load_object  # noqa: E402
from bayesgrasp.vision import Camera, Registrar, segment_table  # noqa: E402


def views(objs, per_object, rng):
    for i, o in enumerate(objs):
        for _ in range(per_object):
            x, y, yaw = rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rng.uniform(-np.pi, np.pi)
            T = np.eye(4)
            T[:3, :3] = [[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]]
            T[:3, 3] = [x, y, 0]
            az, el, dist = rng.uniform(-np.pi, np.pi), np.radians(rng.uniform(30, 60)), rng.uniform(0.6, 0.8)
            V = o.vertices @ T[:3, :3].T + T[:3, 3]
            c = V.mean(axis=0)
            eye = c + dist * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
            yield i, T, V, c, eye, int(rng.integers(2**31))


def sources(o, V, c, eye, seed):
    """(name, object cloud in the world frame, viewpoint, cloud-frame -> world) per source."""
    table = {"z": 0.0, "center": tuple(c[:2]), "half_extents": (0.6, 0.6)}
    cloud = Camera.looking_at(eye=eye, target=c).capture([(V, o.faces)], table=table, seed=seed)
    seg = segment_table(cloud)
    if seg.clusters:
        yield "sim", seg.cluster_points[0], eye, np.eye(4)
    E = look_at(eye, c)
    scan = render_scan(V, o.faces, E, KINECT, seed=seed)
    D = np.round(scan.depth * 1000.0).astype(np.uint16)
    P = cloud_from_depth(D, KINECT)
    v = to_table_frame(P, E)
    yield "depth", v.object_points, v.viewpoint, np.eye(4)
    try:
        r = to_table_frame(P)
        yield "ransac", r.object_points, r.viewpoint, E @ np.linalg.inv(r.transform)
    except ValueError:
        pass


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--views-per-object", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default="bench/results/camera_registration.json")
    a = ap.parse_args()
    objs = [load_object(m) for m in MODELS]
    reg = Registrar(objs, names=MODELS, voxel=0.005, threads=a.threads)
    rows, t0 = [], time.perf_counter()
    n = len(objs) * a.views_per_object
    for k, (i, T, V, c, eye, seed) in enumerate(views(objs, a.views_per_object, np.random.default_rng(a.seed))):
        axis = np.array([0.0, 0.0, 1.0]) if MODELS[i] in REVOLUTION else np.zeros(3)
        seen = set()
        for name, P, vp, to_world in sources(objs[i], V, c, eye, seed):
            seen.add(name)
            res = reg.register(P, seed=seed, viewpoint=vp)
            w = np.array([r.weight for r in res])
            rot, tr = errors(to_world @ np.asarray(res[i].transform), T, axis)
            rows.append(dict(view=k, model=MODELS[i], source=name, points=int(len(P)), top=bool(np.argmax(w) == i),
                             rot_deg=rot, trans_m=tr, success=bool(np.argmax(w) == i and rot < 10 and tr < 0.01)))
        for name in {"sim", "depth", "ransac"} - seen:       # no object found: a failure of that source
            rows.append(dict(view=k, model=MODELS[i], source=name, points=0, top=False, rot_deg=180.0, trans_m=1.0,
                             success=False))
        print(f"\r{k + 1}/{n} views, {time.perf_counter() - t0:.0f} s", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    summary = {}
    for name in ("sim", "depth", "ransac"):
        r = [x for x in rows if x["source"] == name]
        summary[name] = {"views": len(r), "success_rate": float(np.mean([x["success"] for x in r])),
                         "true_model_top": float(np.mean([x["top"] for x in r])),
                         "median_rot_deg": float(np.median([x["rot_deg"] for x in r])),
                         "median_trans_mm": 1000 * float(np.median([x["trans_m"] for x in r])),
                         "median_points": float(np.median([x["points"] for x in r]))}
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps({"models": MODELS, "views_per_object": a.views_per_object, "seed": a.seed,
                                       "summary": summary, "rows": rows}, indent=1))
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
