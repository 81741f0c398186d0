"""Figures of bayesgrasp's results: a scene, a grasp, registrations, a category grasp, fusion rounds
and a touch's fitness landscape, saved as PNG (:mod:`bayesgrasp.viz`)."""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Optional, Sequence, Tuple

import matplotlib.pyplot as plt
import numpy as np

from .draw import (new_axes, draw_meshes, grid_quad_mesh, box_mesh, capsule_mesh, draw_points, set_equal_aspect, save_figure)

def plot_scene(scene, path=None, title: Optional[str] = None, extra: Optional[Callable] = None,
               extra_meshes: Sequence[tuple] = (),
               colors: Sequence[str] = ("tab:orange", "tab:blue", "tab:green", "tab:red"),
               elev: float = 28.0, azim: float = -60.0, table_margin: float = 0.05):
    """Draw a scene's objects on (a patch of) its table; save a PNG when ``path`` is given.

    Args:
        scene: a :class:`~bayesgrasp.objects.Scene`.
        path: output image path, or None to return the open figure.
        title: figure title.
        extra: ``extra(ax)`` called after the objects are drawn (e.g. contact points).
        extra_meshes: more ``(V, F, color[, alpha[, cull]])`` drawn in the same depth-sorted
            collection as the objects (e.g. the hand's links from :func:`box_mesh` /
            :func:`capsule_mesh`), so that they occlude each other correctly.
        table_margin: how far (m) the drawn table patch extends beyond the objects.

    Returns:
        the saved path, or ``(fig, ax)`` when ``path`` is None.
    """
    fig, ax = new_axes(elev=elev, azim=azim)
    lo, hi = scene.bounds()
    sx, sy = scene.table_size
    x0, x1 = max(lo[0] - table_margin, -sx / 2), min(hi[0] + table_margin, sx / 2)
    y0, y1 = max(lo[1] - table_margin, -sy / 2), min(hi[1] + table_margin, sy / 2)
    TV, TF = grid_quad_mesh(x0, x1, y0, y1, 0.0, 24)
    items = [(TV, TF, (0.85, 0.80, 0.70), 1.0, False)]
    for i in range(len(scene)):
        V, F = scene.object_mesh_world(i)
        items.append((V, F, colors[i % len(colors)]))
    items += list(extra_meshes)
    draw_meshes(ax, items)
    if extra is not None:
        extra(ax)
    ax.set_title(title or repr(scene), fontsize=9)
    if path is None:
        return fig, ax
    return save_figure(fig, path)


def plot_registrations(cloud: np.ndarray, models: Sequence, results: Sequence, path, max_points: int = 4000) -> None:
    """A PNG with one 3-D panel per model: the model's surface samples (grey) moved by the
    registration, and the partial cloud (red) over them. ``results``: the
    :class:`bayesgrasp.vision.RegistrationResult` of each model, in order."""
    from bayesgrasp.vision import model_samples

    n = len(results)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig = plt.figure(figsize=(4.2 * cols, 4.2 * rows))
    rng = np.random.default_rng(0)
    C = np.asarray(cloud)[np.isfinite(cloud).all(axis=1)]
    if len(C) > max_points:
        C = C[rng.choice(len(C), max_points, replace=False)]
    for k, (m, r) in enumerate(zip(models, results)):
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        P, _ = model_samples(m, samples=3000)
        P = P @ r.transform[:3, :3].T + r.transform[:3, 3]
        ax.scatter(P[:, 0], P[:, 1], P[:, 2], s=1, c="0.6", alpha=0.5)
        ax.scatter(C[:, 0], C[:, 1], C[:, 2], s=1, c="tab:red")
        title = f"{r.model}\n" + (f"fit {r.fitness:.2f}  rmse {r.rmse * 1e3:.1f} mm  w {r.weight:.2f}"
                                  if r.success else f"failed: {r.reason[:40]}")
        ax.set_title(title, fontsize=9)
        allp = np.vstack([P, C])
        mid, half = allp.mean(axis=0), (allp.max(axis=0) - allp.min(axis=0)).max() / 2
        ax.set_xlim(mid[0] - half, mid[0] + half)
        ax.set_ylim(mid[1] - half, mid[1] + half)
        ax.set_zlim(mid[2] - half, mid[2] + half)
        ax.set_xlabel("x")
        ax.set_ylabel("y")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def shape_mesh(s) -> Tuple[np.ndarray, np.ndarray]:
    """One hand shape (a :class:`~bayesgrasp.hand.ShapeGeometry`, world frame) as a triangle mesh
    (V, F): a capsule or a box tessellated, a convex shape's own triangles."""
    if s.type == "capsule":
        return capsule_mesh(s.p0, s.p1, s.radius)
    if s.type == "convex":
        return np.asarray(s.vertices, float), np.asarray(s.faces)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = s.rotation, s.center
    return box_mesh(T, s.half_extents)


