"""Where each grasp's IK starts: the joint vectors of a seeded library whose palm poses lie nearest
the grasp.

A library of joint vectors (the joints' mid-range, then ``size - 1`` uniform draws within the
limits from a generator seeded by ``seed``) is put through forward kinematics once per arm, base,
mount and seed. A grasp's starts are the ``k`` library entries whose palm poses are nearest it by

    d = |p - p*| + w angle(R^T R*),     angle = arccos((tr(R^T R*) - 1) / 2),  w = ROTATION_WEIGHT

(w = 0 for position-only IK), nearest first: the damped least squares then begins a short way
from the answer, on a branch that already points the palm about the right way.
"""
from __future__ import annotations

import numpy as np

__all__ = ["LIBRARY_SIZE", "ROTATION_WEIGHT", "nearest_starts", "start_library"]

LIBRARY_SIZE = 1024
ROTATION_WEIGHT = 0.2   # m per rad: a turn of the palm weighs like 0.2 m per radian


def start_library(arm, seed: int, size: int = LIBRARY_SIZE):
    """(q (L, dof), palm rotations (L, 3, 3), palm positions (L, 3)) of the library, kept on the arm
    for the same base, mount, seed and size."""
    key = (int(seed), int(size), arm.base.tobytes(), arm.mount.tobytes())
    cache = arm.__dict__.setdefault("_start_libraries", {})
    if key not in cache:
        rng = np.random.default_rng(seed)
        q = np.vstack([0.5 * (arm.lower + arm.upper), rng.uniform(arm.lower, arm.upper, (size - 1, arm.dof))])
        P = arm.palm_poses(q)
        cache.clear()   # one library per arm: a new base or mount replaces it
        cache[key] = (q, P[:, :3, :3].copy(), P[:, :3, 3].copy())
    return cache[key]


def nearest_starts(arm, P: np.ndarray, k: int, seed: int, position_only: bool = False,
                   size: int = LIBRARY_SIZE) -> np.ndarray:
    """(N, k, dof): for each palm pose of P (N, 4, 4), the k library joint vectors nearest it."""
    q, R, p = start_library(arm, seed, max(size, k))
    d = np.linalg.norm(P[:, None, :3, 3] - p[None], axis=2)                         # (N, L) m
    if not position_only:
        tr = P[:, :3, :3].reshape(len(P), 9) @ R.reshape(len(R), 9).T              # tr(R*^T R) for all pairs
        d = d + ROTATION_WEIGHT * np.arccos(np.clip(0.5 * (tr - 1.0), -1.0, 1.0))
    near = np.argpartition(d, k - 1, axis=1)[:, :k]
    near = np.take_along_axis(near, np.argsort(np.take_along_axis(d, near, axis=1), axis=1), axis=1)
    return q[near]
