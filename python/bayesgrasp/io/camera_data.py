"""A depth camera's data in: intrinsics, camera-to-table extrinsics, depth images, and the cloud
a depth image back-projects to (Open3D's ``create_from_depth_image``).

Frames: the camera frame has x right, y down, z forward (Open3D's, OpenCV's and ours); an
*extrinsic* here is always the camera's pose in the table frame, the 4x4 that maps camera
coordinates to table coordinates (Open3D's own ``extrinsic`` argument is its inverse).

>>> from bayesgrasp.io import read_intrinsics, read_depth, cloud_from_depth
>>> K = read_intrinsics("intrinsics.json")         # Open3D PinholeCameraIntrinsic JSON
>>> K = read_intrinsics("525,525,319.5,239.5,640,480")
>>> P = cloud_from_depth(read_depth("depth.png"), K)              # camera frame, metres
>>> P = cloud_from_depth("depth.png", K, extrinsic=T_table_camera)  # table frame
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Union

import numpy as np

#: The file types :func:`read_depth` reads.
DEPTH_EXTENSIONS = (".png", ".npy")


@dataclass(frozen=True)
class Intrinsics:
    """A pinhole camera: focal lengths and principal point (pixels), image size."""

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    def __post_init__(self):
        for k in ("fx", "fy", "cx", "cy"):
            v = getattr(self, k)
            if not (isinstance(v, (int, float, np.number)) and np.isfinite(v)):
                raise ValueError(f"intrinsics: {k} must be a finite number, got {v!r}")
        if self.fx <= 0 or self.fy <= 0:
            raise ValueError(f"intrinsics: focal lengths must be positive, got fx={self.fx}, fy={self.fy}")
        for k in ("width", "height"):
            v = getattr(self, k)
            if isinstance(v, bool) or not float(v).is_integer() or not 0 < v <= 100_000:
                raise ValueError(f"intrinsics: {k} must be a positive integer, got {v!r}")
        object.__setattr__(self, "width", int(self.width))
        object.__setattr__(self, "height", int(self.height))

    @property
    def K(self) -> np.ndarray:
        """The 3x3 camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def to_open3d(self):
        import open3d as o3d

        return o3d.camera.PinholeCameraIntrinsic(self.width, self.height, self.fx, self.fy, self.cx, self.cy)

    def to_json(self) -> dict:
        """Open3D's PinholeCameraIntrinsic JSON (the matrix column-major, as Open3D writes it)."""
        return {"width": self.width, "height": self.height, "intrinsic_matrix": self.K.T.ravel().tolist()}


def read_intrinsics(source, width: Optional[int] = None, height: Optional[int] = None) -> Intrinsics:
    """Intrinsics from an :class:`Intrinsics`, an ``open3d.camera.PinholeCameraIntrinsic``, a JSON
    file or dict in Open3D's format (``width``, ``height``, column-major ``intrinsic_matrix``), the
    text ``"fx,fy,cx,cy,width,height"``, or a 3x3 matrix (with ``width`` and ``height``)."""
    if isinstance(source, Intrinsics):
        return source
    if hasattr(source, "intrinsic_matrix") and hasattr(source, "width"):   # Open3D's own class
        K = np.asarray(source.intrinsic_matrix, float)
        return Intrinsics(K[0, 0], K[1, 1], K[0, 2], K[1, 2], source.width, source.height)
    if isinstance(source, dict):
        return _from_open3d_json(source, "intrinsics")
    if isinstance(source, (str, os.PathLike)):
        s = os.fspath(source)
        if Path(s).suffix.lower() == ".json" or Path(s).is_file():
            return _from_file(Path(s))
        try:
            v = [float(x) for x in s.split(",")]
        except ValueError:
            v = []
        if len(v) != 6:
            raise ValueError(f"intrinsics: expected a JSON file or 'fx,fy,cx,cy,width,height', got {s!r}")
        return Intrinsics(*v[:4], v[4], v[5])
    K = np.asarray(source, dtype=float)
    if K.shape != (3, 3):
        raise ValueError(f"intrinsics: expected a 3x3 matrix, a JSON file or 'fx,fy,cx,cy,width,height', "
                         f"got shape {K.shape}")
    if width is None or height is None:
        raise ValueError("intrinsics: a 3x3 matrix needs width= and height=")
    return Intrinsics(K[0, 0], K[1, 1], K[0, 2], K[1, 2], width, height)


