"""Mesh primitives of the object library: surfaces of revolution, swept tubes, prisms, boxes
(also subdivided), and joining parts (a boolean union when ``manifold3d`` is installed). Each
returns (V float64 (N, 3), F int64 (M, 3)), closed and wound outward."""
from __future__ import annotations

import numpy as np

from .topology import orient_outward

def revolve(profile, n: int):
    """Closed surface of revolution about the z axis.

    Args:
        profile: (P, 2) points (r, z); the first and last must lie on the axis (r = 0), the others
            have r > 0. The curve between them is swept around z.
        n: segments around the axis.
    """
    prof = np.asarray(profile, dtype=np.float64)
    if prof[0, 0] != 0 or prof[-1, 0] != 0 or np.any(prof[1:-1, 0] <= 0):
        raise ValueError("profile must start and end on the axis (r = 0) with r > 0 in between")
    inner = prof[1:-1]
    P = len(inner)
    th = 2 * np.pi * np.arange(n) / n
    c, s = np.cos(th), np.sin(th)
    rings = np.stack([inner[:, :1] * c, inner[:, :1] * s, np.repeat(inner[:, 1:], n, axis=1)], -1)
    V = np.vstack([[0, 0, prof[0, 1]], rings.reshape(-1, 3), [0, 0, prof[-1, 1]]])
    top = len(V) - 1
    k = np.arange(n)
    k1 = (k + 1) % n
    F = [np.stack([np.zeros(n, int), 1 + k1, 1 + k], 1)]
    for j in range(P - 1):
        a, b = 1 + j * n, 1 + (j + 1) * n
        F.append(np.stack([a + k, a + k1, b + k1], 1))
        F.append(np.stack([a + k, b + k1, b + k], 1))
    last = 1 + (P - 1) * n
    F.append(np.stack([np.full(n, top), last + k, last + k1], 1))
    return V, orient_outward(V, np.vstack(F))


