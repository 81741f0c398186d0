"""Drawing primitives on matplotlib (Agg) 3D axes: shaded meshes, boxes, capsules, segments and
points, axes limits and saving (:mod:`bayesgrasp.viz`)."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Optional, Tuple

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402

_LIGHT = np.array([0.4, -0.5, 0.77])
_LIGHT = _LIGHT / np.linalg.norm(_LIGHT)


def _shade(V: np.ndarray, F: np.ndarray, color, alpha: float) -> np.ndarray:
    """Per-face RGBA with Lambert shading (ambient 0.35) from a fixed light direction."""
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, norm, out=np.zeros_like(n), where=norm > 0)
    k = 0.35 + 0.65 * np.clip(n @ _LIGHT, 0.0, 1.0)
    rgba = np.array(to_rgba(color, alpha))
    out = np.tile(rgba, (len(F), 1))
    out[:, :3] = np.clip(rgba[:3] * k[:, None], 0, 1)
    return out


def new_axes(figsize=(7, 6), elev: float = 28.0, azim: float = -60.0):
    """A figure with one 3-D axes at a sensible viewing angle."""
    fig = plt.figure(figsize=figsize)
    ax = fig.add_subplot(111, projection="3d")
    ax.view_init(elev=elev, azim=azim)
    return fig, ax


def _view_dir(ax) -> np.ndarray:
    """Unit vector from the scene towards the camera of a 3-D axes."""
    e, a = np.radians(ax.elev), np.radians(ax.azim)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def _check_mesh(V, F):
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"V must have shape (N, 3), got {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"F must have shape (M, 3), got {F.shape}")
    return V, F


def _polys(ax, V, F, color, alpha, cull):
    V, F = _check_mesh(V, F)
    cols = _shade(V, F, color, alpha)
    if cull:  # back faces of a closed, outward-wound mesh are hidden anyway
        n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        keep = n @ _view_dir(ax) >= 0
        F, cols = F[keep], cols[keep]
    return V[F], cols


def draw_meshes(ax, meshes, edgecolor=None, linewidth: float = 0.3):
    """Draw several meshes as ONE depth-sorted collection (no wrong overlaps between them).

    Args:
        meshes: iterable of ``(V, F, color)`` or ``(V, F, color, alpha)`` or
            ``(V, F, color, alpha, cull)`` tuples; ``cull`` (default True) hides back faces,
            right for closed outward-wound meshes, wrong for open surfaces.
    """
    polys, cols, allv = [], [], []
    for item in meshes:
        V, F, color = item[:3]
        alpha = item[3] if len(item) > 3 else 1.0
        cull = item[4] if len(item) > 4 else True
        P, C = _polys(ax, V, F, color, alpha, cull)
        polys.append(P)
        cols.append(C)
        allv.append(np.asarray(V, dtype=np.float64))
    # edges in the face colour (default) hide the hairline seams between triangles
    cols = np.concatenate(cols)
    coll = Poly3DCollection(np.concatenate(polys), facecolors=cols,
                            edgecolors=edgecolor if edgecolor is not None else cols,
                            linewidths=linewidth)
    ax.add_collection3d(coll)
    _grow_limits(ax, np.vstack(allv))
    return coll


def draw_mesh(ax, V, F, color="tab:orange", alpha: float = 1.0, edgecolor=None, linewidth=0.3,
              cull: bool = True):
    """Draw a triangle mesh (V (N, 3), F (M, 3)) with flat Lambert shading.

    ``cull`` hides faces turned away from the camera (right for closed outward-wound meshes).
    """
    return draw_meshes(ax, [(V, F, color, alpha, cull)], edgecolor, linewidth)


def grid_quad_mesh(x0, x1, y0, y1, z=0.0, n: int = 16):
    """(V, F) of a flat rectangle split into n x n cells (so that depth sorting works)."""
    xs, ys = np.linspace(x0, x1, n + 1), np.linspace(y0, y1, n + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    V = np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, z)])
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    F = np.vstack([np.stack([a, a + n + 1, a + n + 2], 1), np.stack([a, a + n + 2, a + 1], 1)])
    return V, F


_BOX_F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                   [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])


def box_mesh(T, half_extents) -> Tuple[np.ndarray, np.ndarray]:
    """(V, F) of a box with the given half extents at the 4x4 pose T."""
    T = np.asarray(T, dtype=np.float64)
    h = np.asarray(half_extents, dtype=np.float64)
    if T.shape != (4, 4):
        raise ValueError(f"T must be a 4x4 transform, got shape {T.shape}")
    if h.shape != (3,):
        raise ValueError(f"half_extents must have 3 entries, got shape {h.shape}")
    corners = np.array([[(i & 1) * 2 - 1, ((i >> 1) & 1) * 2 - 1, ((i >> 2) & 1) * 2 - 1]
                        for i in range(8)], dtype=np.float64) * h
    return corners @ T[:3, :3].T + T[:3, 3], _BOX_F.copy()


def draw_box(ax, T, half_extents, color="tab:gray", alpha: float = 1.0):
    """Draw a box with the given half extents (3,) at the 4x4 pose T."""
    V, F = box_mesh(T, half_extents)
    return draw_mesh(ax, V, F, color, alpha)


def capsule_mesh(p0, p1, radius: float, n: int = 16, n_cap: int = 5):
    """(V, F) of a capsule from p0 to p1 with the given radius."""
    p0, p1 = np.asarray(p0, dtype=np.float64), np.asarray(p1, dtype=np.float64)
    axis = p1 - p0
    L = np.linalg.norm(axis)
    z = axis / L if L > 0 else np.array([0.0, 0.0, 1.0])
    x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    # profile (r, h) from the bottom pole to the top pole, revolved about the axis
    from bayesgrasp.objects.primitives import revolve

    a = np.linspace(-np.pi / 2, 0, n_cap + 1)
    prof = [(radius * np.cos(t), radius * np.sin(t)) for t in a]
    prof += [(radius * np.cos(t), L - radius * np.sin(t)) for t in a[::-1]]
    prof = np.array(prof)
    prof[0, 0] = prof[-1, 0] = 0.0
    Vl, F = revolve(prof, n)
    V = p0 + Vl[:, :1] * x + Vl[:, 1:2] * y + Vl[:, 2:3] * z
    return V, F


def draw_capsule(ax, p0, p1, radius: float, color="tab:gray", alpha: float = 1.0):
    """Draw a capsule (cylinder with hemispherical ends) from p0 to p1."""
    V, F = capsule_mesh(p0, p1, radius)
    return draw_mesh(ax, V, F, color, alpha)


def draw_segments(ax, P0, P1, color="k", linewidth: float = 1.5):
    """Draw line segments from the rows of P0 (K, 3) to the rows of P1 (K, 3)."""
    P0 = np.atleast_2d(np.asarray(P0, dtype=np.float64))
    P1 = np.atleast_2d(np.asarray(P1, dtype=np.float64))
    coll = Line3DCollection(np.stack([P0, P1], axis=1), colors=color, linewidths=linewidth)
    ax.add_collection3d(coll)
    _grow_limits(ax, np.vstack([P0, P1]))
    return coll


def draw_points(ax, P, color="r", size: float = 12.0, front: bool = False, label: Optional[str] = None):
    """Scatter points P (K, 3); ``front``: drawn over every mesh (e.g. contacts, which would
    otherwise be hidden inside the fingers that make them)."""
    P = np.atleast_2d(np.asarray(P, dtype=np.float64))
    if front:
        ax.computed_zorder = False          # draw in zorder, not by mplot3d's depth sort
        return ax.scatter(P[:, 0], P[:, 1], P[:, 2], c=color, s=size, depthshade=False, zorder=10,
                          edgecolors="k", linewidths=0.6, label=label)
    return ax.scatter(P[:, 0], P[:, 1], P[:, 2], c=color, s=size, depthshade=False, label=label)


def _grow_limits(ax, V):
    lo, hi = V.min(axis=0), V.max(axis=0)
    old = getattr(ax, "_bg_bounds", None)
    if old is not None:
        lo, hi = np.minimum(lo, old[0]), np.maximum(hi, old[1])
    ax._bg_bounds = (lo, hi)
    set_equal_aspect(ax, lo, hi)


def set_equal_aspect(ax, lo=None, hi=None, margin: float = 0.05):
    """Equal scale on x, y, z around the box [lo, hi] (default: everything drawn so far)."""
    if lo is None or hi is None:
        lo, hi = ax._bg_bounds
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    c = (lo + hi) / 2
    r = max(float(np.max(hi - lo)) / 2 * (1 + margin), 1e-3)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.tick_params(labelsize=7)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")


def save_figure(fig, path, dpi: int = 120) -> Path:
    """Save ``fig`` as an image (PNG by the extension), create parent folders, close it."""
    path = Path(os.fspath(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(str(path), dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return path
