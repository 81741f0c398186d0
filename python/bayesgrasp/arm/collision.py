"""The arm's links against the table and the object, for a batch of joint vectors.

* The table is the half-space z < 0 of the table frame (table top at z = 0). A link shape hits it
  when its lowest point is below ``clearance``; that point is computed in closed form, batched
  with numpy, for spheres (c_z - r), cylinders (c_z - h |a_z| - r sqrt(1 - a_z^2), a the axis),
  capsules (c_z - h |a_z| - r) and boxes (c_z - sum_k h_k |R_zk|); any other shape goes through
  coal against a coal.Halfspace.
* The object is its triangle mesh as a coal BVH (OBBRSS). Only shapes whose bounding sphere comes
  within ``clearance`` of the object's bounding box go to coal.collide (with that security
  margin). coal tests the shapes against the mesh's surface: a link wholly inside a closed mesh
  without touching its surface is not seen (the arm's links are larger than the objects' walls
  are thick, so it cannot get there without crossing them).

Shapes fixed to the arm's root are not checked (the base stands where it is mounted), nor the arm
against itself (self-collision is left to the arm's own controller).
"""
from __future__ import annotations

from typing import Optional

import numpy as np

__all__ = ["ArmCollision", "FREE", "HITS_TABLE", "HITS_OBJECT"]

FREE, HITS_TABLE, HITS_OBJECT = 0, 1, 2


def _lowest_z(geom, T: np.ndarray) -> Optional[np.ndarray]:
    """(B,) the lowest z of a coal primitive placed at T (B, 4, 4), or None for other shapes."""
    kind = type(geom).__name__
    cz = T[:, 2, 3]
    az = T[:, 2, 2]   # z of the shape's local z axis (cylinders and capsules lie along it)
    if kind == "Sphere":
        return cz - geom.radius
    if kind == "Cylinder":
        return cz - geom.halfLength * np.abs(az) - geom.radius * np.sqrt(np.maximum(0.0, 1 - az * az))
    if kind == "Capsule":
        return cz - geom.halfLength * np.abs(az) - geom.radius
    if kind == "Box":
        return cz - np.abs(T[:, 2, :3]) @ np.asarray(geom.halfSide)
    return None


def _bounding_radius(geom) -> float:
    kind = type(geom).__name__
    if kind == "Sphere":
        return float(geom.radius)
    if kind == "Cylinder":
        return float(np.hypot(geom.radius, geom.halfLength))
    if kind == "Capsule":
        return float(geom.radius + geom.halfLength)
    if kind == "Box":
        return float(np.linalg.norm(geom.halfSide))
    geom.computeLocalAABB()
    return float(geom.aabb_radius)


def _transform(T: np.ndarray):
    import coal

    return coal.Transform3s(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))


class ArmCollision:
    """The table and (optionally) an object mesh, checked against an arm's link shapes.

    ``object_mesh``: None, a trimesh.Trimesh, or (vertices (V, 3), faces (F, 3)) in the table frame.
    ``clearance``: m, the gap a link must keep from the table and the object.
    """

    def __init__(self, arm, object_mesh=None, table: bool = True, clearance: float = 0.0):
        import coal

        self._coal = coal
        self.arm = arm
        self.table = bool(table)
        self.clearance = float(clearance)
        self.shapes = arm.link_shapes()
        self.radii = np.array([_bounding_radius(g) for _, g, _, _ in self.shapes])
        self.object = None
        if object_mesh is not None:
            if hasattr(object_mesh, "vertices") and hasattr(object_mesh, "faces"):
                V, F = object_mesh.vertices, object_mesh.faces
            else:
                try:
                    V, F = object_mesh
                except (TypeError, ValueError):
                    raise ValueError("object_mesh: expected a trimesh.Trimesh or (vertices, faces)") from None
            V = np.asarray(V, dtype=float)
            F = np.asarray(F)
            if V.ndim != 2 or V.shape[1] != 3 or len(V) < 3 or not np.all(np.isfinite(V)):
                raise ValueError(f"object_mesh: vertices must be finite (V >= 3, 3), got {V.shape}")
            if F.ndim != 2 or F.shape[1] != 3 or len(F) < 1 or F.min() < 0 or F.max() >= len(V):
                raise ValueError(f"object_mesh: faces must be (F, 3) indices into the {len(V)} vertices")
            bvh = coal.BVHModelOBBRSS()
            bvh.beginModel(len(F), len(V))
            bvh.addVertices(V)
            bvh.addTriangles(F.astype(np.int32))
            bvh.endModel()
            self.object = bvh
            self._lo, self._hi = V.min(axis=0), V.max(axis=0)
        self._request = coal.CollisionRequest()
        self._request.security_margin = self.clearance

    def check(self, q: np.ndarray, frames: Optional[np.ndarray] = None) -> np.ndarray:
        """(B,) int: FREE, HITS_TABLE or HITS_OBJECT for each joint vector of q (B, dof); the table
        is reported first when a configuration hits both."""
        F = self.arm.joint_frames(q) if frames is None else frames
        B = F.shape[0]
        out = np.full(B, FREE)
        hit_obj = np.zeros(B, dtype=bool)
        for (name, geom, k, placement), radius in zip(self.shapes, self.radii):
            T = F[:, k] @ placement
            if self.table:
                z = _lowest_z(geom, T)
                hit = z < self.clearance if z is not None else self._table_coal(geom, T)
                out[(out == FREE) & hit] = HITS_TABLE
            if self.object is not None:
                # bounding sphere against the object's box (distance from centre to box)
                c = T[:, :3, 3]
                d = np.linalg.norm(np.maximum(0.0, np.maximum(self._lo - c, c - self._hi)), axis=1)
                for b in np.flatnonzero((d <= radius + self.clearance) & ~hit_obj):
                    res = self._coal.CollisionResult()
                    if self._coal.collide(geom, _transform(T[b]), self.object, self._coal.Transform3s(),
                                          self._request, res):
                        hit_obj[b] = True
        out[(out == FREE) & hit_obj] = HITS_OBJECT
        return out

    def _table_coal(self, geom, T: np.ndarray) -> np.ndarray:
        """coal against the table's half-space z <= clearance (its normal n = +z, offset d: n.x <= d)."""
        hs = self._coal.Halfspace(np.array([0.0, 0.0, 1.0]), self.clearance)
        req = self._coal.CollisionRequest()
        hit = np.zeros(T.shape[0], dtype=bool)
        for b in range(T.shape[0]):
            res = self._coal.CollisionResult()
            hit[b] = self._coal.collide(geom, _transform(T[b]), hs, self._coal.Transform3s(), req, res) > 0
        return hit
