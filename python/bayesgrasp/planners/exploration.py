"""Informative exploration (thesis §3.3, Pub. III-IV, Eq. 3.2).

Plan the maximally stable grasp first; if its expected stability is below
``settings.explore_threshold``, execute instead the grasp that minimises the expected entropy of
the posterior, E_M[H(P(O | a, M))], estimated by drawing measurements from the GP measurement
model at particles drawn by weight (Monte Carlo, common random numbers across candidates).
By default the search minimises E[H] - 2 P(S) (``settings.explore_stability_weight``): among
about equally informative grasps it takes one that may also hold; a weight of 0 is the thesis's
pure entropy minimisation.

Entropy estimates: "weight" - the thesis's weight-based estimate, -sum w log w of the posterior
weights (fast, comparable only for the same particle positions, which is what planning needs);
"kernel" - a Gaussian kernel estimate over the particle positions, -sum_i w_i log sum_j w_j K_ij,
with the kernel's bandwidth from the current belief by Scott's rule (slower, comparable over time).
"""
from __future__ import annotations

from typing import Optional, Tuple

import numpy as np

from .. import optim
from .base import Planner, wrap_angle
from .pose_results import Plan

#: nats added to an unreachable action's objective in the exploration search: more than the
#: objective (an entropy of a planar-pose belief minus a weighted P(S)) can span, so that a
#: reachable action always wins over an unreachable one.
UNREACHABLE_ENTROPY = 1.0e6


