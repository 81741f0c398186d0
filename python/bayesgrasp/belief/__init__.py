"""Particle beliefs over object poses, their entropy, and the expected entropy after an action.

:class:`ParticleBelief` is a weighted particle set over a box-bounded state (the planar pose
x, y, yaw is the main case; ``wraps`` flags angle dimensions, kept in [low, high)), with its own
seeded generator. Updates run in C++: reweighting by log-likelihoods, resampling (systematic,
stratified, multinomial), Metropolis random-walk moves and roughening. Likelihoods are either a
vectorised Python callable ``(N, D) -> (N,)`` (called once per batch, never per particle) or a GP
measurement model (:meth:`ParticleBelief.update_gp`, one C++ call).

Entropy: :func:`weight_entropy` (the thesis's weight-based estimate), :func:`kde_entropy`
(positions and weights), and :func:`expected_posterior_entropy` / :func:`expected_posterior_entropy_gp`
(Eq. 3.2, by sampling measurements from the predictive distribution).

If every likelihood is zero the weights are reset to uniform and a :class:`UserWarning` is
emitted (never NaN weights). Bad input raises ``ValueError``.
"""
from __future__ import annotations

import warnings
from typing import Callable, Optional, Sequence, Tuple

from bayesgrasp._args import c_int, c_seed
import numpy as np

from bayesgrasp import _core

_c = _core.belief

__all__ = ["ParticleBelief", "planar_pose_bounds", "weight_entropy", "kde_entropy", "expected_posterior_entropy",
           "expected_posterior_entropy_gp", "relative_planar_pose", "absolute_planar_pose",
           "absolute_planar_pose_paired", "resample_indices", "gp_log_likelihood", "shape_weights",
           "AllZeroLikelihoodWarning"]


class AllZeroLikelihoodWarning(UserWarning):
    """Every particle had zero likelihood; the weights were reset to uniform."""


def _warn_recovered(flag: bool) -> bool:
    if flag:
        warnings.warn("all particle likelihoods are zero: weights reset to uniform", AllZeroLikelihoodWarning,
                      stacklevel=3)
    return bool(flag)


def planar_pose_bounds(x_range: Tuple[float, float], y_range: Tuple[float, float]):
    """(low, high, wraps) for a planar pose (x, y, yaw), yaw wrapping in [-pi, pi)."""
    return (np.array([x_range[0], y_range[0], -np.pi]), np.array([x_range[1], y_range[1], np.pi]),
            [False, False, True])


def _flags(wraps):
    """The wrapping flags as a list (None: no dimension wraps)."""
    return None if wraps is None else list(wraps)


def _core_property(name: str, doc: str) -> property:
    """A read-only property forwarding to the C++ belief's attribute ``name``."""
    return property(lambda self: getattr(self._b, name), doc=doc)


