"""The arm of a grasp record (the grasp schema's ``arm``, written with ``--robot``) as things to
draw: the arm loaded from the record's URDF with its base, flange and mount
(:class:`bayesgrasp.arm.Arm`), each moving collision shape as a mesh in its own frame with its
4x4 pose in the table frame at the record's joints, and the stick figure through the base, the
joint origins, the flange and the palm.

A shape's pose is the forward kinematics of its joint times its placement,
T_shape(q) = T_joint(q) M_shape (:meth:`Arm.joint_frames`, :meth:`Arm.link_shapes`).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import List, Optional, Tuple

import numpy as np

__all__ = ["ArmView", "arm_view", "shape_local_mesh"]


@dataclass
class ArmView:
    """What a step draws of its arm: ``arm`` and the joints at the grasp (``q``) and pre-grasp
    (``q_pre``, or None), or no arm (``arm`` None) and ``note`` saying why."""

    arm: Optional[object]
    q: Optional[np.ndarray] = None
    q_pre: Optional[np.ndarray] = None
    note: str = ""


def _as_key(a) -> tuple:
    return tuple(float(v) for v in np.asarray(a, float).ravel())


@lru_cache(maxsize=8)
def _load(urdf: str, flange: str, mount: tuple, base: tuple):
    from ..arm import Arm

    return Arm.load(urdf, flange=flange, mount=np.reshape(mount, (4, 4)), base=np.reshape(base, (4, 4)))


def _urdf(path: str) -> str:
    """The record's URDF path, or the built-in arm of the same file name when the path is gone
    (a record written in another checkout)."""
    from ..arm import ROBOTS_DIR

    p = Path(path)
    if not p.is_file() and (ROBOTS_DIR / p.name).is_file():
        return str(ROBOTS_DIR / p.name)
    return path


def arm_view(grasp: Optional[dict]) -> Optional[ArmView]:
    """The arm of a grasp record: None when the record has no ``arm``; an :class:`ArmView` with
    no arm and the reason when the grasp is unreachable or the arm cannot be loaded."""
    rec = (grasp or {}).get("arm")
    if not rec:
        return None
    if not rec.get("reachable") or rec.get("joint_positions") is None:
        return ArmView(None, note=f"arm: unreachable ({rec.get('reason') or 'no reason given'})")
    try:
        arm = _load(_urdf(rec["urdf"]), rec.get("flange_link"), _as_key(rec["mount"]), _as_key(rec["base"]))
    except (KeyError, ValueError, OSError) as e:
        return ArmView(None, note=f"arm: cannot be drawn ({e})")
    if list(rec.get("joint_names") or arm.joint_names) != list(arm.joint_names):
        return ArmView(None, note=f"arm: the record's joints {rec['joint_names']} are not the URDF's chain "
                                  f"{arm.joint_names}")
    try:
        q = arm.check_q(rec["joint_positions"], "arm.joint_positions")[0]
        pre = rec.get("pregrasp_joint_positions")
        q_pre = None if pre is None else arm.check_q(pre, "arm.pregrasp_joint_positions")[0]
    except ValueError as e:
        return ArmView(None, note=f"arm: cannot be drawn ({e})")
    return ArmView(arm, q, q_pre, note=f"arm: {Path(arm.urdf).stem}, reachable")


def shape_local_mesh(geom) -> Optional[Tuple[np.ndarray, np.ndarray]]:
    """A coal collision shape as a triangle mesh (V, F) in the shape's own frame: spheres,
    cylinders and capsules (along z, centred), boxes, meshes (BVH) and convex hulls; None for
    any other shape."""
    import trimesh

    kind = type(geom).__name__
    if kind == "Sphere":
        m = trimesh.creation.icosphere(subdivisions=2, radius=geom.radius)
    elif kind == "Cylinder":
        m = trimesh.creation.cylinder(radius=geom.radius, height=2 * geom.halfLength, sections=24)
    elif kind == "Capsule":
        m = trimesh.creation.capsule(height=2 * geom.halfLength, radius=geom.radius, count=[16, 16])
    elif kind == "Box":
        m = trimesh.creation.box(extents=2 * np.asarray(geom.halfSide, float))
    elif kind.startswith("BVHModel"):
        F = np.array([[t[i] for i in range(3)] for t in (geom.tri_indices(j) for j in range(geom.num_tris))])
        return np.asarray(geom.vertices(), float), F.reshape(-1, 3).astype(np.int32)
    elif hasattr(geom, "points"):      # a convex shape: its hull's triangles
        m = trimesh.convex.convex_hull(np.asarray(geom.points(), float))
    else:
        return None
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int32)


def link_poses(arm, q) -> List[Tuple[str, object, np.ndarray]]:
    """(unique name, coal shape, 4x4 pose in the table frame) of each moving collision shape at
    joints ``q``: T_joint(q) M_shape."""
    T = arm.joint_frames(q)[0]
    out, count = [], {}
    for name, geom, k, M in arm.link_shapes():
        i = count[name] = count.get(name, -1) + 1
        out.append((f"{name.replace('/', '_')}-{i}", geom, T[k] @ M))
    return out


def link_meshes(arm, q) -> List[Tuple[str, np.ndarray, np.ndarray, np.ndarray]]:
    """(name, V, F, 4x4 pose) per moving collision shape at joints ``q``: the mesh in the shape's
    frame, placed by the pose (shapes with no mesh are left out)."""
    out = []
    for name, geom, T in link_poses(arm, q):
        mesh = shape_local_mesh(geom)
        if mesh is not None:
            out.append((name, mesh[0], mesh[1], T))
    return out


def stick_points(arm, q) -> np.ndarray:
    """(dof + 3, 3): the arm as a polyline in the table frame: the base, each joint's origin, the
    flange and the palm."""
    T = arm.joint_frames(q)[0]
    return np.vstack([arm.base[:3, 3], T[:, :3, 3], arm.flange_poses(q)[0, :3, 3], arm.palm_poses(q)[0, :3, 3]])