def _frames(path: np.ndarray):
    """Tangents and parallel-transported normals/binormals along a polyline."""
    d = np.gradient(path, axis=0)
    t = d / np.linalg.norm(d, axis=1, keepdims=True)
    ref = np.array([0.0, 0.0, 1.0]) if abs(t[0, 2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    nrm = np.cross(t[0], ref)
    nrm /= np.linalg.norm(nrm)
    N = [nrm]
    for i in range(1, len(t)):
        v = N[-1] - np.dot(N[-1], t[i]) * t[i]
        N.append(v / np.linalg.norm(v))
    N = np.array(N)
    B = np.cross(t, N)
    return t, N, B


def sweep(path, radii, m: int, normal_hint=None):
    """Closed tube of elliptic cross-section swept along a polyline, with flat end caps.

    Args:
        path: (K, 3) centre line.
        radii: (a, b) semi-axes of the cross-section along the frame's normal and binormal.
        m: segments around the cross-section.
        normal_hint: optional (3,) direction for the cross-section's first axis (kept
            perpendicular to the path), e.g. the plane normal of a planar handle.
    """
    path = np.asarray(path, dtype=np.float64)
    K = len(path)
    t, N, B = _frames(path)
    if normal_hint is not None:
        h = np.asarray(normal_hint, dtype=np.float64)
        N = h - np.einsum("ij,j->i", t, h)[:, None] * t
        N /= np.linalg.norm(N, axis=1, keepdims=True)
        B = np.cross(t, N)
    a, b = radii
    ph = 2 * np.pi * np.arange(m) / m
    ring = (a * np.cos(ph))[None, :, None] * N[:, None, :] + (b * np.sin(ph))[None, :, None] * B[:, None, :]
    rings = path[:, None, :] + ring
    V = np.vstack([rings.reshape(-1, 3), path[0], path[-1]])
    c0, c1 = K * m, K * m + 1
    k = np.arange(m)
    k1 = (k + 1) % m
    F = []
    for j in range(K - 1):
        p, q = j * m, (j + 1) * m
        F.append(np.stack([p + k, p + k1, q + k1], 1))
        F.append(np.stack([p + k, q + k1, q + k], 1))
    F.append(np.stack([np.full(m, c0), k1, k], 1))
    last = (K - 1) * m
    F.append(np.stack([np.full(m, c1), last + k, last + k1], 1))
    return V, orient_outward(V, np.vstack(F))


def prism(polygon_xy, z0: float, z1: float):
    """Closed prism: a convex polygon (counter-clockwise, (P, 2)) extruded from z0 to z1."""
    poly = np.asarray(polygon_xy, dtype=np.float64)
    P = len(poly)
    V = np.vstack([np.column_stack([poly, np.full(P, z0)]), np.column_stack([poly, np.full(P, z1)])])
    k = np.arange(P)
    k1 = (k + 1) % P
    F = [np.stack([k, k1, P + k1], 1), np.stack([k, P + k1, P + k], 1)]
    fan = np.arange(1, P - 1)
    F.append(np.stack([np.zeros(P - 2, int), fan + 1, fan], 1))           # bottom
    F.append(np.stack([np.full(P - 2, P), P + fan, P + fan + 1], 1))     # top
    return V, orient_outward(V, np.vstack(F))


def box(center, half_extents):
    """Closed axis-aligned box (12 triangles)."""
    c = np.asarray(center, dtype=np.float64)
    h = np.asarray(half_extents, dtype=np.float64)
    sq = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64) * h[:2] + c[:2]
    return prism(sq, c[2] - h[2], c[2] + h[2])


def grid_box(center, half_extents, n: int):
    """Closed axis-aligned box whose six faces are n x n grids of squares, each split in two
    (12 n^2 triangles): a finely tessellated flat-faced object (the simulator's and the
    benchmarks' large-mesh case)."""
    c = np.asarray(center, dtype=np.float64)
    h = np.asarray(half_extents, dtype=np.float64)
    t = np.linspace(-1.0, 1.0, n + 1)
    gu, gv = (a.ravel() for a in np.meshgrid(t, t, indexing="ij"))
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), indexing="ij"))
    a = i * (n + 1) + j
    b = a + n + 1
    quad = np.concatenate([np.stack([a, b, b + 1], 1), np.stack([a, b + 1, a + 1], 1)])
    V, F = [], []
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for side in (-1.0, 1.0):
            P = np.empty((len(gu), 3))
            P[:, axis], P[:, u], P[:, v] = side, gu, gv
            F.append((quad if side > 0 else quad[:, [0, 2, 1]]) + sum(len(x) for x in V))  # (u, v, axis) right-handed
            V.append(P * h + c)
    V = np.vstack(V)
    return V, orient_outward(V, np.vstack(F))


def _rotate(V, R, t=(0.0, 0.0, 0.0)):
    return V @ np.asarray(R, dtype=np.float64).T + np.asarray(t, dtype=np.float64)




def boolean_available() -> bool:
    """True when the ``manifold3d`` boolean engine can be used by trimesh."""
    try:
        import manifold3d  # noqa: F401
    except Exception:
        return False
    return True


def _combine(parts, use_boolean: bool):
    """Join closed parts: boolean union (overlapping parts) or concatenation (touching parts)."""
    if use_boolean:
        import trimesh

        meshes = [trimesh.Trimesh(V, F, process=False) for V, F in parts]
        u = trimesh.boolean.union(meshes, engine="manifold")
        V = np.asarray(u.vertices, dtype=np.float64)
        F = np.asarray(u.faces, dtype=np.int64)
        return V, orient_outward(V, F)
    Vs, Fs, off = [], [], 0
    for V, F in parts:
        Vs.append(V)
        Fs.append(F + off)
        off += len(V)
    return np.vstack(Vs), np.vstack(Fs)
