"""Pub. VI's belief over the training models of a category (thesis §4.3, Eqs. 4.4-4.5): per model i
a shape-fit weight w_i and a planar pose p_i = (x, y, yaw) of that model on the table, updated from
the finger joint angles of an executed top grasp; or, beyond the thesis (``belief="particles"``), a
joint particle belief over (model, pose). The updates run in C++ (``_core.belief``:
``map_model_poses``, ``update_model_weights``, ``measurement_log_likelihood``,
``resample_and_jitter``); the planner that uses it is :class:`bayesgrasp.planners.fusion.FusionPlanner`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from .. import _core
from . import relative_planar_pose

_b = _core.belief

__all__ = ["ModelMixtureBelief", "MixtureSettings", "UpdateResult", "LOG_MIN_LIKELIHOOD", "BELIEFS", "wrap"]

BELIEFS = ("map", "particles")

#: log of the smallest normal double (the core's): every likelihood below it means the measurement
#: is impossible under every model (the belief is then kept, and the update says so).
LOG_MIN_LIKELIHOOD = float(_b.LOG_MIN_LIKELIHOOD)


def wrap(a):
    """Angles wrapped into [-pi, pi)."""
    return np.mod(np.asarray(a, dtype=float) + np.pi, 2 * np.pi) - np.pi


@dataclass(frozen=True)
class MixtureSettings:
    """The belief's settings (the fusion planner's settings extend them): belief "map" (the
    thesis's per-model MAP poses) or "particles"; recursive: Eq. 4.5's recursive form; iterations:
    Eq. 4.4 repeated with the prior re-centred at the last iterate; prior_std (m, m, rad) of Eq.
    4.4's prior; measurement_noise (rad) added to the GP variance; particles per model (belief
    "particles"); threads of the C++ updates."""

    belief: str = "map"
    recursive: bool = False
    iterations: int = 1
    prior_std: Sequence[float] = (0.015, 0.015, float(np.radians(15.0)))
    measurement_noise: float = 0.0
    particles_per_model: int = 200
    threads: int = 1

    def __post_init__(self):
        if self.belief not in BELIEFS:
            raise ValueError(f"belief: one of {', '.join(BELIEFS)}; got {self.belief!r}")
        if self.iterations < 1:
            raise ValueError(f"iterations: must be at least 1, got {self.iterations}")
        ps = np.asarray(self.prior_std, dtype=float)
        if ps.shape != (3,) or not np.all(np.isfinite(ps)) or np.any(ps <= 0):
            raise ValueError(f"prior_std: three positive numbers (m, m, rad), got {self.prior_std}")
        if not (np.isfinite(self.measurement_noise) and self.measurement_noise >= 0):
            raise ValueError(f"measurement_noise: must be >= 0, got {self.measurement_noise}")
        if self.particles_per_model < 2:
            raise ValueError(f"particles_per_model: at least 2, got {self.particles_per_model}")


@dataclass
class UpdateResult:
    """What one tactile update did: the weights and poses after it, each model's log-likelihood,
    and whether every likelihood underflowed (the previous weights were then kept)."""

    weights: np.ndarray
    poses: np.ndarray
    log_likelihoods: np.ndarray
    underflow: bool

    def to_dict(self) -> dict:
        return {"weights": self.weights.tolist(), "poses": self.poses.tolist(),
                "log_likelihoods": self.log_likelihoods.tolist(), "underflow": bool(self.underflow)}


class ModelMixtureBelief:
    """Per training model: weight w_i and planar pose p_i (Eqs. 4.4-4.5), or particles per model."""

    def __init__(self, names: Sequence[str], models: Sequence["GraspModels"], weights, poses,
                 settings: Optional[MixtureSettings] = None, seed: int = 0):
        self.names = list(names)
        self.models = list(models)
        self.settings = settings or MixtureSettings()
        w = np.asarray(weights, dtype=float).ravel()
        p = np.atleast_2d(np.asarray(poses, dtype=float))
        if not (len(self.names) == len(self.models) == len(w) == len(p)) or len(w) == 0:
            raise ValueError("names, models, weights, poses: need one of each per model (at least one model)")
        if p.shape[1] != 3 or not np.all(np.isfinite(p)):
            raise ValueError(f"poses: expected finite (M, 3) planar poses, got shape {p.shape}")
        if not np.all(np.isfinite(w)) or np.any(w < 0) or not w.sum() > 0:
            raise ValueError("weights: must be finite, >= 0 and not all zero")
        k = {m.n_joints for m in self.models}
        if len(k) != 1:
            raise ValueError("models: every model must measure the same joints")
        self.k = k.pop()
        self.weights = w / w.sum()
        self.poses = p.copy()
        self.poses[:, 2] = wrap(self.poses[:, 2])
        self._rng = np.random.default_rng(seed)
        self.particles = None
        if self.settings.belief == "particles":
            self._init_particles()

    # ---- particles (beyond the thesis) -------------------------------------------------------------
    def _init_particles(self) -> None:
        s, n = self.settings, self.settings.particles_per_model
        std = np.asarray(s.prior_std, dtype=float)
        self.particles = [pose + self._rng.normal(0.0, 1.0, (n, 3)) * std for pose in self.poses]
        for P in self.particles:
            P[:, 2] = wrap(P[:, 2])
        self.particle_log_weights = [np.full(n, np.log(w / n)) if w > 0 else np.full(n, -np.inf)
                                     for w in self.weights]
        self.poses = np.array([self._mean_pose(P, lw) for P, lw in zip(self.particles, self.particle_log_weights)])

    def _grids(self):
        return [m.table().grid for m in self.models]

    # ---- Eqs. 4.4-4.5 -------------------------------------------------------------------------------
    def update(self, grasp, measurement) -> UpdateResult:
        """The belief after the top grasp ``grasp`` (x, y, yaw, world) read ``measurement``."""
        g = np.asarray(grasp, dtype=float).ravel()
        m = np.asarray(measurement, dtype=float).ravel()
        if g.shape != (3,) or not np.all(np.isfinite(g)):
            raise ValueError(f"grasp: expected a finite top grasp (x, y, yaw), got {grasp}")
        if m.shape != (self.k,) or not np.all(np.isfinite(m)):
            raise ValueError(f"measurement: expected {self.k} finite joint angles, got shape {m.shape}")
        if self.settings.belief == "particles":
            return self._update_particles(g, m)
        return self._update_map(g, m)

    def _pose_options(self):
        o = _b.ModelPoseOptions()
        o.prior_std = np.asarray(self.settings.prior_std, dtype=float)
        o.measurement_noise = float(self.settings.measurement_noise)
        return o

    def _update_map(self, g, m) -> UpdateResult:
        k, o, grids = self.k, self._pose_options(), self._grids()
        poses = self.poses
        for _ in range(self.settings.iterations):
            ups = _b.map_model_poses(grids, 1, 1 + k, k, g, m, poses, o, self.settings.threads)
            poses = np.array([u.pose for u in ups])
        ll = np.array([u.log_likelihood for u in ups])
        w = _b.update_model_weights(ll, self.weights, self.settings.recursive)
        if not w.underflow:   # an impossible measurement moves nothing (the recovery is reported)
            self.poses, self.weights = poses, np.asarray(w.weights)
        return UpdateResult(self.weights.copy(), self.poses.copy(), ll, bool(w.underflow))

    def _update_particles(self, g, m) -> UpdateResult:
        k = self.k
        lls, new_lw = [], []
        for grid, P, lw in zip(self._grids(), self.particles, self.particle_log_weights):
            ll = np.asarray(_b.measurement_log_likelihood(grid, 1, 1 + k, k, g, m, P,
                                                          self.settings.measurement_noise))
            lls.append(ll)
            new_lw.append(lw + ll)
        top = max(float(np.max(x)) for x in new_lw)
        underflow = not max(float(np.max(ll)) for ll in lls) > LOG_MIN_LIKELIHOOD
        if not underflow:
            self.particle_log_weights = [x - top for x in new_lw]
            self._resample_and_move(g, m)
        mass = np.array([np.exp(np.logaddexp.reduce(x)) for x in self.particle_log_weights])
        self.weights = mass / mass.sum()
        self.poses = np.array([self._mean_pose(P, lw) for P, lw in zip(self.particles, self.particle_log_weights)])
        ll_model = np.array([np.logaddexp.reduce(lw + ll) - np.logaddexp.reduce(lw) if np.isfinite(lw).any() else -np.inf
                             for lw, ll in zip(self.particle_log_weights, lls)])
        return UpdateResult(self.weights.copy(), self.poses.copy(), ll_model, underflow)

    def _resample_and_move(self, g, m) -> None:
        """Within each model, systematic resampling when the ESS is below half, then a Gaussian
        jitter of a fifth of the prior sd, the models' total weights kept (C++:
        ``_core.belief.resample_and_jitter``)."""
        std = 0.2 * np.asarray(self.settings.prior_std, dtype=float)
        for i, (P, lw) in enumerate(zip(self.particles, self.particle_log_weights)):
            did, Q, lw_new = _b.resample_and_jitter(P, lw, std, 0.5, int(self._rng.integers(2**31)))
            if did:
                self.particles[i], self.particle_log_weights[i] = np.asarray(Q), np.asarray(lw_new)

    @staticmethod
    def _mean_pose(P, lw) -> np.ndarray:
        if not np.isfinite(lw).any():
            return P.mean(axis=0)
        w = np.exp(lw - np.logaddexp.reduce(lw))
        return np.array([w @ P[:, 0], w @ P[:, 1], np.arctan2(w @ np.sin(P[:, 2]), w @ np.cos(P[:, 2]))])

    # ---- Eq. 4.6's stability term --------------------------------------------------------------------
    def stability(self, grasps) -> np.ndarray:
        """P(S | G, w, p) = sum_i w_i P_i(S | G - p_i) for top grasps (N, 3)."""
        G = np.atleast_2d(np.asarray(grasps, dtype=float))
        out = np.zeros(len(G))
        for i, (model, w) in enumerate(zip(self.models, self.weights)):
            if w <= 0:
                continue
            if self.particles is not None:
                P, lw = self.particles[i], self.particle_log_weights[i]
                pw = np.exp(lw - np.logaddexp.reduce(lw))
                out += w * np.asarray(model.table().expected_stability(G, P, pw, self.settings.threads))
            else:
                out += w * model.table().stability(relative_planar_pose(G, self.poses[i][None, :]))
        return out
