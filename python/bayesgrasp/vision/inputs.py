"""Input conversion shared by the camera and the registration: meshes and clouds as arrays."""
from __future__ import annotations

from typing import Tuple

import numpy as np

# input conversion
def as_mesh(obj, name: str = "mesh") -> Tuple[np.ndarray, np.ndarray]:
    """(vertices float64 (N, 3), faces int32 (M, 3)) from a (V, F) tuple or an object with
    ``.vertices`` and ``.faces`` (ObjectModel, trimesh.Trimesh)."""
    if hasattr(obj, "vertices") and hasattr(obj, "faces"):
        V, F = obj.vertices, obj.faces
    elif isinstance(obj, (tuple, list)) and len(obj) == 2:
        V, F = obj
    else:
        raise ValueError(f"{name}: expected a (vertices, faces) tuple or an object with .vertices and .faces")
    V = np.ascontiguousarray(np.asarray(V, dtype=np.float64))
    F = np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"{name}: vertices must have shape (N, 3), got {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3 or (F.size and not np.issubdtype(F.dtype, np.integer)):
        raise ValueError(f"{name}: faces must be integer with shape (M, 3), got {F.shape} {F.dtype}")
    return V, np.ascontiguousarray(F, dtype=np.int32)


def as_cloud(cloud, name: str = "cloud") -> np.ndarray:
    """(N, 3) float64 from a numpy array (N, 3) or (H, W, 3) (organised), or an Open3D point cloud
    (anything with ``.points``). NaN rows are kept (the functions below drop them)."""
    if hasattr(cloud, "points") and not isinstance(cloud, np.ndarray):
        cloud = np.asarray(cloud.points)
    a = np.asarray(cloud, dtype=np.float64)
    if a.ndim == 3 and a.shape[2] == 3:
        a = a.reshape(-1, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (N, 3) or (H, W, 3), got {a.shape}")
    if np.isinf(a).any():
        raise ValueError(f"{name}: contains infinity")
    return np.ascontiguousarray(a)
