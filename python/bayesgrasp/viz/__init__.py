"""Matplotlib (Agg) drawings of meshes, hand links and table-top scenes, saved as PNG.

Generic helpers take plain arrays so that any caller (the demo, the planners) can draw a hand as
boxes / capsules given 4x4 link poses:

* :func:`draw_mesh` (triangle mesh, shaded), :func:`draw_meshes` (several in one depth-sorted
  collection: use it when meshes occlude each other), :func:`draw_box` (box at a pose),
  :func:`draw_capsule`, :func:`draw_segments`, :func:`draw_points`;
* :func:`new_axes`, :func:`set_equal_aspect`, :func:`save_figure`;
* :func:`plot_scene` draws a :class:`~bayesgrasp.objects.Scene` (table patch and objects) and
  optional extra drawing via a callback;
* :func:`hand_meshes` (a hand's collision shapes as meshes) and :func:`plot_grasp` (a
  :class:`~bayesgrasp.world.World` grasp: the scene, the closed hand, the object contacts).
"""
from __future__ import annotations

from .draw import (box_mesh, capsule_mesh, draw_box, draw_capsule, draw_mesh, draw_meshes, draw_points,
                   draw_segments, grid_quad_mesh, new_axes, save_figure, set_equal_aspect)
from .plots import (hand_meshes, plot_category_grasp, plot_fusion_rounds, plot_grasp, plot_registrations,
                    plot_scene, plot_touch_landscape, shape_mesh)

__all__ = ["box_mesh", "capsule_mesh", "draw_box", "draw_capsule", "draw_mesh", "draw_meshes", "draw_points",
           "draw_segments", "grid_quad_mesh", "new_axes", "save_figure", "set_equal_aspect", "hand_meshes",
           "plot_category_grasp", "plot_fusion_rounds", "plot_grasp", "plot_registrations", "plot_scene",
           "plot_touch_landscape", "shape_mesh"]
