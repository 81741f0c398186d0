"""What a command's JSON carries so that its result can be seen again (``bayesgrasp view``): the
camera's cloud, the belief's particles and a lift test's trace, each cut to a size that keeps the
JSON readable.

    cloud_json(points)                      # at most 2,000 points, 0.1 mm
    belief_json(particles, weights)         # the 200 heaviest particles (x, y, yaw) and their weights
    lift_trace_json(trace, world_pose)      # the object's centre in the hand during the lift, world frame
"""
from __future__ import annotations

from typing import Optional

import numpy as np

MAX_CLOUD_POINTS = 2000
MAX_PARTICLES = 200


def cloud_json(points, max_points: int = MAX_CLOUD_POINTS) -> list:
    """Every k-th point (k so that at most ``max_points`` remain), rounded to 0.1 mm."""
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    step = max(1, int(np.ceil(len(P) / max_points)))
    return np.round(P[::step], 4).tolist()


def belief_json(particles, weights, max_particles: int = MAX_PARTICLES) -> dict:
    """The heaviest ``max_particles`` particles (x, y, yaw) with their normalised weights, heaviest
    first, and how many particles the belief has."""
    X = np.asarray(particles, dtype=float)
    w = np.asarray(weights, dtype=float)
    w = w / w.sum() if w.sum() > 0 else np.full(len(w), 1.0 / max(len(w), 1))
    top = np.argsort(-w, kind="stable")[:max_particles]
    return {"n": int(len(X)), "particles": np.round(X[top, :3], 5).tolist(), "weights": w[top].tolist()}


def lift_trace_json(trace, hand_pose, lifted: Optional[bool] = None) -> dict:
    """A lift trace (:class:`bayesgrasp.lift_trace.LiftTrace`) as the object's path in the hand:
    the object frame's origin at each sample, placed at the grasp (``hand_pose``, world), so that
    a drawn path shows how far the object slipped in the hand; and the last sample's motion of the
    object relative to the hand (4x4, world frame: object pose at the end = this @ at the grasp);
    ``lifted``: the lift test's verdict on the traced run, added when given."""
    H = np.asarray(hand_pose, dtype=float)
    P = trace.object_pose                                   # (S, 4, 4) in the palm frame
    path = P[:, :3, 3] @ H[:3, :3].T + H[:3, 3]
    rel = H @ P[-1] @ np.linalg.inv(trace.reference_pose) @ np.linalg.inv(H)
    doc = {"time": np.round(trace.time, 4).tolist(), "path": np.round(path, 5).tolist(),
           "phase_ends": np.asarray(trace.phase_ends, float).tolist(),
           "displacement": np.round(trace.displacement, 5).tolist(), "slip": rel.tolist()}
    if lifted is not None:
        doc["lifted"] = bool(lifted)
    return doc
