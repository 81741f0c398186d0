"""Table-top scenes: objects resting on a table (z up, table top at z = 0) at planar poses.

Placement rule. Each object gets an *object frame* (its canonical mesh, :meth:`Scene.canonical_object`):

* default: the mesh is shifted so that the centre of its xy bounding box is on the z axis and its
  lowest point is at z = 0;
* ``keep_origin=True``: the mesh keeps its own x and y origin (no xy centring) and is only lifted
  (or lowered) along z so that its lowest point is at z = 0. Keeping the mesh's own z as well
  would put part of it under the table or in the air, so z is always adjusted; the shift applied
  is :meth:`Scene.object_offset`.

The planar pose (x, y, yaw) then puts the object frame at (x, y, 0) rotated by yaw about the
vertical: ``p_world = Rz(yaw) p_object + (x, y, 0)``. Yaw therefore turns the object about the
centre of its xy bounding box (default) or about its own origin (keep_origin). Top-grasp
coordinates are relative to this object frame.

The table is a rectangle of ``table_size`` (default 1 m x 1 m) centred at the world origin; a pose
whose origin is off the table, or non-finite, raises ValueError.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np

from .library import load_object
from .mesh_io import ObjectModel


def planar_pose_matrix(x: float, y: float, yaw: float) -> np.ndarray:
    """4x4 rigid transform: rotation yaw about z, translation (x, y, 0)."""
    c, s = np.cos(yaw), np.sin(yaw)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[0, 3], T[1, 3] = x, y
    return T


@dataclass
class _Placed:
    source: ObjectModel      # the object as loaded (its own frame)
    canonical: ObjectModel   # after the centring (object frame)
    offset: np.ndarray       # (3,) translation from the source frame to the object frame
    pose: Tuple[float, float, float]
    keep_origin: bool


class Scene:
    """One or more objects on a table, each at a planar pose (x, y, yaw).

    Args:
        table_size: (sx, sy) of the table top in metres, centred at the world origin.

    Example:
        >>> scene = Scene()
        >>> i = scene.add_object("mug", x=0.05, y=-0.02, yaw=np.pi / 4)
        >>> V, F = scene.object_mesh_world(i)
    """

    def __init__(self, table_size: Sequence[float] = (1.0, 1.0)):
        ts = np.asarray(table_size, dtype=np.float64).reshape(-1)
        if ts.shape != (2,) or not np.all(np.isfinite(ts)) or np.any(ts <= 0):
            raise ValueError(f"table_size must be two finite positive lengths (m), got {table_size!r}")
        self.table_size = (float(ts[0]), float(ts[1]))
        self._objects: List[_Placed] = []

    @classmethod
    def single(cls, obj: Union[str, ObjectModel], x: float = 0.0, y: float = 0.0, yaw: float = 0.0,
               keep_origin: bool = False, table_size: Sequence[float] = (1.0, 1.0)) -> "Scene":
        """A scene with one object (built-in name, path or ObjectModel) at (x, y, yaw)."""
        s = cls(table_size)
        s.add_object(obj, x, y, yaw, keep_origin=keep_origin)
        return s

    # ---- building ----------------------------------------------------------------------------
    def add_object(self, obj: Union[str, ObjectModel], x: float = 0.0, y: float = 0.0,
                   yaw: float = 0.0, keep_origin: bool = False,
                   density: Optional[float] = None) -> int:
        """Put an object on the table; returns its index.

        Args:
            obj: an :class:`ObjectModel`, a built-in name or a mesh path (see load_object).
            x, y: position of the object frame's origin on the table (m).
            yaw: rotation about the vertical (rad).
            keep_origin: keep the mesh's own xy origin instead of centring its xy bounding box.
            density: kg/m^3 when ``obj`` is a name or path.
        """
        model = obj if isinstance(obj, ObjectModel) else load_object(obj, density=density)
        pose = self._check_pose(x, y, yaw)
        lo, hi = model.bounds
        if keep_origin:
            offset = np.array([0.0, 0.0, -lo[2]])
        else:
            offset = np.array([-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2]])
        T = np.eye(4)
        T[:3, 3] = offset
        canonical = model.transformed(T)
        self._objects.append(_Placed(model, canonical, offset, pose, bool(keep_origin)))
        return len(self._objects) - 1

    def set_pose(self, i: int, x: float, y: float, yaw: float) -> None:
        """Move object ``i`` to the planar pose (x, y, yaw)."""
        self._get(i).pose = self._check_pose(x, y, yaw)

    def _check_pose(self, x, y, yaw):
        try:
            vals = [float(x), float(y), float(yaw)]
        except (TypeError, ValueError):
            raise ValueError(f"pose (x, y, yaw) must be three numbers, got {(x, y, yaw)!r}") from None
        for nm, v in zip(("x", "y", "yaw"), vals):
            if not np.isfinite(v):
                raise ValueError(f"pose {nm} must be finite, got {v}")
        hx, hy = self.table_size[0] / 2, self.table_size[1] / 2
        if abs(vals[0]) > hx or abs(vals[1]) > hy:
            raise ValueError(f"pose (x={vals[0]}, y={vals[1]}) is outside the table "
                             f"[-{hx}, {hx}] x [-{hy}, {hy}] m")
        return tuple(vals)

    def _get(self, i) -> _Placed:
        if not isinstance(i, (int, np.integer)) or not 0 <= i < len(self._objects):
            raise ValueError(f"object index i must be an integer in [0, {len(self._objects)}), got {i!r}")
        return self._objects[int(i)]

    # ---- queries -----------------------------------------------------------------------------
    def __len__(self) -> int:
        return len(self._objects)

    @property
    def n_objects(self) -> int:
        return len(self._objects)

    def object(self, i: int = 0) -> ObjectModel:
        """Object ``i`` as loaded (its own frame, before centring)."""
        return self._get(i).source

    def canonical_object(self, i: int = 0) -> ObjectModel:
        """Object ``i`` after the centring: the mesh in the object frame (min z = 0)."""
        return self._get(i).canonical

    def object_offset(self, i: int = 0) -> np.ndarray:
        """(3,) translation taking the loaded mesh's frame to the object frame."""
        return self._get(i).offset.copy()

    def planar_pose(self, i: int = 0) -> Tuple[float, float, float]:
        """(x, y, yaw) of object ``i``."""
        return self._get(i).pose

    def object_pose(self, i: int = 0) -> np.ndarray:
        """4x4 transform from object ``i``'s object frame to the world."""
        return planar_pose_matrix(*self._get(i).pose)

    def object_mesh_world(self, i: int = 0) -> Tuple[np.ndarray, np.ndarray]:
        """(V, F) of object ``i`` in the world: V (N, 3) float64, F (M, 3) int32, C-contiguous."""
        p = self._get(i)
        T = planar_pose_matrix(*p.pose)
        V = p.canonical.vertices @ T[:3, :3].T + T[:3, 3]
        return np.ascontiguousarray(V), p.canonical.faces.copy()

    def object_mass_properties_world(self, i: int = 0) -> dict:
        """Mass properties of object ``i`` in the world frame.

        Returns dict with ``volume``, ``mass``, ``com`` (3,) and ``inertia`` (3, 3) about the
        centre of mass, axes of the world frame.
        """
        p = self._get(i)
        T = planar_pose_matrix(*p.pose)
        R = T[:3, :3]
        mp = p.canonical.mass_properties
        mp["com"] = R @ mp["com"] + T[:3, 3]
        mp["inertia"] = R @ mp["inertia"] @ R.T
        return mp

    def bounds(self) -> np.ndarray:
        """(2, 3) bounding box of all objects in the world frame."""
        if not self._objects:
            raise ValueError("the scene has no objects")
        Vs = [self.object_mesh_world(i)[0] for i in range(len(self))]
        allv = np.vstack(Vs)
        return np.stack([allv.min(axis=0), allv.max(axis=0)])

    def table_mesh(self, thickness: float = 0.02) -> Tuple[np.ndarray, np.ndarray]:
        """(V, F) of the table as a box whose top face is at z = 0."""
        from .primitives import box

        sx, sy = self.table_size
        V, F = box([0.0, 0.0, -thickness / 2], [sx / 2, sy / 2, thickness / 2])
        return V, F.astype(np.int32)

    def __repr__(self) -> str:
        items = ", ".join(f"{p.source.name}@({p.pose[0]:.3f}, {p.pose[1]:.3f}, {p.pose[2]:.3f})"
                          for p in self._objects)
        return f"Scene(table {self.table_size[0]} x {self.table_size[1]} m: {items})"


#: Alias: every scene is a table-top scene.
TableScene = Scene
