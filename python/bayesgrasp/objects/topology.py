"""Triangle-mesh topology of the object meshes: watertightness (every edge used twice), consistent
winding and its repair, connected components, outward orientation, and the solid check a mesh
must pass to be an object (:mod:`bayesgrasp.objects.mesh_io`)."""
from __future__ import annotations

from collections import deque

import numpy as np

def _edge_use_counts(F: np.ndarray) -> np.ndarray:
    """Number of faces using each undirected edge (one entry per distinct edge)."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    e = np.sort(e, axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return counts


def mesh_is_watertight(F: np.ndarray) -> bool:
    """True when every edge is shared by exactly two faces (closed, edge-manifold)."""
    F = np.asarray(F)
    if len(F) == 0:
        return False
    return bool(np.all(_edge_use_counts(F) == 2))


def _winding_is_consistent(F: np.ndarray) -> bool:
    """True when no directed edge appears twice (neighbours traverse shared edges oppositely)."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    return len(np.unique(e, axis=0)) == len(e)


def _fix_winding(F: np.ndarray) -> np.ndarray:
    """Make face orientation consistent across shared edges (breadth-first over each component).

    Each connected component keeps the orientation of its lowest-index face; the caller flips whole
    components afterwards if their signed volume is negative.
    """
    F = F.copy()
    M = len(F)
    # map undirected edge -> faces using it
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    face_of = np.tile(np.arange(M), 3)
    key = np.sort(edges, axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    key_sorted = key[order]
    same = np.all(key_sorted[1:] == key_sorted[:-1], axis=1)
    neighbours = [[] for _ in range(M)]
    for k in np.nonzero(same)[0]:
        a, b = face_of[order[k]], face_of[order[k + 1]]
        if a != b:
            neighbours[a].append(b)
            neighbours[b].append(a)
    visited = np.zeros(M, dtype=bool)

    def directed(f):
        t = F[f]
        return {(t[0], t[1]), (t[1], t[2]), (t[2], t[0])}

    for seed in range(M):
        if visited[seed]:
            continue
        visited[seed] = True
        queue = deque([seed])
        while queue:
            f = queue.popleft()
            df = directed(f)
            for g in neighbours[f]:
                if visited[g]:
                    continue
                # consistent neighbours share an edge in opposite directions
                if df & directed(g):
                    F[g] = F[g][::-1]
                visited[g] = True
                queue.append(g)
    return F


def _components(F: np.ndarray, n_vertices: int) -> np.ndarray:
    """Connected-component label per face (faces connected through shared vertices)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    rows = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    cols = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    A = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n_vertices, n_vertices))
    _, labels = connected_components(A, directed=False)
    return labels[F[:, 0]]


def orient_outward(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Faces with consistent winding and every closed component's signed volume positive."""
    F = np.asarray(F, dtype=np.int64)
    if not _winding_is_consistent(F):
        F = _fix_winding(F)
    labels = _components(F, len(V))
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    signed = np.einsum("ij,ij->i", a, np.cross(b, c))  # 6 x signed tetra volume about the origin
    vol = np.bincount(labels, weights=signed)
    flip = vol[labels] < 0
    F[flip] = F[flip][:, ::-1]
    return F


def _check_solid(V: np.ndarray, F: np.ndarray, name: str) -> None:
    """ValueError unless the mesh's vertices span three dimensions: a single triangle, a flat
    square or a line has no volume, mass or convex hull (Qhull fails on it)."""
    used = V[np.unique(F)]
    if len(used) < 4:
        raise ValueError(f"mesh '{name}' is degenerate: {len(used)} vertices cannot enclose a volume")
    s = np.linalg.svd(used - used.mean(axis=0), compute_uv=False)
    if not s[2] > 1e-9 * s[0]:
        raise ValueError(f"mesh '{name}' is flat (all its vertices lie in a plane or on a line): "
                         "an object needs a volume")