def hand_meshes(hand, joint_angles, hand_pose, color="tab:gray", alpha: float = 1.0) -> list:
    """A hand's collision shapes (a :class:`~bayesgrasp.hand.Hand` at joints and 4x4 pose) as
    ``(V, F, color, alpha)`` meshes for :func:`draw_meshes` / :func:`plot_scene`."""
    items = []
    for s in hand.link_geometry(joint_angles, hand_pose):
        V, F = shape_mesh(s)
        items.append((V, F, color, alpha))
    return items


def plot_grasp(world, grasp, path, title: Optional[str] = None):
    """PNG of the world's scene with the hand closed as in ``grasp`` (a
    :meth:`~bayesgrasp.world.World.grasp` result) and its object contacts marked."""
    pts = np.array([c.point for c in grasp.contacts if not c.on_table]).reshape(-1, 3)
    return plot_scene(
        world.scene, path, title=title,
        extra_meshes=hand_meshes(world.hand, grasp.joint_angles, grasp.hand_pose, alpha=0.9),
        extra=(lambda ax: draw_points(ax, pts, color="red", size=25, front=True)) if len(pts) else None)


def plot_category_grasp(cloud, models: Sequence, transforms: Sequence, weights: Sequence[float], hand, joint_angles,
                        hand_pose, path, title: Optional[str] = None, max_points: int = 3000):
    """PNG of a category grasp (Eq. 4.1): the observed cloud (red points), every training model
    placed by its registration (grey, more opaque for a larger weight; the legend gives each
    weight), the table patch and the hand closed at the executed grasp."""
    import matplotlib.patches as mpatches

    fig, ax = new_axes(figsize=(8, 6.5))
    C = np.asarray(cloud, float)
    if len(C) > max_points:
        C = C[np.random.default_rng(0).choice(len(C), max_points, replace=False)]
    wmax = max(max(weights), 1e-12)
    meshes, handles = [], []
    colors = plt.get_cmap("tab10")
    for k, (m, T, w) in enumerate(zip(models, transforms, weights)):
        T = np.asarray(T, float)
        V = np.asarray(m.vertices) @ T[:3, :3].T + T[:3, 3]
        meshes.append((V, np.asarray(m.faces), colors(k % 10), 0.08 + 0.35 * w / wmax))
        handles.append(mpatches.Patch(color=colors(k % 10), label=f"{getattr(m, 'name', k)}: weight {w:.2f}"))
    meshes += hand_meshes(hand, joint_angles, hand_pose, alpha=0.9)
    lo, hi = C.min(axis=0) - 0.12, C.max(axis=0) + 0.12
    Vt, Ft = grid_quad_mesh(lo[0], hi[0], lo[1], hi[1], 0.0, n=4)
    meshes.append((Vt, Ft, "tan", 0.3))
    draw_meshes(ax, meshes)
    draw_points(ax, C, color="red", size=1.5)
    handles.append(mpatches.Patch(color="red", label="observed cloud"))
    handles.append(mpatches.Patch(color="tab:gray", label="hand at the executed grasp"))
    ax.legend(handles=handles, fontsize=7, loc="upper left")
    set_equal_aspect(ax, lo, np.maximum(hi, lo + 0.05))
    if title:
        ax.set_title(title, fontsize=9)
    return save_figure(fig, path)


