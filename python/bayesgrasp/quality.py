"""Grasp quality: the L1 grasp wrench space, Ferrari-Canny epsilon and GWS volume.

Each contact's friction cone is linearised into ``n_edges`` forces with a unit normal
component, f = -n + mu (cos a t1 + sin a t2); its wrench is (f, (p - com) x f / torque_scale),
where ``torque_scale`` is the largest distance from the centre of mass to the object's
surface. The GWS is the convex hull of all contact wrenches (Qhull). epsilon is the radius of
the largest origin-centred ball inside it: > 0 means force closure, <= 0 none (0 when the
wrenches do not span 6-D). Degenerate grasps are never an error::

    eps, vol = epsilon_volume(points, normals, com, torque_scale, mu=0.5)
    eps, vol = epsilon_volume_batch([points_a, points_b], [normals_a, normals_b], com, scale)
"""
from __future__ import annotations

from bayesgrasp._args import c_int
import numpy as np

from bayesgrasp import _core

__all__ = ["DEFAULT_FRICTION", "DEFAULT_CONE_EDGES", "contact_wrenches", "epsilon_volume",
           "epsilon_volume_batch"]

DEFAULT_FRICTION = _core.quality.DEFAULT_FRICTION  # 0.5
DEFAULT_CONE_EDGES = _core.quality.DEFAULT_CONE_EDGES  # 8


def _points(a, name):
    try:
        a = np.asarray(a, dtype=float)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: not a numeric array ({e})") from None
    if a.ndim == 1 and a.size == 0:
        a = a.reshape(0, 3)
    return a


def contact_wrenches(points, normals, com, torque_scale, mu=DEFAULT_FRICTION, n_edges=DEFAULT_CONE_EDGES):
    """The primitive contact wrenches, (K * n_edges, 6) (K rows when ``mu == 0``)."""
    return _core.quality.contact_wrenches(_points(points, "points"), _points(normals, "normals"),
                                          np.asarray(com, dtype=float), float(torque_scale),
                                          float(mu), c_int(n_edges, "n_edges"))


def epsilon_volume(points, normals, com, torque_scale, mu=DEFAULT_FRICTION, n_edges=DEFAULT_CONE_EDGES,
                   volume=True):
    """Epsilon and GWS volume of one grasp.

    Args:
        points: (K, 3) contact points on the object (m); K may be 0.
        normals: (K, 3) outward object surface normals at the contacts.
        com: (3,) centre of mass of the object.
        torque_scale: largest distance from the centre of mass to the surface (m), > 0.
        mu: friction coefficient (default 0.5; 0 for frictionless contacts).
        n_edges: edges of the linearised friction cone (default 8, >= 3).
        volume: also compute the volume (else 0.0).

    Returns:
        ``(epsilon, volume)`` floats.
    """
    return _core.quality.epsilon_volume(_points(points, "points"), _points(normals, "normals"),
                                        np.asarray(com, dtype=float), float(torque_scale),
                                        float(mu), c_int(n_edges, "n_edges"), bool(volume))


def epsilon_volume_batch(points, normals, com, torque_scale, mu=DEFAULT_FRICTION, n_edges=DEFAULT_CONE_EDGES,
                         counts=None, volume=True, threads=0):
    """Epsilon and volume of N grasps of one object, in C++ threads.

    Either ``points`` and ``normals`` are lists of N (K_i, 3) arrays, or they are (M, 3)
    arrays of all contacts, grasp after grasp, and ``counts`` (N,) gives K_i. ``threads``: C++
    threads over the grasps (0 = all cores; the result does not depend on it).

    Returns:
        ``(epsilon, volume)``, two (N,) arrays.
    """
    if counts is None:
        if not isinstance(points, (list, tuple)) or not isinstance(normals, (list, tuple)):
            raise ValueError("points, normals: pass lists of (K_i, 3) arrays, or (M, 3) arrays with counts")
        if len(points) != len(normals):
            raise ValueError(f"points and normals: {len(points)} vs {len(normals)} grasps")
        P = [_points(p, f"points[{i}]") for i, p in enumerate(points)]
        N = [_points(n, f"normals[{i}]") for i, n in enumerate(normals)]
        for i, (p, n) in enumerate(zip(P, N)):
            if p.ndim != 2 or p.shape[1:] != (3,):
                raise ValueError(f"points[{i}]: expected shape (K, 3), got {p.shape}")
            if n.shape != p.shape:
                raise ValueError(f"normals[{i}]: expected shape {p.shape}, got {n.shape}")
        counts = np.array([len(p) for p in P], dtype=np.int64)
        points = np.concatenate(P) if P else np.zeros((0, 3))
        normals = np.concatenate(N) if N else np.zeros((0, 3))
    else:
        points, normals = _points(points, "points"), _points(normals, "normals")
        counts = np.asarray(counts)
        if counts.size and not np.issubdtype(counts.dtype, np.integer):
            raise ValueError(f"counts: expected integers, got dtype {counts.dtype}")
        counts = counts.astype(np.int64)  # int32 would truncate 2**32 + 3 to 3
    return _core.quality.epsilon_volume_batch(points, normals, counts, np.asarray(com, dtype=float),
                                              float(torque_scale), float(mu), c_int(n_edges, "n_edges"), bool(volume),
                                              c_int(threads, "threads"))
