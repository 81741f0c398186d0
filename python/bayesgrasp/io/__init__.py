"""A real camera's data in: point clouds and depth images from files or Open3D / trimesh objects,
into the table frame (z up, table top at z = 0), through Open3D's own calls.

>>> from bayesgrasp.io import read_cloud, cloud_from_depth, read_intrinsics, to_table_frame
>>> P = cloud_from_depth("depth.png", read_intrinsics("intrinsics.json"))   # camera frame
>>> view = to_table_frame(P)                       # table by RANSAC, the object cut out
>>> view.object_points, view.viewpoint             # what register() and the planners take

Every call accepts (N, 3) arrays, ``open3d.geometry.PointCloud``, ``open3d.t.geometry.PointCloud``
and ``trimesh.PointCloud``; none modifies its input. Lengths are metres unless ``units=`` says
otherwise, and an object whose extent is outside 5 mm .. 2 m is refused with the likely unit named.
"""
from .camera_data import (DEPTH_EXTENSIONS, Intrinsics, check_rigid, cloud_from_depth, depth_in_metres,
                          read_depth, read_extrinsic, read_intrinsics, write_depth_png)
from .clouds import CLOUD_EXTENSIONS, CloudWarning, as_points, read_cloud, to_open3d
from .scan import KINECT, Scan, look_at, render_scan
from .table_frame import TableFrameOptions, TableView, to_table_frame
from .units import UNITS, check_extent, unit_scale

__all__ = [
    "CLOUD_EXTENSIONS", "CloudWarning", "DEPTH_EXTENSIONS", "Intrinsics", "KINECT", "Scan", "TableFrameOptions",
    "TableView", "UNITS", "as_points", "check_extent", "check_rigid", "cloud_from_depth", "depth_in_metres",
    "look_at", "read_cloud", "read_depth", "read_extrinsic", "read_intrinsics", "render_scan", "to_open3d",
    "to_table_frame", "unit_scale", "write_depth_png",
]
