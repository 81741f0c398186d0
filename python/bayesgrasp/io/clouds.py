"""Point clouds in: files (through Open3D's readers, or numpy), Open3D and trimesh objects,
arrays, all as (N, 3) float64 metres with the non-finite points dropped (and counted).

>>> from bayesgrasp.io import read_cloud, as_points
>>> P = read_cloud("scan.ply")                       # (N, 3) metres
>>> P = read_cloud("scan_mm.pcd", units="mm")        # millimetres in the file
>>> P = as_points(open3d_cloud)                      # legacy or tensor cloud, trimesh.PointCloud, array
"""
from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import Optional, Union

import numpy as np

from .units import SCENE_EXTENT_MAX, check_extent, unit_scale

#: The file types :func:`read_cloud` reads (Open3D's readers, and numpy's for .npy).
CLOUD_EXTENSIONS = (".pcd", ".ply", ".xyz", ".xyzn", ".xyzrgb", ".pts", ".npy")


class CloudWarning(UserWarning):
    """Points dropped from a cloud (NaN or infinite coordinates)."""


def _raw_points(cloud, name: str) -> np.ndarray:
    """The coordinates of any supported cloud type, as an array (not yet checked)."""
    if isinstance(cloud, np.ndarray):
        return cloud
    if hasattr(cloud, "point") and hasattr(cloud, "to_legacy"):      # open3d.t.geometry.PointCloud
        if "positions" not in cloud.point:
            return np.zeros((0, 3))
        return cloud.point.positions.numpy()
    if hasattr(cloud, "points") and hasattr(cloud, "has_points"):     # open3d.geometry.PointCloud
        return np.asarray(cloud.points)
    if type(cloud).__name__ == "PointCloud" and hasattr(cloud, "vertices"):  # trimesh.PointCloud
        return np.asarray(cloud.vertices)
    if isinstance(cloud, (list, tuple)):
        return np.asarray(cloud, dtype=np.float64)
    raise ValueError(f"{name}: expected an (N, 3) array, an Open3D point cloud (legacy or tensor) or a "
                     f"trimesh.PointCloud, got {type(cloud).__name__}")


def as_points(cloud, name: str = "cloud", units: Optional[str] = None, drop_nonfinite: bool = True) -> np.ndarray:
    """(N, 3) float64 metres from an (N, 3) or organised (H, W, 3) array, an
    ``open3d.geometry.PointCloud``, an ``open3d.t.geometry.PointCloud`` or a ``trimesh.PointCloud``.

    The input is never modified. Points with a NaN or infinite coordinate are dropped, with a
    :class:`CloudWarning` giving the count; ValueError if the cloud is empty or nothing finite is left.
    ``units``: the unit of the coordinates (m, cm or mm), scaled to metres."""
    scale = unit_scale(units)
    a = np.asarray(_raw_points(cloud, name))
    if a.dtype == object or not (np.issubdtype(a.dtype, np.number) or a.dtype == bool):
        raise ValueError(f"{name}: expected numbers, got dtype {a.dtype}")
    a = a.astype(np.float64, copy=True)
    if a.ndim == 3 and a.shape[2] == 3:
        a = a.reshape(-1, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (N, 3) or (H, W, 3), got {a.shape}")
    if len(a) == 0:
        raise ValueError(f"{name}: is empty (no points)")
    if drop_nonfinite and not np.isfinite(a).all():     # the row mask only when something is not finite
        ok = np.isfinite(a[:, 0]) & np.isfinite(a[:, 1]) & np.isfinite(a[:, 2])
        n_bad = int(len(a) - ok.sum())
        if n_bad == len(a):
            raise ValueError(f"{name}: all {len(a)} points are NaN or infinite")
        if n_bad:
            warnings.warn(f"{name}: dropped {n_bad} of {len(a)} points with NaN or infinite coordinates",
                          CloudWarning, stacklevel=2)
            a = a[ok]
    if scale != 1.0:
        a *= scale
    return np.ascontiguousarray(a)


def read_cloud(path: Union[str, os.PathLike], units: Optional[str] = None) -> np.ndarray:
    """Reads a point cloud file: ``.pcd``, ``.ply``, ``.xyz``, ``.xyzn``, ``.xyzrgb``, ``.pts``
    (Open3D's readers) or ``.npy`` (an (N, 3) or (H, W, 3) array). Returns (N, 3) metres, the
    non-finite points dropped (see :func:`as_points`).

    ValueError for an unknown extension, an unreadable or empty file, or a scene whose extent
    says it is not in ``units`` (default metres); FileNotFoundError if it does not exist."""
    p = checked_file(path, CLOUD_EXTENSIONS, "point cloud")
    raw = load_npy(p) if p.suffix.lower() == ".npy" else _read_open3d(p)
    P = as_points(raw, name=str(p), units=units)
    check_extent(P, str(p), units, lo=0.0, hi=SCENE_EXTENT_MAX)
    return P


def checked_file(path: Union[str, os.PathLike], extensions, what: str) -> Path:
    """``path`` as a Path, if its extension is one of ``extensions`` (ValueError) and it exists
    (FileNotFoundError)."""
    p = Path(path)
    ext = p.suffix.lower()
    if ext not in extensions:
        raise ValueError(f"{p}: unknown {what} type '{ext}' (known: {', '.join(extensions)})")
    if not p.is_file():
        raise FileNotFoundError(f"{what} file not found: '{p}'")
    return p


def load_npy(p: Path) -> np.ndarray:
    """A ``.npy`` array (never a pickle); ValueError if it cannot be read."""
    try:
        return np.load(p, allow_pickle=False)
    except (ValueError, OSError) as e:
        raise ValueError(f"{p}: not a readable .npy array: {e}") from None


def _read_open3d(p: Path) -> np.ndarray:
    import open3d as o3d

    # Open3D prints a warning and returns an empty cloud for a file it cannot parse.
    with _quiet_open3d(o3d):
        pcd = o3d.io.read_point_cloud(str(p), format="auto", remove_nan_points=False,
                                      remove_infinite_points=False)
    P = np.asarray(pcd.points)
    if len(P) == 0:
        raise ValueError(f"{p}: unreadable or empty point cloud (Open3D read no points)")
    return P


def _quiet_open3d(o3d):
    """Open3D's console verbosity lowered to errors for the duration of a block."""
    return o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error)


def to_open3d(points: np.ndarray):
    """An ``open3d.geometry.PointCloud`` of (N, 3) float64 points (a copy)."""
    import open3d as o3d

    return o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.ascontiguousarray(points, dtype=np.float64)))
