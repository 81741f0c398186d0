"""``bayesgrasp register``: a simulated depth view of an object, table segmentation, and the
registration of the object's cloud against models."""
from __future__ import annotations

import json

import numpy as np

from .args import SEED_MAX, CliError, bounded_int, floats, output_file


def add(sub) -> None:
    r = sub.add_parser("register", help="render a view of an object, segment it and register it against models")
    r.add_argument("--scene-object", required=True, help="object placed in the scene (built-in name or mesh file)")
    r.add_argument("--pose", default="0,0,0", metavar="X,Y,YAW", help="its pose on the table")
    r.add_argument("--models", required=True, nargs="+", metavar="NAME_OR_PATH", help="models to register against")
    r.add_argument("--voxel", type=float, default=0.005, help="voxel size (m); all radii scale from it")
    r.add_argument("--seed", type=bounded_int(0, SEED_MAX), default=0)
    r.add_argument("--png", default=None, help="write a PNG of the cloud over each registered model")
    r.add_argument("--json", action="store_true", help="print one JSON object")
    r.set_defaults(run=run)


def run(args) -> int:
    from ..objects import load_object
    from ..objects.views import capture_view
    from ..vision import register

    pose = floats(args.pose, 3, "--pose")
    if not (args.voxel > 0 and np.isfinite(args.voxel)):
        raise CliError(f"--voxel: must be positive, got {args.voxel}")
    png = output_file(args.png, "--png")
    view = capture_view(args.scene_object, pose, seed=args.seed)
    models = [load_object(m) for m in args.models]
    res = register(view.object_points, models, voxel=args.voxel, seed=args.seed, viewpoint=view.camera.eye,
                   names=[str(m) for m in args.models])
    doc = {"scene_object": str(args.scene_object), "pose": pose, "scene_points": int(len(view.object_points)),
           "models": [r.as_dict() for r in res]}
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        _print(args.scene_object, pose, len(view.object_points), res)
    if png:
        from ..viz import plot_registrations

        plot_registrations(view.object_points, models, res, str(png))
        print(f"saved {png}")
    return 0


def _print(name, pose, n_points: int, results) -> None:
    x, y, yaw = pose
    print(f"scene object {name} at x={x:.3f} y={y:.3f} yaw={yaw:.3f}: {n_points} points in the largest cluster")
    for r in results:
        if not r.success:
            print(f"  {r.model}: registration failed: {r.reason}")
            continue
        print(f"  {r.model}: fitness {r.fitness:.3f}  rmse {r.rmse * 1000:.2f} mm  "
              f"delta {r.delta * 1000:.2f} mm  weight {r.weight:.3f}")
        for row in r.transform:
            print("      [" + " ".join(f"{v: .4f}" for v in row) + "]")
