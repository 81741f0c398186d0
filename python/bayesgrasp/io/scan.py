"""A sensor-like depth scan of a mesh on a table, rendered with Open3D's ``RaycastingScene``: for
examples, tests and benchmarks of the camera-data path on files that look like a real sensor's.

Noise (Nguyen, Izadi and Lovell 2012, the Kinect's axial noise): Gaussian depth noise of standard
deviation ``0.0012 + 0.0019 (z - 0.4)^2`` m at depth ``z``, plus ``0.0001 / sqrt(z) * theta^2 /
(pi/2 - theta)^2`` at incidence angle ``theta``; pixels are dropped with a probability rising
linearly from 0 at ``drop_start`` to 1 at ``drop_end`` incidence (grazing surfaces return nothing).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from .camera_data import Intrinsics

KINECT = Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)


@dataclass
class Scan:
    """depth: (H, W) float metres, 0 where nothing was measured; intrinsics; extrinsic: the
    camera's pose in the table frame (camera -> table, 4x4)."""

    depth: np.ndarray
    intrinsics: Intrinsics
    extrinsic: np.ndarray


def look_at(eye: Sequence[float], target: Sequence[float], up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """Camera -> table pose of a camera at ``eye`` looking at ``target`` (x right, y down, z forward)."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, np.asarray(up, float))
    if np.linalg.norm(x) < 1e-9:
        raise ValueError("eye, target: the view direction is parallel to up")
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, eye
    return T


def render_scan(vertices: np.ndarray, faces: np.ndarray, extrinsic: np.ndarray,
                intrinsics: Intrinsics = KINECT, noise: bool = True, seed: int = 0, table_half_extent: float = 0.6,
                drop_start_deg: float = 70.0, drop_end_deg: float = 85.0) -> Scan:
    """Ray-casts the mesh (table frame, metres) standing on a table top at z = 0 (a square of
    ``table_half_extent`` about the mesh's footprint) from the camera ``extrinsic``."""
    import open3d as o3d

    V = np.asarray(vertices, np.float32)
    F = np.asarray(faces, np.uint32)
    c = V[:, :2].mean(axis=0)
    h = float(table_half_extent)
    TV = np.array([[c[0] - h, c[1] - h, 0], [c[0] + h, c[1] - h, 0], [c[0] + h, c[1] + h, 0],
                   [c[0] - h, c[1] + h, 0]], np.float32)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(V), o3d.core.Tensor(F))
    scene.add_triangles(o3d.core.Tensor(TV), o3d.core.Tensor(np.array([[0, 1, 2], [0, 2, 3]], np.uint32)))
    K = intrinsics
    rays = scene.create_rays_pinhole(o3d.core.Tensor(K.K), o3d.core.Tensor(np.linalg.inv(extrinsic)),
                                     K.width, K.height)
    hit = scene.cast_rays(rays)
    d = rays.numpy()[..., 3:]
    t = hit["t_hit"].numpy()
    z_axis = np.asarray(extrinsic, float)[:3, 2]
    depth = t * (d @ z_axis)                              # distance along the optical axis
    valid = np.isfinite(depth)
    depth = np.where(valid, depth, 0.0)
    if noise:
        depth = _sensor_noise(depth, valid, d, hit["primitive_normals"].numpy(), np.random.default_rng(seed),
                              np.radians(drop_start_deg), np.radians(drop_end_deg))
    return Scan(depth.astype(np.float64), K, np.asarray(extrinsic, float).copy())


def _sensor_noise(depth, valid, directions, normals, rng, drop_start, drop_end) -> np.ndarray:
    u = directions / np.linalg.norm(directions, axis=-1, keepdims=True)
    cos = np.abs(np.sum(u * normals, axis=-1))
    theta = np.arccos(np.clip(cos, 0.0, 1.0))
    z = np.where(valid, depth, 1.0)
    sigma = 0.0012 + 0.0019 * (z - 0.4) ** 2 + 0.0001 / np.sqrt(z) * theta**2 / np.maximum(np.pi / 2 - theta, 1e-3) ** 2
    out = depth + rng.standard_normal(depth.shape) * sigma
    p_drop = np.clip((theta - drop_start) / max(drop_end - drop_start, 1e-9), 0.0, 1.0)
    keep = valid & (rng.random(depth.shape) >= p_drop) & (out > 0)
    return np.where(keep, out, 0.0)