def kernel_matrix(particles: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Gaussian kernel K_ij (N, N) between planar poses, covariance f^2 C with C the weighted
    covariance (yaw differences wrapped) and Scott's factor f = n_eff^(-1/7)."""
    P = np.asarray(particles, dtype=float)
    w = np.asarray(weights, dtype=float)
    w = w / w.sum()
    mu = w @ P
    mu[2] = np.arctan2(w @ np.sin(P[:, 2]), w @ np.cos(P[:, 2]))
    d = P - mu
    d[:, 2] = wrap_angle(d[:, 2])
    C = (d * w[:, None]).T @ d / max(1.0 - np.sum(w * w), 1e-12)
    f = (1.0 / np.sum(w * w)) ** (-1.0 / 7.0)
    C = f * f * C + 1e-12 * np.eye(3)
    L = np.linalg.cholesky(np.linalg.inv(C))
    D = P[:, None, :] - P[None, :, :]
    D[..., 2] = wrap_angle(D[..., 2])
    q = np.einsum("ijk,kl->ijl", D, L)
    return np.exp(-0.5 * np.sum(q * q, axis=-1))


def expected_kernel_entropy(mean: np.ndarray, var: np.ndarray, log_weights: np.ndarray, K: np.ndarray,
                            n_samples: int, seed: int) -> Tuple[np.ndarray, np.ndarray]:
    """Expected posterior kernel entropy of A actions: mean, var (A, N, J) measurement predictions
    at every particle; K (N, N) the kernel matrix. Same draws for every action (common random
    numbers). Returns (entropy (A,), standard error (A,)); entropies up to the kernel's constant."""
    A, N, J = mean.shape
    rng = np.random.default_rng(seed)
    lw = np.asarray(log_weights, dtype=float)
    w = np.exp(lw - lw.max())
    w /= w.sum()
    # Stratified particle draws and standard normal noise, shared by all actions.
    u = (np.arange(n_samples) + rng.uniform(size=n_samples)) / n_samples
    idx = np.minimum(np.searchsorted(np.cumsum(w), u), N - 1)
    z = rng.standard_normal((n_samples, J))
    h = np.empty(A)
    se = np.empty(A)
    for a in range(A):
        m = mean[a, idx] + np.sqrt(var[a, idx]) * z                          # (S, J) sampled measurements
        r = (m[:, None, :] - mean[a][None, :, :]) ** 2 / var[a][None, :, :]   # (S, N, J)
        ll = -0.5 * (r.sum(-1) + np.log(var[a]).sum(-1)[None, :]) + lw[None, :]
        ll -= ll.max(axis=1, keepdims=True)
        W = np.exp(ll)
        W /= W.sum(axis=1, keepdims=True)                                     # (S, N) posterior weights
        p = W @ K                                                              # density at each particle
        hs = -np.sum(W * np.log(np.maximum(p, 1e-300)), axis=1)
        h[a] = hs.mean()
        se[a] = hs.std(ddof=1) / np.sqrt(n_samples) if n_samples > 1 else 0.0
    return h, se


class ExplorationPlanner(Planner):
    """The maximally stable grasp when its expected stability reaches the threshold; otherwise
    the most informative grasp (minimum expected posterior entropy)."""

    method = "explore"

    def _plan(self) -> Plan:
        b = self.belief
        f, a, v, n = self.most_stable(b.particles, b.weights)
        if v >= self.settings.explore_threshold:
            return Plan(action=a, kind="stability", predicted_stability=v, objective=v, evaluations=n, family=f)
        best = None
        for g in self.families:   # the most informative grasp of each family; the lowest objective wins
            e, obj, n2 = self.minimise_entropy(init_best=a if g == f else None, family=g)
            n += n2
            if best is None or obj < best[2]:
                best = (g, e, obj)
        g, e, _ = best
        h = float(self.expected_entropy(e[None, :], seed=self.seed + 7919 * self._plans, family=g)[0][0])
        return Plan(action=e, kind="explore", predicted_stability=self.expected_stability(e, g), objective=-h,
                    expected_entropy=h, evaluations=n, family=g)

    def expected_entropy(self, actions, n_samples: Optional[int] = None, seed: Optional[int] = None,
                         method: Optional[str] = None, family: Optional[str] = None):
        """Expected posterior entropy (Eq. 3.2) of actions (A, 3) of ``family`` (None: the
        first) under the current belief: (entropy (A,), standard error (A,))."""
        s = self.settings
        table = self.tables[self._family(family)]
        A = np.atleast_2d(np.asarray(actions, dtype=float))
        n_samples = s.entropy_samples if n_samples is None else int(n_samples)
        seed = self.seed + 7919 * self._plans if seed is None else int(seed)
        method = s.entropy if method is None else method
        b = self.belief
        if method == "weight":
            return table.expected_posterior_entropy(A, b.particles, b.log_weights, n_samples, seed, s.threads)
        if method != "kernel":
            raise ValueError(f"method: 'weight' or 'kernel', got {method!r}")
        K = kernel_matrix(b.particles, b.weights)
        hs, ses = [], []
        for start in range(0, len(A), 64):
            mean, var = table.measurement_pairs(A[start:start + 64], b.particles, s.threads)
            h, se = expected_kernel_entropy(mean, var, b.log_weights, K, n_samples, seed)
            hs.append(h)
            ses.append(se)
        return np.concatenate(hs), np.concatenate(ses)

    def minimise_entropy(self, init_best=None, family: Optional[str] = None):
        """PSO over (x, y, yaw) of ``family``'s grasps (None: the first) of the expected posterior
        entropy minus explore_stability_weight x P(S); with a ``reach``, an unreachable action's
        objective is raised by UNREACHABLE_ENTROPY. Returns (action, objective, nfev)."""
        s = self.settings
        family = self._family(family)
        table = self.tables[family]
        low, high = self.action_bounds()
        seed = self.seed + 7919 * self._plans   # one common-random-number seed for the whole search
        k = s.explore_pso_particles
        init = self._rng.uniform(low, high, size=(k, 3))
        if init_best is not None:
            init[0] = np.clip(init_best, low, high)

        lam = s.explore_stability_weight
        b = self.belief
        reachable = self._reachable(family)
        best = [np.inf]   # the lowest objective of a reachable action met so far

        def objective(X):
            h = self.expected_entropy(X, seed=seed, family=family)[0]
            if lam != 0.0:
                h = h - lam * table.expected_stability(X, b.particles, b.weights, s.threads)
            if reachable is not None:   # Eq. 3.2 over the reachable actions; the arm asked only
                h = np.array(h, dtype=float)
                ask = np.flatnonzero(h < best[0])   # about those that beat the best reachable one
                if ask.size:
                    ok = reachable(X[ask])
                    best[0] = min(best[0], float(np.min(h[ask][ok], initial=np.inf)))
                    h[ask[~ok]] += UNREACHABLE_ENTROPY
            return h

        r = optim.pso(objective, (low, high), n_particles=k, max_iter=s.explore_pso_iter,
                      seed=int(self._rng.integers(2**31)), init=init)
        return r.x, r.fun, r.nfev
