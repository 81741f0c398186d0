"""Writes what a depth camera would give for an object on a table, as files the CLI reads:

  depth.png        16-bit depth in millimetres (0: no measurement), 640 x 480, Kinect-like noise
  intrinsics.json  Open3D's PinholeCameraIntrinsic JSON
  extrinsic.json   the camera's pose in the table frame (4x4, camera -> table)
  cloud.ply        the depth image back-projected, in the camera frame (what a driver publishes)
  truth.json       the object and its pose on the table (x, y, yaw), for the simulated stand-in

Usage: python examples/make_scan.py [--object mug/3] [--object-pose 0.03,-0.02,0.8] [--out out/scan]
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import open3d as o3d

from bayesgrasp.io import KINECT, cloud_from_depth, look_at, render_scan, write_depth_png
from bayesgrasp.objects import load_object


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--object", default="mug/3", help="built-in object or mesh file")
    ap.add_argument("--object-pose", "--pose", dest="pose", default="0.03,-0.02,0.8",
                    help="x,y,yaw on the table (m, m, rad); --pose: the old spelling")
    ap.add_argument("--eye", default="0.5,-0.45,0.5", help="camera position relative to the object (m)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="out/scan")
    a = ap.parse_args()
    x, y, yaw = (float(v) for v in a.pose.split(","))
    obj = load_object(a.object)
    c, s = np.cos(yaw), np.sin(yaw)
    V = obj.vertices @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]).T + [x, y, 0.0]
    centre = V.mean(axis=0)
    T = look_at(centre + np.array([float(v) for v in a.eye.split(",")]), centre)
    scan = render_scan(V, obj.faces, T, KINECT, seed=a.seed)

    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    write_depth_png(out / "depth.png", scan.depth)
    (out / "intrinsics.json").write_text(json.dumps(KINECT.to_json()))
    (out / "extrinsic.json").write_text(json.dumps({"extrinsic": T.tolist()}))
    P = cloud_from_depth(out / "depth.png", out / "intrinsics.json")            # camera frame
    o3d.io.write_point_cloud(str(out / "cloud.ply"), o3d.geometry.PointCloud(o3d.utility.Vector3dVector(P)))
    (out / "truth.json").write_text(json.dumps({"object": a.object, "pose": [x, y, yaw]}))
    print(f"wrote {out}/depth.png, intrinsics.json, extrinsic.json, cloud.ply ({len(P)} points), truth.json")


if __name__ == "__main__":
    main()
