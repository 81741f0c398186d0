"""The same scene as the browser view, drawn by matplotlib when no browser is installed: the table,
the object's parts, the hand at one step with its fingers at the read joints, the arm (when the
grasp record has a reachable ``arm``) as a stick figure through its base, joint origins, flange and
palm, and the contacts in front; the title says what happened (a failed grasp says so, an
unreachable one says why there is no arm)."""
from __future__ import annotations

from pathlib import Path
from typing import Dict, List

import numpy as np

from .scene import ResultScene, planar_transform

PART_COLOURS = ("tab:orange", "tab:blue", "tab:green", "tab:purple", "tab:olive", "tab:cyan")


def render_step(scene: ResultScene, k: int, path) -> Path:
    """Step ``k`` of ``scene`` as a PNG at ``path``."""
    from ..viz import draw_meshes, draw_points, grid_quad_mesh, hand_meshes, new_axes, save_figure, set_equal_aspect
    from .arm import arm_view, stick_points
    from .serve import hand_named

    fig, ax = new_axes(figsize=(6, 5.5))
    items, lo, hi = [], np.array([-0.08, -0.08, 0.0]), np.array([0.08, 0.08, 0.1])
    if scene.object is not None and scene.object_pose is not None:
        T = planar_transform(scene.object_pose)
        V = scene.object.vertices @ T[:3, :3].T + T[:3, 3]
        F = np.asarray(scene.object.faces)
        ids = np.zeros(len(F), int) if scene.object.parts is None else np.asarray(scene.object.parts)
        for i in np.unique(ids):
            items.append((V, F[ids == i], PART_COLOURS[i % len(PART_COLOURS)]))
        lo, hi = V.min(axis=0) - 0.05, V.max(axis=0) + 0.05
    TV, TF = grid_quad_mesh(lo[0], hi[0], lo[1], hi[1], 0.0, 16)
    items.insert(0, (TV, TF, (0.85, 0.80, 0.70), 1.0, False))
    step = scene.steps[k]
    g = step.grasp
    if g is not None:
        items += hand_meshes(hand_named(g["hand"]), np.asarray(g["joint_positions"]), np.asarray(g["pose"]),
                             alpha=0.85)
    draw_meshes(ax, items)
    arm = arm_view(g)
    if arm is not None and arm.arm is not None:
        S = stick_points(arm.arm, arm.q)
        ax.plot(S[:, 0], S[:, 1], S[:, 2], "-o", color="0.15", lw=3, ms=4, label="arm", zorder=10)
        set_equal_aspect(ax, np.minimum(lo, S.min(axis=0)), np.maximum(hi, S.max(axis=0)))
        ax.legend(loc="upper left", fontsize=8)
    if step.contacts:
        draw_points(ax, np.array([c.point for c in step.contacts]), color="red", size=25, front=True,
                    label="contact")
        ax.legend(loc="upper left", fontsize=8)
    verdict = {"lifted": "lifted", "not lifted": "FAILED: not lifted"}.get(step.outcome, step.outcome)
    note = "" if arm is None else f"; {arm.note}"
    ax.set_title(f"{scene.title}\n{step.label}: {verdict}{note}", fontsize=9)
    return save_figure(fig, path)


def render_steps(scene: ResultScene, paths: Dict[int, object]) -> List[Path]:
    return [render_step(scene, k, p) for k, p in sorted(paths.items())]
