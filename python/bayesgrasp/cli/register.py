"""``bayesgrasp register``: the object's cloud, from a camera's cloud or depth image (``--cloud``,
``--depth``) or a simulated view of a scene object, registered against models."""
from __future__ import annotations

import json

import numpy as np

from . import camera_input
from .args import CliError, Renamed, add_seed_option, add_view_option, floats, output_file


def add(sub) -> None:
    r = sub.add_parser("register", help="register a camera's cloud (or a simulated view) against models",
                       description="One view of an object (a camera's --cloud or --depth, or a simulated view of "
                                   "--scene-object), the table segmented off, and each model registered to it "
                                   "(FPFH + RANSAC, then ICP; thesis section 4.2): pose, fit and weight per model.")
    r.add_argument("--scene-object", default=None,
                   help="simulated view: object placed in the scene (built-in name or mesh file)")
    r.add_argument("--object-pose", "--pose", dest="object_pose", action=Renamed, old=["--pose"], default="0,0,0",
                   metavar="X,Y,YAW", help="its pose on the table (--pose: the old spelling, deprecated)")
    r.add_argument("--models", required=True, nargs="+", metavar="NAME_OR_PATH", help="models to register against")
    r.add_argument("--voxel", type=float, default=0.005, help="voxel size (m); all radii scale from it")
    add_seed_option(r, "seed of the registration's random draws")
    r.add_argument("--png", default=None, help="write a PNG of the cloud over each registered model")
    r.add_argument("--json", action="store_true", help="print one JSON object")
    add_view_option(r)
    camera_input.add(r)
    r.set_defaults(run=run)


def run(args) -> int:
    from ..objects import load_object
    from ..vision import register

    pose = floats(args.object_pose, 3, "--object-pose")
    if not (args.voxel > 0 and np.isfinite(args.voxel)):
        raise CliError(f"--voxel: must be positive, got {args.voxel}")
    if camera_input.given(args) == bool(args.scene_object):
        raise CliError("--scene-object, --cloud, --depth: give exactly one (a simulated view or camera data)")
    png = output_file(args.png, "--png")
    models = [load_object(m, units=args.units) for m in args.models]
    points, viewpoint, source = _scene(args, pose)
    res = register(points, models, voxel=args.voxel, seed=args.seed, viewpoint=viewpoint,
                   names=[str(m) for m in args.models])
    from ..io.view_fields import cloud_json

    doc = {"scene": source, "scene_points": int(len(points)), "models": [r.as_dict() for r in res],
           "cloud": cloud_json(points)}
    if args.scene_object:
        doc.update(scene_object=str(args.scene_object), units=args.units, pose=pose)
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        _print(source, len(points), res)
    if png:
        from ..viz import plot_registrations

        plot_registrations(points, models, res, str(png))
        print(f"saved {png}")
    from .view import show_result

    show_result(args, doc)
    return 0


def _scene(args, pose):
    """(object cloud in the table frame, camera centre or None, a description of where it came from)."""
    view = camera_input.observe(args)
    if view is not None:
        return view.object_points, view.viewpoint, args.cloud or args.depth
    from ..objects.views import capture_view

    v = capture_view(args.scene_object, pose, seed=args.seed)
    x, y, yaw = pose
    return v.object_points, v.camera.eye, f"{args.scene_object} at x={x:.3f} y={y:.3f} yaw={yaw:.3f}"


def _print(source: str, n_points: int, results) -> None:
    print(f"{source}: {n_points} points of the object in the table frame")
    for r in results:
        if not r.success:
            print(f"  {r.model}: registration failed: {r.reason}")
            continue
        print(f"  {r.model}: fitness {r.fitness:.3f}  rmse {r.rmse * 1000:.2f} mm  "
              f"delta {r.delta * 1000:.2f} mm  weight {r.weight:.3f}")
        for row in r.transform:
            print("      [" + " ".join(f"{v: .4f}" for v in row) + "]")
