"""Generates the fixed registration benchmark set: partial, noisy views of built-in objects at
random table poses and camera angles, rendered by our camera, segmented by our table segmentation.

Writes bench/results/vision_views.npz (no pickle): for view i, cloud points[offsets[i]:offsets[i+1]]
(world frame), eye[i], the ground-truth model->world transform T_true[i], model index model[i] and
the model's surface samples (model_points/model_normals sliced by model_offsets), and the symmetry
axis of the model (0 0 0 for none; 0 0 1 for bodies of revolution about z: bottles, cylinder).
Usage: python bench/vision_make_views.py [--views 240] [--seed 0]
"""
import argparse
import os
import time

import numpy as np

from bayesgrasp.objects import load_object  # noqa: E402
from bayesgrasp.vision import Camera, model_samples, segment_table  # noqa: E402

MODELS = ["mug/0", "mug/1", "mug/2", "mug/3", "bottle/0", "bottle/1", "bottle/2", "bottle/3", "bottle/4",
          "hammer/0", "hammer/1", "knife/0", "cylinder", "pitcher"]  # no cube: its 90-degree symmetries
REVOLUTION = {"bottle/0", "bottle/1", "bottle/2", "bottle/3", "bottle/4", "cylinder"}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--views", type=int, default=240)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--voxel", type=float, default=0.005)
    ap.add_argument("--out", default="bench/results/vision_views.npz")
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    objs = [load_object(m) for m in MODELS]
    mp, mn, moff = [], [], [0]
    for i, o in enumerate(objs):
        P, N = model_samples(o, voxel=a.voxel, seed=1000 + i)
        mp.append(P)
        mn.append(N)
        moff.append(moff[-1] + len(P))
    pts, offs, eyes, Ts, mids, seeds = [], [0], [], [], [], []
    t0 = time.time()
    v = 0
    tries = 0
    while v < a.views:
        tries += 1
        k = int(rng.integers(len(objs)))
        o = objs[k]
        x, y, yaw = rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(-np.pi, np.pi)
        c, s = np.cos(yaw), np.sin(yaw)
        T = np.array([[c, -s, 0, x], [s, c, 0, y], [0, 0, 1, 0], [0, 0, 0, 1.0]])
        V = o.vertices @ T[:3, :3].T + T[:3, 3]
        centre = V.mean(axis=0)
        az, el, dist = rng.uniform(-np.pi, np.pi), rng.uniform(np.radians(25), np.radians(65)), rng.uniform(0.6, 0.9)
        eye = centre + dist * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        cam = Camera.looking_at(eye, centre)
        seed = int(rng.integers(2**31))
        cloud = cam.capture([(V, o.faces)], table={"z": 0.0, "half_extents": (0.6, 0.6)}, seed=seed)
        try:
            seg = segment_table(cloud)
        except ValueError:
            continue
        if not seg.clusters or len(seg.clusters[0]) < 200:
            continue
        part = seg.cluster_points[0]
        pts.append(part)
        offs.append(offs[-1] + len(part))
        eyes.append(eye)
        Ts.append(T)
        mids.append(k)
        seeds.append(seed)
        v += 1
    axes = np.array([[0, 0, 1.0] if m in REVOLUTION else [0, 0, 0.0] for m in MODELS])
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    np.savez_compressed(a.out, points=np.vstack(pts), offsets=np.array(offs), eye=np.array(eyes),
                        T_true=np.array(Ts), model=np.array(mids), render_seed=np.array(seeds),
                        model_points=np.vstack(mp), model_normals=np.vstack(mn), model_offsets=np.array(moff),
                        model_names=np.array(MODELS), symmetry_axis=axes, voxel=np.array(a.voxel))
    sizes = np.diff(offs)
    print(f"{v} views ({tries} tries) of {len(MODELS)} models in {time.time() - t0:.1f} s; "
          f"points per view: median {int(np.median(sizes))}, min {sizes.min()}, max {sizes.max()} -> {a.out}")


if __name__ == "__main__":
    main()
