"""Where the hand sits on the flange: the mount, the palm's 4x4 pose in the flange's frame.

The hand frame (:mod:`bayesgrasp.hand`) has its origin at the centre of the palm face and +z
along the approach, out of the palm. Mounted by default, the hand's base (the back of the palm,
its lowest point along z) rests on the flange's face and the approach is the flange's z:

    mount = translation(0, 0, depth),   depth = -min_z(palm shapes in the hand frame)

(0.06 m for the Barrett BH8: its palm box spans z in [-0.06, 0]).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

__all__ = ["default_mount", "mount_pose", "palm_depth"]


def palm_depth(hand) -> float:
    """m: how far the palm's shapes reach behind the palm face (along -z of the hand frame), from
    the hand's palm (link 0) geometry at the open preshape."""
    zs = []
    for g in hand.link_geometry():
        if g.link != 0:
            continue
        if g.type == "capsule":
            zs.append(min(g.p0[2], g.p1[2]) - g.radius)
        elif g.type == "box":
            zs.append(g.center[2] - np.abs(g.rotation[2]) @ g.half_extents)
        elif g.type == "convex":
            zs.append(g.vertices[:, 2].min())
    return float(max(0.0, -min(zs))) if zs else 0.0


def default_mount(hand=None) -> np.ndarray:
    """The palm in the flange's frame with the hand's base on the flange and its approach along the
    flange's z (identity without a hand)."""
    T = np.eye(4)
    if hand is not None:
        T[2, 3] = palm_depth(hand)
    return T


def mount_pose(xyzrpy: Sequence[float]) -> np.ndarray:
    """A mount from X, Y, Z (m), ROLL, PITCH, YAW (rad; R = Rz(yaw) Ry(pitch) Rx(roll), the URDF's
    convention) of the palm in the flange's frame."""
    v = np.asarray(xyzrpy, dtype=float).ravel()
    if v.shape != (6,) or not np.all(np.isfinite(v)):
        raise ValueError(f"mount: expected X, Y, Z, ROLL, PITCH, YAW (m, rad), got {xyzrpy!r}")
    from scipy.spatial.transform import Rotation

    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", v[3:]).as_matrix()   # extrinsic x-y-z = Rz Ry Rx
    T[:3, 3] = v[:3]
    return T
