"""A 640 x 480 depth PNG to the object's cloud in the table frame (read, back-project, voxel
down-sample, table plane by RANSAC, crop above the table, DBSCAN cluster, outlier removal,
normals): bayesgrasp.io against the same steps written directly with Open3D calls, same
parameters, alternating, on the same file. Run on one core (bench/run_camera.sh pins it).

Usage: python bench/camera_pipeline.py [--reps 40] [--out bench/results/camera_pipeline.json]"""
import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import open3d as o3d

from bayesgrasp.io import KINECT, TableFrameOptions, cloud_from_depth, look_at, read_depth, render_scan, \
    to_table_frame, write_depth_png
from bayesgrasp.objects import load_object

OPT = TableFrameOptions()


def ours(png: Path):
    return to_table_frame(cloud_from_depth(read_depth(png), KINECT)).object_points


def direct_open3d(png: Path):
    """The peer: the same steps, in the same order and with the same parameters, as Open3D calls
    (and the numpy between them) in one function."""
    depth = o3d.io.read_image(str(png))
    pcd = o3d.geometry.PointCloud.create_from_depth_image(depth, KINECT.to_open3d(), depth_scale=1000.0,
                                                          depth_trunc=3.0)
    P = np.asarray(pcd.points)
    rng = np.random.default_rng(0)
    sample = pcd.select_by_index(np.sort(rng.choice(len(P), OPT.plane_samples, replace=False)).tolist())
    o3d.utility.random.seed(0)
    plane, _ = sample.segment_plane(OPT.plane_threshold, 3, OPT.plane_iterations)
    n, d = np.asarray(plane[:3]), plane[3]
    if d < 0:
        n, d = -n, -d
    x = np.array([0.0, 0.0, 1.0]) - n[2] * n
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.stack([x, np.cross(n, x), n])
    T[:3, 3] = T[:3, :3] @ (d * n)
    pcd.transform(T)
    Q = np.asarray(pcd.points)
    table = np.abs(Q[:, 2]) <= OPT.plane_threshold
    lo, hi = Q[table, :2].min(0) - OPT.margin, Q[table, :2].max(0) + OPT.margin
    keep = (Q[:, 2] >= OPT.min_height) & (Q[:, 2] <= OPT.max_height) & np.all((Q[:, :2] >= lo) & (Q[:, :2] <= hi), 1)
    sub = pcd.select_by_index(np.flatnonzero(keep).tolist()).voxel_down_sample(OPT.voxel)
    labels = np.asarray(sub.cluster_dbscan(OPT.cluster_tolerance, 4))
    obj = sub.select_by_index(np.flatnonzero(labels == np.bincount(labels[labels >= 0]).argmax()).tolist())
    obj, _ = obj.remove_statistical_outlier(OPT.outlier_neighbours, OPT.outlier_std)
    obj.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=OPT.normal_radius, max_nn=30))
    obj.orient_normals_towards_camera_location(T[:3, 3])
    return np.asarray(obj.points)


def open3d_voxel_first(png: Path):
    """For reference, the textbook order: the whole cloud voxel-down-sampled first, RANSAC on all of it."""
    depth = o3d.io.read_image(str(png))
    pcd = o3d.geometry.PointCloud.create_from_depth_image(depth, KINECT.to_open3d(), depth_scale=1000.0,
                                                          depth_trunc=3.0).voxel_down_sample(OPT.voxel)
    o3d.utility.random.seed(0)
    plane, inliers = pcd.segment_plane(OPT.plane_threshold, 3, OPT.plane_iterations)
    rest = pcd.select_by_index(inliers, invert=True)
    labels = np.asarray(rest.cluster_dbscan(OPT.cluster_tolerance, 4))
    obj = rest.select_by_index(np.flatnonzero(labels == np.bincount(labels[labels >= 0]).argmax()).tolist())
    obj, _ = obj.remove_statistical_outlier(OPT.outlier_neighbours, OPT.outlier_std)
    obj.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=OPT.normal_radius, max_nn=30))
    return np.asarray(obj.points)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=40)
    ap.add_argument("--out", default="bench/results/camera_pipeline.json")
    a = ap.parse_args()
    o = load_object("mug/3")
    centre = o.vertices.mean(axis=0)
    T = look_at(centre + [0.5, -0.45, 0.5], centre)
    scan = render_scan(o.vertices, o.faces, T, KINECT, seed=0)
    with tempfile.TemporaryDirectory() as tmp:
        png = Path(tmp) / "depth.png"
        write_depth_png(png, scan.depth)
        n_ours, n_peer = len(ours(png)), len(direct_open3d(png))        # warm-up, and the same object
        open3d_voxel_first(png)
        times = {"ours": [], "open3d": [], "open3d_voxel_first": []}
        for _ in range(a.reps):
            for name, f in (("ours", ours), ("open3d", direct_open3d), ("open3d_voxel_first", open3d_voxel_first)):
                t0 = time.perf_counter()
                f(png)
                times[name].append(time.perf_counter() - t0)
    med = {k: float(np.median(v)) for k, v in times.items()}
    out = {"image": "640x480 uint16 PNG, mug/3 on a 1.2 m table, Kinect-like noise", "reps": a.reps,
           "open3d": o3d.__version__, "median_s": med, "ratio_ours_over_open3d": med["ours"] / med["open3d"],
           "object_points": {"ours": n_ours, "open3d": n_peer}, "times": times}
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(out, indent=1))
    print(f"median: ours {1e3 * med['ours']:.1f} ms, direct Open3D (same steps) {1e3 * med['open3d']:.1f} ms, ratio "
          f"{out['ratio_ours_over_open3d']:.2f}; Open3D voxel-first order {1e3 * med['open3d_voxel_first']:.1f} ms; "
          f"object points {n_ours} / {n_peer}")


if __name__ == "__main__":
    main()