class ParticleBelief:
    """Weighted particles over [low, high] (wrapping dims for angles), with a seeded generator.

    Construct from explicit particles, or with :meth:`uniform` / :meth:`gaussian`.
    """

    def __init__(self, particles, low, high, wraps: Optional[Sequence[bool]] = None, log_weights=None, seed: int = 0):
        self._b = _c.ParticleBelief(np.asarray(particles, dtype=float), np.asarray(low, dtype=float),
                                    np.asarray(high, dtype=float), _flags(wraps),
                                    None if log_weights is None else np.asarray(log_weights, dtype=float),
                                    c_seed(seed, "seed"))

    @classmethod
    def _wrap(cls, core):
        self = cls.__new__(cls)
        self._b = core
        return self

    @classmethod
    def uniform(cls, low, high, n: int, wraps=None, seed: int = 0) -> "ParticleBelief":
        """n particles uniform in the box."""
        return cls._wrap(_c.ParticleBelief.uniform(np.asarray(low, float), np.asarray(high, float), c_int(n, "n"),
                                                   _flags(wraps), c_seed(seed, "seed")))

    @classmethod
    def gaussian(cls, low, high, mean, std, n: int, wraps=None, seed: int = 0) -> "ParticleBelief":
        """n particles from N(mean, diag(std^2)) truncated to the box (wrapping dims wrapped)."""
        return cls._wrap(_c.ParticleBelief.gaussian(np.asarray(low, float), np.asarray(high, float),
                                                    np.asarray(mean, float), np.asarray(std, float), c_int(n, "n"),
                                                    _flags(wraps), c_seed(seed, "seed")))

    # ---- state (read from the C++ belief) ---------------------------------------------------------
    particles = _core_property("particles", "(N, D) particle states (a copy).")
    log_weights = _core_property("log_weights", "(N,) normalised log-weights.")
    weights = _core_property("weights", "(N,) weights summing to 1.")
    low = _core_property("low", "(D,) lower bounds.")
    high = _core_property("high", "(D,) upper bounds.")
    wraps = _core_property("wraps", "Per dimension: whether it wraps (an angle in [low, high)).")
    dim = _core_property("dim", "State dimension D.")

    def __len__(self) -> int:
        return self._b.size

    def ess(self) -> float:
        """Effective sample size 1 / sum w^2."""
        return self._b.ess()

    def mean(self) -> np.ndarray:
        """Weighted mean (circular mean for wrapping dims)."""
        return self._b.mean()

    # ---- updates ---------------------------------------------------------------------------------
    def reweight(self, log_likelihood) -> bool:
        """Multiplies the weights by exp(log_likelihood) (N,) and normalises. Returns True (and warns)
        if all likelihoods were zero and the weights were reset to uniform."""
        return _warn_recovered(self._b.reweight(np.asarray(log_likelihood, dtype=float)))

    def update(self, log_likelihood: Callable[[np.ndarray], np.ndarray]) -> bool:
        """Bayes update with a vectorised log-likelihood (N, D) -> (N,), called once."""
        return _warn_recovered(self._b.update(log_likelihood))

    def update_gp(self, gp, action, measurement) -> bool:
        """Bayes update with a GP measurement model P(M | A, O): the log predictive density of
        ``measurement`` at the grasp pose ``action`` relative to every particle's pose.

        ``gp`` is a fitted :class:`bayesgrasp.gp.ExactGP` / ``SparseGP`` (or a core model) over inputs
        ``relative_planar_pose(action, pose)``. With one core model this is one C++ call; with
        independent per-output models it is one vectorised call per model.
        """
        action = np.asarray(action, dtype=float).ravel()
        measurement = np.atleast_1d(np.asarray(measurement, dtype=float)).ravel()
        core = _single_core_model(gp)
        if core is not None:
            return _warn_recovered(self._b.update_gp(core, action, measurement))
        return self.update(gp_log_likelihood(gp, action, measurement))

    def resample(self, scheme: str = "systematic", n: int = 0) -> None:
        """Resamples N (or n > 0) particles; weights become uniform."""
        self._b.resample(scheme, c_int(n, "n"))

    def resample_if_needed(self, threshold: float = 0.5, scheme: str = "systematic") -> bool:
        """Resamples when ess < threshold * N; returns whether it did."""
        return self._b.resample_if_needed(float(threshold), scheme)

    def metropolis(self, log_target: Callable[[np.ndarray], np.ndarray], step, n_steps: int = 1):
        """n_steps Metropolis random-walk sweeps under log_target (vectorised, called once per sweep
        plus once at the start); proposal std ``step`` per dimension. Returns a
        :class:`bayesgrasp._core.belief.MetropolisStats` (``acceptance_rate``, ``evaluations``)."""
        return self._b.metropolis(log_target, np.broadcast_to(np.asarray(step, float), (self.dim,)).copy(),
                                  c_int(n_steps, "n_steps"))

    def roughen(self, k: float = 0.2) -> None:
        """Gordon et al. roughening: jitter std k * spread * N^(-1/D) per dimension."""
        self._b.roughen(float(k))

    # ---- entropy ---------------------------------------------------------------------------------
    def weight_entropy(self) -> float:
        """-sum w log w (weights as probability masses; log N for uniform weights)."""
        return self._b.weight_entropy()

    def kde_entropy(self, bandwidth: str = "scott") -> float:
        """Weighted Gaussian-KDE entropy by resubstitution ('scott' or 'silverman' bandwidth)."""
        return self._b.kde_entropy(bandwidth)

    def __repr__(self):
        return f"ParticleBelief(n={len(self)}, dim={self.dim}, ess={self.ess():.1f})"