def _from_file(p: Path) -> Intrinsics:
    if not p.is_file():
        raise FileNotFoundError(f"intrinsics file not found: '{p}'")
    try:
        doc = json.loads(p.read_text())
    except (ValueError, UnicodeDecodeError) as e:
        raise ValueError(f"intrinsics: {p} is not JSON: {e}") from None
    return _from_open3d_json(doc, f"intrinsics {p}")


def _from_open3d_json(doc: dict, what: str) -> Intrinsics:
    try:
        K = np.asarray(doc["intrinsic_matrix"], dtype=float).reshape(3, 3).T   # column-major
        return Intrinsics(K[0, 0], K[1, 1], K[0, 2], K[1, 2], doc["width"], doc["height"])
    except (KeyError, TypeError, ValueError) as e:
        if isinstance(e, ValueError) and str(e).startswith("intrinsics:"):
            raise
        raise ValueError(f"{what}: expected Open3D's PinholeCameraIntrinsic JSON (width, height, "
                         f"intrinsic_matrix of 9 numbers), got {e!r}") from None


def check_rigid(T, name: str = "extrinsic", tol: float = 1e-4) -> np.ndarray:
    """``T`` as a (4, 4) float64 rigid transform; ValueError if it is not one (R^T R = I and det R = 1
    within ``tol``, last row 0 0 0 1)."""
    T = np.asarray(T, dtype=np.float64)
    if T.shape != (4, 4):
        raise ValueError(f"{name}: expected a 4x4 matrix, got shape {T.shape}")
    if not np.all(np.isfinite(T)):
        raise ValueError(f"{name}: contains NaN or infinity")
    R = T[:3, :3]
    if not np.allclose(T[3], [0, 0, 0, 1], atol=tol):
        raise ValueError(f"{name}: last row must be 0 0 0 1, got {T[3].tolist()}")
    err = float(np.abs(R.T @ R - np.eye(3)).max())
    if err > tol or abs(np.linalg.det(R) - 1.0) > tol:
        raise ValueError(f"{name}: not a rigid transform (R^T R differs from I by {err:.3g}, det R = "
                         f"{np.linalg.det(R):.4g}); scale or shear is not allowed")
    return T.copy()


