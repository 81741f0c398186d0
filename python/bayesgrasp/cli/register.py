"""``bayesgrasp register``: a simulated depth view of an object, table segmentation, and the
registration of the object's cloud against models."""
from __future__ import annotations

import numpy as np

from .args import CliError, floats, output_file


def add(sub) -> None:
    r = sub.add_parser("register", help="render a view of an object, segment it and register it against models")
    r.add_argument("--scene-object", required=True, help="object placed in the scene (built-in name or mesh file)")
    r.add_argument("--pose", default="0,0,0", metavar="X,Y,YAW", help="its pose on the table")
    r.add_argument("--models", required=True, nargs="+", metavar="NAME_OR_PATH", help="models to register against")
    r.add_argument("--voxel", type=float, default=0.005, help="voxel size (m); all radii scale from it")
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--png", default=None, help="write a PNG of the cloud over each registered model")
    r.add_argument("--json", action="store_true", help="print one JSON object")
    r.set_defaults(run=run)


def run(args) -> int:
    from ..vision import register_command

    pose = floats(args.pose, 3, "--pose")
    if not (args.voxel > 0 and np.isfinite(args.voxel)):
        raise CliError(f"--voxel: must be positive, got {args.voxel}")
    png = output_file(args.png, "--png")
    register_command(args.scene_object, pose, args.models, json_out=args.json, png=str(png) if png else None,
                     voxel=args.voxel, seed=args.seed)
    return 0