def weight_entropy(log_weights) -> float:
    """-sum w log w of the normalised weights exp(log_weights)."""
    return _c.weight_entropy(np.asarray(log_weights, dtype=float))


def kde_entropy(particles, log_weights, low, high, wraps=None, bandwidth: str = "scott") -> float:
    """Weighted Gaussian-KDE entropy -sum_i w_i log p(x_i): kernel covariance f^2 C with C the weighted
    covariance and f by Scott's or Silverman's rule (n_eff = 1/sum w^2) — scipy.stats.gaussian_kde's
    conventions. Differences in wrapping dims are wrapped."""
    return _c.kde_entropy(np.asarray(particles, float), np.asarray(log_weights, float), np.asarray(low, float),
                          np.asarray(high, float), _flags(wraps), bandwidth)


def expected_posterior_entropy(log_weights, mean, var, n_samples: int = 100, seed: int = 0, n_threads: int = 1):
    """Expected posterior weight entropy of one or many actions (Eq. 3.2).

    mean, var: predictive mean and variance (including the measurement noise) of the K measurement
    outputs at every particle: (N, K) for one action, or (A, N, K) for A actions. For each of
    n_samples draws: a particle j with probability w_j, a measurement m ~ N(mean_j, var_j), the
    posterior w_i ∝ w_i N(m; mean_i, var_i) and its weight entropy; the average is returned with its
    standard error. The same seed gives the same draws for every action.

    Returns (entropy, std_error): floats for (N, K) input, arrays (A,) for (A, N, K).
    """
    mean = np.asarray(mean, dtype=float)
    var = np.asarray(var, dtype=float)
    if mean.ndim == 1:
        mean, var = mean[:, None], var.reshape(-1, 1)
    h, se = _c.expected_posterior_entropy(np.asarray(log_weights, float), mean, var, c_int(n_samples, "n_samples"), c_seed(seed, "seed"),
                                          c_int(n_threads, "n_threads"))
    if mean.ndim == 2:
        return float(h[0]), float(se[0])
    return h, se


def expected_posterior_entropy_gp(gp, belief: ParticleBelief, actions, n_samples: int = 100, seed: int = 0,
                                  n_threads: int = 1):
    """Expected posterior entropy (Eq. 3.2) of A actions (rows of ``actions``) under a GP measurement
    model over relative poses: the GP is evaluated once for all (action, particle) pairs.
    Returns (entropy (A,), std_error (A,))."""
    actions = np.atleast_2d(np.asarray(actions, dtype=float))
    core = _single_core_model(gp)
    if core is not None:
        return _c.expected_posterior_entropy_gp(core, belief.particles, belief.log_weights, actions,
                                                c_int(n_samples, "n_samples"), c_seed(seed, "seed"), c_int(n_threads, "n_threads"))
    X = relative_planar_pose(actions, belief.particles)
    mv = [m.predict(X, True) for m in gp.models_]
    mean = np.concatenate([a for a, _ in mv], axis=1).reshape(len(actions), len(belief), -1)
    var = np.concatenate([b for _, b in mv], axis=1).reshape(len(actions), len(belief), -1)
    return expected_posterior_entropy(belief.log_weights, mean, var, n_samples, seed, n_threads)


def relative_planar_pose(actions, poses) -> np.ndarray:
    """Grasp poses relative to object poses for all pairs: actions (A, 3 + extra) rows
    (x, y, yaw, ...), poses (N, 3) -> (A*N, 3 + extra); row a*N + j is
    (R(-yaw_j)(a_xy - o_xy), wrap(a_yaw - yaw_j) in [-pi, pi), extra_a)."""
    return _c.relative_planar_pose(np.atleast_2d(np.asarray(actions, float)), np.atleast_2d(np.asarray(poses, float)))


