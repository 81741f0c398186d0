"""Training data for the grasp models, from the simulator: random relative top grasps, their
outcomes (joint angles, epsilon, and the lift test), the finger-spread pilot and the logistic
calibration of P(S)."""
from __future__ import annotations

from typing import Optional

import numpy as np
from scipy.optimize import minimize
from scipy.special import expit

from ..world import World
from .settings import AUTO_SPREADS, ModelSettings


def random_relative_grasps(rng: np.random.Generator, n: int, box) -> np.ndarray:
    """n relative top grasps (x, y, yaw): x, y uniform in the box ((2, 2): lows, highs), yaw uniform
    in [-pi, pi)."""
    box = np.asarray(box, dtype=float)
    return np.column_stack([rng.uniform(box[0, 0], box[1, 0], n), rng.uniform(box[0, 1], box[1, 1], n),
                            rng.uniform(-np.pi, np.pi, n)])


def simulate_training_data(world: World, settings: ModelSettings, seed_offset: int = 0, n: Optional[int] = None,
                           spread: Optional[float] = None):
    """Relative grasps (n, 3), joint angles (n, J) and epsilon (n,) from the simulator, in the
    settings' grasp box for the object (n scaled with the box, see ModelSettings.scaled); grasps
    whose open hand started in collision are dropped."""
    rng = np.random.default_rng([settings.seed, seed_offset])
    box = settings.grasp_box(world.object)
    n = settings.scaled(settings.n_samples if n is None else int(n), box)
    rel = random_relative_grasps(rng, n, box)
    spread = settings.spread if spread is None else spread
    b = world.grasp_batch(rel, spread=spread, threads=0)
    ok = ~np.asarray(b.collision_at_start, dtype=bool)
    return rel[ok], np.asarray(b.joint_angles)[ok], np.asarray(b.epsilon)[ok]


def lift_outcomes(world: World, rel: np.ndarray, spread: float) -> np.ndarray:
    """(n,) bool: each relative grasp held in the lift test. A grasp whose hand touches nothing of
    the object cannot hold it and is not simulated."""
    rel = np.atleast_2d(np.asarray(rel, dtype=float))
    b = world.grasp_batch(rel, spread=spread, threads=0)
    touches = np.asarray(b.link_contact, dtype=bool).any(axis=1) & ~np.asarray(b.collision_at_start, bool)
    lifted = np.zeros(len(rel), dtype=bool)
    idx = np.flatnonzero(touches)
    if len(idx):
        lifted[idx] = np.asarray(world.grasp_batch(rel[idx], spread=spread, lift=True, threads=0).lifted, bool)
    return lifted


def success_labels(world: World, settings: ModelSettings, rel: np.ndarray, eps: np.ndarray, spread: float) -> np.ndarray:
    """S for each grasp under the settings' success criterion (lift test or epsilon)."""
    if settings.success == "lift":
        return lift_outcomes(world, rel, spread)
    return np.asarray(eps) > settings.eps_stable


def choose_spread(world: World, settings: ModelSettings, say=lambda m: None) -> tuple:
    """The pilot behind ModelSettings.spread = None: for each spread in AUTO_SPREADS, simulate
    n_pilot random relative top grasps and score how often a random grasp succeeds.

    With success "lift": the first n_pilot_lifts collision-free grasps that touch the object are
    lift-tested; score = touching fraction x lifted fraction. With "epsilon": up to n_pilot_lifts
    of the stable grasps are lift-tested; score = stable fraction x lifted fraction. Returns
    (best spread, {degrees: (fraction, lifted, tested)}); with no grasp lifted at any spread, the
    spread with the largest fraction."""
    rng = np.random.default_rng([settings.seed, 7])
    rel = random_relative_grasps(rng, settings.n_pilot, settings.grasp_box(world.object))
    table, scores = {}, []
    for sp in AUTO_SPREADS:
        b = world.grasp_batch(rel, spread=sp, threads=0)
        free = ~np.asarray(b.collision_at_start, dtype=bool)
        if settings.success == "lift":
            ok = free & np.asarray(b.link_contact, dtype=bool).any(axis=1)
            what = "touch the object"
        else:
            ok = free & (np.asarray(b.epsilon) > settings.eps_stable)
            what = "stable"
        idx = np.flatnonzero(ok)[:settings.n_pilot_lifts]
        lifted = int(np.sum(world.grasp_batch(rel[idx], spread=sp, lift=True, threads=0).lifted)) if len(idx) else 0
        frac = float(np.mean(ok))
        table[round(float(np.degrees(sp)))] = (frac, lifted, int(len(idx)))
        scores.append((frac * (lifted / len(idx) if len(idx) else 0.0), frac))
        say(f"  spread {np.degrees(sp):3.0f} deg: {100 * frac:.0f}% {what}, {lifted}/{len(idx)} of those tested lifted")
    best = max(range(len(scores)), key=lambda i: scores[i])
    return AUTO_SPREADS[best], table


def fit_calibration(z, stable) -> tuple:
    """Logistic regression P = 1 / (1 + exp(-(a z + b))) of outcomes on scores (maximum likelihood,
    a tiny ridge keeps it finite when the classes separate)."""
    z = np.asarray(z, dtype=float)
    y = np.asarray(stable, dtype=float)

    def nll(p):
        t = p[0] * z + p[1]
        return np.sum(np.logaddexp(0.0, t) - y * t) + 1e-3 * (p[0] ** 2 + p[1] ** 2)

    def grad(p):
        t = p[0] * z + p[1]
        r = expit(t) - y
        return np.array([r @ z, r.sum()]) + 2e-3 * p

    res = minimize(nll, np.array([1.0, 0.0]), jac=grad, method="BFGS")
    return float(res.x[0]), float(res.x[1])
