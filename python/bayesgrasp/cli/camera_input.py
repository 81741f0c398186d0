"""The camera-data options every command that sees shares (``register``, ``category``, ``fuse``,
``plan``): a point cloud file or a depth image with its intrinsics, the camera-to-table extrinsic,
the cloud's frame and units; read once here into the object's cloud in the table frame."""
from __future__ import annotations

import argparse

from .args import CliError, floats


def add(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("camera data (a real sensor's cloud or depth image instead of the simulated view)")
    g.add_argument("--cloud", default=None, metavar="FILE",
                   help="point cloud file: .pcd, .ply, .xyz, .xyzn, .xyzrgb, .pts or .npy (N x 3)")
    g.add_argument("--depth", default=None, metavar="FILE", help="depth image: 16-bit PNG or .npy (needs --intrinsics)")
    g.add_argument("--intrinsics", default=None, metavar="FILE|FX,FY,CX,CY,W,H",
                   help="the depth camera's intrinsics: Open3D PinholeCameraIntrinsic JSON or six numbers")
    g.add_argument("--extrinsic", default=None, metavar="FILE",
                   help="the camera's pose in the table frame (4x4 camera -> table; .npy, .json or text); "
                        "without it the table plane is found by RANSAC")
    g.add_argument("--cloud-frame", default="camera", choices=["camera", "table"],
                   help="the frame the cloud is in: the camera's (default) or already the table's (z up, table at z = 0)")
    g.add_argument("--viewpoint", default=None, metavar="X,Y,Z",
                   help="the camera centre in the table frame, for --cloud-frame table")
    g.add_argument("--depth-scale", type=float, default=1000.0,
                   help="depth units per metre of an integer depth image (default 1000: millimetres)")
    g.add_argument("--depth-trunc", type=float, default=3.0, help="depths beyond this (m) are dropped")
    g.add_argument("--units", default=None, choices=["m", "cm", "mm"],
                   help="length unit of the --cloud file and of mesh files (default m)")


def given(args: argparse.Namespace) -> bool:
    """Whether the command was given camera data."""
    return bool(getattr(args, "cloud", None) or getattr(args, "depth", None))


def observe(args: argparse.Namespace):
    """The object's cloud in the table frame (:class:`bayesgrasp.io.TableView`) from the camera
    options, or None when none were given. Every inconsistency is a CliError naming the option."""
    from ..io import cloud_from_depth, read_cloud, to_table_frame

    if args.cloud and args.depth:
        raise CliError("--cloud, --depth: give one of them")
    if args.intrinsics and not args.depth:
        raise CliError("--intrinsics: only with --depth")
    if not given(args):
        for opt in ("extrinsic", "viewpoint"):
            if getattr(args, opt):
                raise CliError(f"--{opt}: only with --cloud or --depth")
        return None
    if args.cloud_frame == "table" and args.extrinsic:
        raise CliError("--extrinsic: not with --cloud-frame table (the cloud is already in the table frame)")
    if args.viewpoint and args.cloud_frame != "table":
        raise CliError("--viewpoint: only with --cloud-frame table (otherwise the camera is the cloud's origin)")
    viewpoint = floats(args.viewpoint, 3, "--viewpoint") if args.viewpoint else None
    if args.depth:
        if not args.intrinsics:
            raise CliError("--depth: needs --intrinsics")
        if args.cloud_frame == "table":
            raise CliError("--cloud-frame table: a depth image is in the camera frame (give --extrinsic instead)")
        points = _named("--depth", cloud_from_depth, args.depth, args.intrinsics, depth_scale=args.depth_scale,
                        depth_trunc=args.depth_trunc)
    else:
        points = _named("--cloud", read_cloud, args.cloud, units=args.units)
    return _named("--cloud" if args.cloud else "--depth", to_table_frame, points, args.extrinsic,
                  frame=args.cloud_frame, viewpoint=viewpoint)


def _named(option: str, f, *a, **kw):
    """``f(*a, **kw)`` with a ValueError's message prefixed by the option it came from."""
    try:
        return f(*a, **kw)
    except ValueError as e:
        text = str(e)
        for name in ("intrinsics", "extrinsic", "depth_scale", "depth_trunc", "viewpoint"):
            if text.startswith(name + ":"):
                raise CliError("--" + name.replace("_", "-") + text[len(name):]) from None
        raise CliError(f"{option}: {text}") from None


def observation(view):
    """A TableView as the category pipeline's :class:`~bayesgrasp.loop.category.Observation`."""
    from ..loop.category import Observation

    return Observation(view.object_points, view.viewpoint)
