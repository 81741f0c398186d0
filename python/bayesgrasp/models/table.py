"""The grasp models tabulated over relative grasps (C++ ``RelativePoseGrid``): the planners look up
P(S) and the measurement moments at every (candidate grasp, particle) pair instead of evaluating
the GPs."""
from __future__ import annotations

import numpy as np

from .. import _core
from .settings import N_BEST


class ModelTable:
    """:class:`~bayesgrasp.models.GraspModels` on a grid: trilinear lookups, batched in C++."""

    def __init__(self, grid, n_joints: int, box: np.ndarray, best: np.ndarray):
        self.grid, self.n_joints, self.box, self.best = grid, int(n_joints), np.asarray(box, float), best

    @classmethod
    def build(cls, models: "GraspModels", xy_step: float, yaw_step: float) -> "ModelTable":
        if not (xy_step > 0 and yaw_step > 0):
            raise ValueError("table: steps must be positive")
        box = models.grasp_box()
        nx = max(2, int(np.ceil((box[1, 0] - box[0, 0]) / xy_step)) + 1)
        ny = max(2, int(np.ceil((box[1, 1] - box[0, 1]) / xy_step)) + 1)
        nyaw = max(4, int(np.ceil(2 * np.pi / yaw_step)))
        xs, ys = np.linspace(box[0, 0], box[1, 0], nx), np.linspace(box[0, 1], box[1, 1], ny)
        yaws = -np.pi + 2 * np.pi * np.arange(nyaw) / nyaw
        X, Y, T = np.meshgrid(xs, ys, yaws, indexing="ij")
        rel = np.column_stack([X.ravel(), Y.ravel(), T.ravel()])
        k = models.n_joints
        values = np.empty((len(rel), 1 + 2 * k))
        for s in range(0, len(rel), 65536):  # bounded memory
            part = rel[s:s + 65536]
            values[s:s + 65536, 0] = models.stability_probability(part)
            mean, var = models.predict_measurement(part)
            values[s:s + 65536, 1:1 + k], values[s:s + 65536, 1 + k:] = mean, var
        outside = np.full(1 + 2 * k, np.nan)
        outside[0] = 0.0
        grid = _core.belief.RelativePoseGrid(box[0].copy(), box[1].copy(), nx, ny, nyaw, values, outside)
        # the planners' PSO seeds: the nodes of highest P(S), best first
        top = np.argpartition(-values[:, 0], N_BEST - 1)[:N_BEST]
        return cls(grid, k, box, rel[top[np.argsort(-values[top, 0])]])

    def best_relative_grasps(self, k: int = 64) -> np.ndarray:
        """The k grid nodes with the highest P(S) (k, 3), best first (found when the table is built)."""
        if not 1 <= k <= len(self.best):
            raise ValueError(f"k: between 1 and {len(self.best)}, got {k}")
        return self.best[:k]

    def stability(self, rel) -> np.ndarray:
        """P(S) at relative grasps (P, 3)."""
        return self.grid.interpolate(np.atleast_2d(np.asarray(rel, dtype=float)))[:, 0]

    def expected_stability(self, actions, poses, weights, threads: int = 1) -> np.ndarray:
        """Eq. 3.1's integral over a particle belief: sum_j w_j P(S | a relative to pose_j), (A,)."""
        return self.grid.expected(np.atleast_2d(np.asarray(actions, float)), np.asarray(poses, float),
                                  np.asarray(weights, float), 0, int(threads))

    def measurement_pairs(self, actions, poses, threads: int = 1):
        """Measurement mean and variance at every (action, pose) pair: two (A, N, K) arrays."""
        A = np.atleast_2d(np.asarray(actions, float))
        P = np.asarray(poses, float)
        k = self.n_joints
        out = self.grid.interpolate_pairs(A, P, 1, 2 * k, int(threads)).reshape(len(A), len(P), 2 * k)
        return out[..., :k], np.maximum(out[..., k:], 1e-12)

    def expected_posterior_entropy(self, actions, poses, log_weights, n_samples: int = 100, seed: int = 0,
                                   threads: int = 1):
        """Eq. 3.2 (weight-based) for every action: (entropy (A,), standard error (A,))."""
        k = self.n_joints
        return self.grid.expected_posterior_entropy(np.atleast_2d(np.asarray(actions, float)),
                                                    np.asarray(poses, float), np.asarray(log_weights, float),
                                                    1, 1 + k, k, int(n_samples), int(seed), int(threads))