def absolute_planar_pose(relative, poses) -> np.ndarray:
    """The inverse of :func:`relative_planar_pose`: grasps given in object frames placed in the
    world, for all pairs: relative (R, 3 + extra) rows (x, y, yaw, ...), poses (N, 3) ->
    (R*N, 3 + extra); row r*N + j is (o_xy_j + R(yaw_j) r_xy, wrap(r_yaw + yaw_j) in [-pi, pi),
    extra_r). With one pose, row r is relative grasp r in the world."""
    return _c.compose_planar_pose(np.atleast_2d(np.asarray(relative, float)), np.atleast_2d(np.asarray(poses, float)))


def absolute_planar_pose_paired(relative, poses) -> np.ndarray:
    """:func:`absolute_planar_pose` one to one: relative (N, 3 + extra) and poses (N, 3) ->
    (N, 3 + extra); row i is (o_xy_i + R(yaw_i) r_xy_i, wrap(r_yaw_i + yaw_i) in [-pi, pi), extra_i)."""
    return _c.compose_planar_pose_paired(np.atleast_2d(np.asarray(relative, float)),
                                         np.atleast_2d(np.asarray(poses, float)))


def resample_indices(weights, n: int, scheme: str = "systematic", seed: int = 0) -> np.ndarray:
    """Indices of n draws with probabilities proportional to weights (>= 0)."""
    return np.asarray(_c.resample_indices(np.asarray(weights, float), c_int(n, "n"), scheme, c_seed(seed, "seed")), dtype=np.int64)


def gp_log_likelihood(gp, action, measurement) -> Callable[[np.ndarray], np.ndarray]:
    """A vectorised log-likelihood (N, 3) -> (N,) of ``measurement`` after ``action`` under a GP over
    relative poses (for :meth:`ParticleBelief.update` / :meth:`ParticleBelief.metropolis`)."""
    action = np.asarray(action, dtype=float).ravel()
    measurement = np.atleast_1d(np.asarray(measurement, dtype=float)).ravel()

    def log_likelihood(poses: np.ndarray) -> np.ndarray:
        X = relative_planar_pose(action[None, :], poses)
        return gp.log_predictive_density(X, np.broadcast_to(measurement, (len(poses), len(measurement))).copy())

    return log_likelihood


def _single_core_model(gp):
    """The C++ GP behind gp if there is exactly one (else None)."""
    if isinstance(gp, _core.gp.GaussianProcess):
        return gp
    models = getattr(gp, "models_", None)
    if models is not None and len(models) == 1 and isinstance(models[0], _core.gp.GaussianProcess):
        return models[0]
    return None


def shape_weights(phi, success) -> np.ndarray:
    """Weights of the models of one registration call (Eq. 4.1's phi(delta_i), normalised).

    ``phi``: (M,) phi(delta_i) of each model; ``success``: (M,) whether model i registered.
    Returns (M,) float64: ``phi_i / sum_j phi_j`` over the models that registered (summed in model
    order), 0 for the others. If no model registered, or every registered phi is 0, every weight
    is 0 (never NaN): there is then no shape evidence to weight by. ValueError for mismatched
    lengths or a registered phi that is negative or not finite."""
    p = np.asarray(phi, dtype=np.float64).ravel()
    ok = np.asarray(success, dtype=bool).ravel()
    if p.shape != ok.shape:
        raise ValueError(f"phi, success: lengths differ ({p.size} vs {ok.size})")
    if not np.all(np.isfinite(p[ok])) or np.any(p[ok] < 0):
        raise ValueError("phi: must be finite and >= 0 for the models that registered")
    w = np.where(ok, p, 0.0)
    total = float(np.cumsum(w)[-1]) if w.size else 0.0
    return w / total if total > 0 else np.zeros_like(w)