def read_extrinsic(source, name: str = "extrinsic") -> np.ndarray:
    """A camera-to-table 4x4 from an array, a ``.npy``, a ``.json`` (a 4x4 list, or a dict with
    ``extrinsic``) or a text file of 16 numbers; checked to be rigid."""
    if isinstance(source, (str, os.PathLike)):
        p = Path(source)
        if not p.is_file():
            raise FileNotFoundError(f"{name} file not found: '{p}'")
        try:
            if p.suffix.lower() == ".npy":
                source = np.load(p, allow_pickle=False)
            elif p.suffix.lower() == ".json":
                doc = json.loads(p.read_text())
                source = doc.get("extrinsic", doc) if isinstance(doc, dict) else doc
            else:
                source = np.loadtxt(p).reshape(4, 4)
        except (ValueError, OSError, UnicodeDecodeError, AttributeError) as e:
            raise ValueError(f"{name}: cannot read a 4x4 matrix from {p}: {e}") from None
    try:
        T = np.asarray(source, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a 4x4 matrix of numbers") from None
    return check_rigid(T, name)


def read_depth(path: Union[str, os.PathLike]) -> np.ndarray:
    """A depth image from a 16-bit PNG (uint16, usually millimetres) or a ``.npy`` (float metres,
    or integers), as the array it holds."""
    from .clouds import _quiet_open3d, checked_file, load_npy

    p = checked_file(path, DEPTH_EXTENSIONS, "depth image")
    if p.suffix.lower() == ".npy":
        return load_npy(p)
    import open3d as o3d

    with _quiet_open3d(o3d):
        img = o3d.io.read_image(str(p))
    D = np.asarray(img)
    if D.size == 0:
        raise ValueError(f"{p}: unreadable PNG (Open3D read no pixels)")
    if D.ndim != 2:
        raise ValueError(f"{p}: a depth image has one channel, this PNG has shape {D.shape}")
    return D


def write_depth_png(path: Union[str, os.PathLike], depth_m: np.ndarray, depth_scale: float = 1000.0) -> Path:
    """Writes float depth in metres (NaN or 0: no measurement) as a 16-bit PNG of depth x depth_scale."""
    import open3d as o3d

    D = np.nan_to_num(np.asarray(depth_m, dtype=np.float64), nan=0.0) * depth_scale
    if np.any(D < 0) or np.any(D > 65535):
        raise ValueError(f"depth: values must be in [0, {65535 / depth_scale:g}] m for a 16-bit PNG")
    p = Path(path)
    if not o3d.io.write_image(str(p), o3d.geometry.Image(np.round(D).astype(np.uint16))):
        raise ValueError(f"{p}: Open3D could not write the PNG")
    return p


def depth_in_metres(depth, depth_scale: float = 1000.0, name: str = "depth") -> np.ndarray:
    """A depth image as float32 metres: integer images are divided by ``depth_scale`` (units per
    metre: 1000 for millimetres), float images are already metres. 0 and NaN mean no measurement."""
    D = np.asarray(depth)
    if D.ndim != 2:
        raise ValueError(f"{name}: expected a 2-D image, got shape {D.shape}")
    if not (np.isfinite(depth_scale) and depth_scale > 0):
        raise ValueError(f"depth_scale: must be positive, got {depth_scale}")
    if np.issubdtype(D.dtype, np.integer) or D.dtype == bool:
        M = D.astype(np.float32) / np.float32(depth_scale)
    elif np.issubdtype(D.dtype, np.floating):
        M = np.nan_to_num(D.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    else:
        raise ValueError(f"{name}: expected integer or float pixels, got dtype {D.dtype}")
    if np.any(M < 0):
        raise ValueError(f"{name}: has negative depths")
    return np.ascontiguousarray(M)


def cloud_from_depth(depth, intrinsics, extrinsic=None, depth_scale: float = 1000.0,
                     depth_trunc: float = 3.0, stride: int = 1) -> np.ndarray:
    """Back-projects a depth image to an (N, 3) cloud in metres (Open3D's
    ``PointCloud.create_from_depth_image``), pixels without a measurement left out.

    Args:
        depth: an array or a file (16-bit PNG, ``.npy``); integer pixels are divided by
            ``depth_scale`` (1000: millimetres), float pixels are metres.
        intrinsics: anything :func:`read_intrinsics` takes; its size must match the image's.
        extrinsic: the camera's pose in the table frame (4x4, camera -> table); None: the cloud
            stays in the camera frame.
        depth_trunc: depths beyond this (m) are dropped.
        stride: keep every ``stride``-th pixel in each direction.
    """
    import open3d as o3d

    K = read_intrinsics(intrinsics)
    D = read_depth(depth) if isinstance(depth, (str, os.PathLike)) else depth
    D = depth_in_metres(D, depth_scale)
    if D.shape != (K.height, K.width):
        raise ValueError(f"depth: image is {D.shape[1]} x {D.shape[0]} pixels but the intrinsics are for "
                         f"{K.width} x {K.height}")
    if not (np.isfinite(depth_trunc) and depth_trunc > 0):
        raise ValueError(f"depth_trunc: must be positive, got {depth_trunc}")
    if isinstance(stride, bool) or not isinstance(stride, (int, np.integer)) or stride < 1:
        raise ValueError(f"stride: must be a positive integer, got {stride!r}")
    T = np.eye(4) if extrinsic is None else read_extrinsic(extrinsic)
    pcd = o3d.geometry.PointCloud.create_from_depth_image(
        o3d.geometry.Image(D), K.to_open3d(), extrinsic=np.linalg.inv(T), depth_scale=1.0,
        depth_trunc=float(depth_trunc), stride=int(stride), project_valid_depth_only=True)
    P = np.asarray(pcd.points)
    if len(P) == 0:
        raise ValueError(f"depth: no pixel has a depth in (0, {depth_trunc:g}] m")
    return P.copy()