def plot_fusion_rounds(names: Sequence[str], rounds: Sequence[dict], true_pose, path, title: Optional[str] = None):
    """PNG of a vision-then-touch episode: the models' weights per round (left) and, from above,
    each model's believed position and yaw per round with the executed grasps and the true pose
    (right; later rounds darker)."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    W = np.array([[r["weights"][n] for n in names] for r in rounds])
    for k, n in enumerate(names):
        a.plot(range(len(rounds)), W[:, k], marker="o", label=n)
    a.set_xlabel("round (0: the first grasp, from vision)")
    a.set_ylabel("model weight w_i")
    a.set_xticks(range(len(rounds)))
    a.set_ylim(0, 1.02)
    a.grid(alpha=0.3)
    a.legend(fontsize=7)
    cmap = plt.get_cmap("tab10")
    for t, r in enumerate(rounds):
        shade = 0.3 + 0.7 * (t + 1) / len(rounds)
        for k, n in enumerate(names):
            x, y, yaw = r["poses"][n]
            b.arrow(100 * x, 100 * y, 1.5 * np.cos(yaw), 1.5 * np.sin(yaw), color=cmap(k % 10), alpha=shade,
                    width=0.05, head_width=0.4)
        gx, gy, gyaw = r["top_grasp"]
        b.plot(100 * gx, 100 * gy, "s" if r["lifted"] else "x", color="k", alpha=shade, ms=8,
               label="grasp (square: lifted)" if t == 0 else None)
    tx, ty, tyaw = true_pose
    b.plot(100 * tx, 100 * ty, "r+", ms=16, mew=2.5, label="true pose")
    b.arrow(100 * tx, 100 * ty, 2 * np.cos(tyaw), 2 * np.sin(tyaw), color="r", width=0.08)
    b.set_aspect("equal")
    b.set_xlabel("x (cm)")
    b.set_ylabel("y (cm)")
    b.set_title("models' poses per round (arrows: yaw), grasps", fontsize=9)
    b.legend(fontsize=7)
    b.grid(alpha=0.3)
    if title:
        fig.suptitle(title, fontsize=10)
    return save_figure(fig, path)


def plot_touch_landscape(landscape: dict, path, title: str = "") -> Path:
    """Pub. I's fitness landscape of one touch: f over (x, y) (log colour scale) at the truth's yaw
    and scale, and f over yaw at the truth's and at the estimate's position, with the truth, the
    initial guess and the estimate marked. ``landscape``: xs, ys (grid axes), f_xy (len(xs), len(ys)),
    yaws, f_yaw_truth, f_yaw_estimate, and truth / initial / estimate as (x, y, yaw, scale)."""
    L = landscape
    truth, initial, est = (np.asarray(L[k], dtype=float) for k in ("truth", "initial", "estimate"))
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5))
    F = np.log10(np.asarray(L["f_xy"], dtype=float).T + 1e-3)
    m = a.pcolormesh(np.asarray(L["xs"]) * 100, np.asarray(L["ys"]) * 100, F, shading="auto", cmap="viridis")
    fig.colorbar(m, ax=a, label="log10(f + 0.001)")
    for p, marker, label in ((truth, "*", "truth"), (initial, "s", "initial guess"), (est, "o", "estimate")):
        a.plot(p[0] * 100, p[1] * 100, marker, color="w", mec="k", ms=11, label=label)
    a.set_xlabel("x (cm)")
    a.set_ylabel("y (cm)")
    a.set_aspect("equal")
    a.legend(fontsize=8, loc="upper right")
    a.set_title(f"f over (x, y) at the true yaw {np.degrees(truth[2]):.1f} deg")
    yaws = np.degrees(np.asarray(L["yaws"], dtype=float))
    b.semilogy(yaws, np.asarray(L["f_yaw_truth"]) + 1e-3, label="at the true position")
    b.semilogy(yaws, np.asarray(L["f_yaw_estimate"]) + 1e-3, label="at the estimated position")
    for p, style, label in ((truth, "k-", "truth"), (initial, "k:", "initial guess"), (est, "r--", "estimate")):
        b.axvline(np.degrees(p[2]), color=style[0], linestyle=style[1:], label=label)
    b.set_xlabel("yaw (deg)")
    b.set_ylabel("f + 0.001")
    b.legend(fontsize=8)
    b.set_title("f over yaw")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save_figure(fig, path)
