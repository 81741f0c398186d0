"""Vision, then touch (thesis §4.3, Pub. VI, Eqs. 4.2-4.6): per-model pose and shape-weight
updates from the fingers, and the grasp that is most likely both stable and task-compatible.

The belief is, per training model i of the category, a shape-fit weight w_i and a planar pose
p_i = (x, y, yaw) of that model on the table (:class:`ModelMixtureBelief`). Vision gives w_i(0)
(the normalised registration weights phi(delta_i)) and p_i(0) (the registrations' planar part).
After a top grasp G (x, y, yaw) whose fingers read m:

* Eq. 4.4: every p_i moves to its MAP pose under model i's measurement GP and a Gaussian prior
  around p_i(t-1) (C++: ``_core.belief.map_model_poses``, trust region, batched over models);
* Eq. 4.5: w_i = L_i / sum_j L_j with L_i the measurement's likelihood at p_i(t) (as the thesis
  writes it, the previous weights forgotten; ``recursive=True`` gives w_i ~ w_i(t-1) L_i).

The next grasp maximises (Eq. 4.6) P(S and T | G, w, p) = P(S | G, w, p) P(T | G, w, p) with

* P(S | G, w, p) = sum_i w_i P_i(S | G - p_i), model i's stability model (learnt from lift
  outcomes, calibrated) tabulated over relative top grasps;
* P(T | G, w, p) = sum_i w_i sum_k Laplace(G; p_i o theta_ik), the demonstrated top task grasps
  theta_ik of model i (planar: x, y, yaw in the model's frame) placed by p_i, with
  Laplace(d) = exp(-(|d_xy| / b_t + |d_yaw| / b_yaw)).

Round 1 uses the task term alone (Fig. 4.4); later rounds the product. The search is PSO over
(x, y, yaw), its swarm seeded with the previous round's grasp and the mapped task grasps.

Beyond the thesis (``belief="particles"``): a joint particle belief over (model, pose) in place
of the per-model MAP poses - particles per model, weighted by the measurement likelihood, the model
weights being the particle weights' sums - with the same interface.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, List, Optional, Sequence

import numpy as np

from .. import _core, optim
from ..belief import absolute_planar_pose_paired, relative_planar_pose
from ..models import GraspModels
from .part_check import choose_lazily

_b = _core.belief

BELIEFS = ("map", "particles")
TASK_TERMS = ("laplace", "part-aware")

#: log of the smallest normal double: every likelihood below it means the measurement is
#: impossible under every model (the belief is then kept, and the update says so).
LOG_MIN_LIKELIHOOD = -708.3964185322641


def wrap(a):
    return np.mod(np.asarray(a, dtype=float) + np.pi, 2 * np.pi) - np.pi


@dataclass(frozen=True)
class FusionSettings:
    """belief: "map" (the thesis's per-model MAP poses) or "particles"; recursive: Eq. 4.5's
    recursive form; iterations: Eq. 4.4 repeated with the prior re-centred at the last iterate;
    prior_std (m, m, rad) of Eq. 4.4's prior; measurement_noise (rad) added to the GP variance;
    laplace_translation / laplace_rotation: Eq. 4.6's task-term scales b_t (m), b_yaw (rad);
    search_margin: the grasp search box is the weighted model poses' x, y extent plus this (m);
    PSO size; particles per model (belief "particles")."""

    belief: str = "map"
    recursive: bool = False
    iterations: int = 1
    prior_std: Sequence[float] = (0.015, 0.015, float(np.radians(15.0)))
    measurement_noise: float = 0.0
    laplace_translation: float = 0.01
    laplace_rotation: float = float(np.radians(10.0))
    search_margin: float = 0.03
    pso_particles: int = 32
    pso_iter: int = 30
    particles_per_model: int = 200
    threads: int = 1
    # task_term "part-aware" (beyond the thesis): Eq. 4.6's optimum, the mapped task grasps and
    # perturbations of them (half-widths m, rad) up to part_candidates, closed on every model at its
    # pose; the chosen one maximises P(S | G) P(T | G) x P(rule, held | G) (stability counts from
    # round 1 on) and passes the task's rule on some model whenever one does (planners.part_check.choose)
    task_term: str = "laplace"
    part_candidates: int = 48
    part_translation: float = 0.01
    part_rotation: float = float(np.radians(20.0))

    def __post_init__(self):
        if self.belief not in BELIEFS:
            raise ValueError(f"belief: one of {', '.join(BELIEFS)}; got {self.belief!r}")
        if self.task_term not in TASK_TERMS:
            raise ValueError(f"task_term: one of {', '.join(TASK_TERMS)}; got {self.task_term!r}")
        if self.part_candidates < 1:
            raise ValueError(f"part_candidates: at least 1, got {self.part_candidates}")
        for name in ("part_translation", "part_rotation"):
            if not (np.isfinite(getattr(self, name)) and getattr(self, name) >= 0):
                raise ValueError(f"{name}: must be >= 0, got {getattr(self, name)}")
        if self.iterations < 1:
            raise ValueError(f"iterations: must be at least 1, got {self.iterations}")
        ps = np.asarray(self.prior_std, dtype=float)
        if ps.shape != (3,) or not np.all(np.isfinite(ps)) or np.any(ps <= 0):
            raise ValueError(f"prior_std: three positive numbers (m, m, rad), got {self.prior_std}")
        for name in ("laplace_translation", "laplace_rotation", "search_margin"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name}: must be positive, got {getattr(self, name)}")
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


class ModelMixtureBelief:
    """Per training model: weight w_i and planar pose p_i (Eqs. 4.4-4.5), or particles per model."""

    def __init__(self, names: Sequence[str], models: Sequence[GraspModels], weights, poses,
                 settings: Optional[FusionSettings] = None, seed: int = 0):
        self.names = list(names)
        self.models = list(models)
        self.settings = settings or FusionSettings()
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
        jitter of a fifth of the prior sd (the models' total weights are kept)."""
        std = 0.2 * np.asarray(self.settings.prior_std, dtype=float)
        for i, (P, lw) in enumerate(zip(self.particles, self.particle_log_weights)):
            if not np.isfinite(lw).any():
                continue
            w = np.exp(lw - np.logaddexp.reduce(lw))
            if 1.0 / np.sum(w * w) >= 0.5 * len(w):
                continue
            total = np.logaddexp.reduce(lw)
            idx = np.asarray(_b.resample_indices(w, len(w), "systematic", int(self._rng.integers(2**31))))
            Q = P[idx] + self._rng.normal(0.0, 1.0, P.shape) * std
            Q[:, 2] = wrap(Q[:, 2])
            self.particles[i] = Q
            self.particle_log_weights[i] = np.full(len(w), total - np.log(len(w)))

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


@dataclass
class FusionPlan:
    """A planned top grasp (x, y, yaw, world): Eq. 4.6's value and its two factors."""

    action: np.ndarray
    objective: float
    stability: float
    task: float
    round: int
    evaluations: int = 0
    seeds: int = 0
    part: Optional[float] = None          # part-aware: P(rule, held | G) over the models


class FusionPlanner:
    """Eq. 4.6 over a :class:`ModelMixtureBelief` with the models' top task grasps (planar)."""

    def __init__(self, belief: ModelMixtureBelief, task_grasps: Sequence[np.ndarray], seed: int = 0,
                 part_check: Optional[Callable[[np.ndarray, "ModelMixtureBelief"], object]] = None):
        """``part_check(grasps (K, 3), belief)`` -> a :class:`~.part_check.PartCheck` of the grasps
        (held may be left to compute lazily): needed by task_term part-aware."""
        if belief.settings.task_term == "part-aware" and part_check is None:
            raise ValueError("task_term part-aware: needs a part check (see planners.part_check.check_top_grasps)")
        self.part_check = part_check
        if len(task_grasps) != len(belief.names):
            raise ValueError("task_grasps: need one (K_i, 3) array of planar top task grasps per model")
        self.belief = belief
        self.task_grasps = [np.atleast_2d(np.asarray(t, dtype=float)).reshape(-1, 3) for t in task_grasps]
        if not any(len(t) for t in self.task_grasps):
            raise ValueError("task_grasps: no model has a demonstrated top grasp for the task")
        self._rng = np.random.default_rng(seed)
        self.round = 0
        self.previous: Optional[np.ndarray] = None

    def mapped_task_grasps(self) -> List[np.ndarray]:
        """Every model's top task grasps placed by its current pose: per model a (K_i, 3) array."""
        return [absolute_planar_pose_paired(t, np.repeat(pose[None, :], len(t), axis=0)) if len(t) else t
                for t, pose in zip(self.task_grasps, self.belief.poses)]

    def task(self, grasps) -> np.ndarray:
        """P(T | G, w, p) = sum_i w_i sum_k Laplace(G; p_i o theta_ik) for top grasps (N, 3)."""
        s = self.belief.settings
        G = np.atleast_2d(np.asarray(grasps, dtype=float))
        out = np.zeros(len(G))
        for mapped, w in zip(self.mapped_task_grasps(), self.belief.weights):
            if not len(mapped) or w <= 0:
                continue
            dxy = np.hypot(G[:, None, 0] - mapped[None, :, 0], G[:, None, 1] - mapped[None, :, 1])
            dyaw = np.abs(wrap(G[:, None, 2] - mapped[None, :, 2]))
            out += w * np.exp(-(dxy / s.laplace_translation + dyaw / s.laplace_rotation)).sum(axis=1)
        return out

    def objective(self, grasps, with_stability: bool) -> np.ndarray:
        t = self.task(grasps)
        return t * self.belief.stability(grasps) if with_stability else t

    def plan(self) -> FusionPlan:
        """Round 1: the task term alone; later rounds: stability x task (Fig. 4.4)."""
        s = self.belief.settings
        self.round += 1
        with_s = self.round > 1
        seeds = np.vstack(self.mapped_task_grasps())
        if self.previous is not None:
            seeds = np.vstack([self.previous[None, :], seeds])
        P = self.belief.poses[self.belief.weights > 0]
        low = np.array([P[:, 0].min() - s.search_margin, P[:, 1].min() - s.search_margin, -np.pi])
        high = np.array([P[:, 0].max() + s.search_margin, P[:, 1].max() + s.search_margin, np.pi])
        init = self._rng.uniform(low, high, (s.pso_particles, 3))
        n = min(len(seeds), s.pso_particles)
        init[:n] = np.clip(seeds[:n], low, high)
        r = optim.pso(lambda X: -self.objective(X, with_s), (low, high), n_particles=s.pso_particles,
                      max_iter=s.pso_iter, seed=int(self._rng.integers(2**31)), init=init)
        a = np.asarray(r.x, dtype=float)
        a[2] = wrap(a[2])
        objective, part, nfev = float(-r.fun), None, int(r.nfev)
        if s.task_term == "part-aware":
            C = self._candidates(a, seeds, low, high)
            J = self.objective(C, True)          # the re-ranking weighs stability from round 1 on
            check = self.part_check(C, self.belief)
            k = choose_lazily(check, J, product=True)
            a, objective, part, nfev = C[k], float(J[k]), float(check.p_success[k]), nfev + len(C)
        self.previous = a.copy()
        st, tk = float(self.belief.stability(a[None])[0]), float(self.task(a[None])[0])
        return FusionPlan(action=a, objective=objective, stability=st, task=tk, round=self.round,
                          evaluations=nfev, seeds=n, part=part)

    def _candidates(self, optimum: np.ndarray, seeds: np.ndarray, low, high) -> np.ndarray:
        """Eq. 4.6's optimum, the seeds (the previous grasp, the mapped task grasps) and perturbations
        of the seeds up to part_candidates (x, y clipped to the search box, yaw wrapped)."""
        s = self.belief.settings
        C = np.vstack([optimum[None, :], seeds])[:max(1, s.part_candidates)]
        more = s.part_candidates - len(C)
        if more > 0:
            ref = seeds[np.arange(more) % len(seeds)]
            d = self._rng.uniform(-1, 1, (more, 3)) * [s.part_translation, s.part_translation, s.part_rotation]
            C = np.vstack([C, ref + d])
        C[:, :2] = np.clip(C[:, :2], low[:2], high[:2])
        C[:, 2] = wrap(C[:, 2])
        return C
