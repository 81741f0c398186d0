"""What every planner for known objects under pose uncertainty shares (thesis §3.2-3.3).

The unknown is the object's planar pose O = (x, y, yaw) on the table; the belief is a
:class:`~bayesgrasp.belief.ParticleBelief` over it; an action is a grasp family (top, as in the
thesis, or side; :mod:`bayesgrasp.models.families`) and its A = (x, y, yaw) in the world frame;
the measurement M is the hand's phalanx joint angles after closing; S is whether the grasp is
stable. Every planner has the same interface::

    planner = StabilityPlanner(models, estimate=(0.01, -0.02, 0.3), seed=0)
    plan = planner.plan()                      # Plan: family, action, kind, predicted stability, ...
    update = planner.observe(plan, Reading(joint_angles, held=False))
    planner.belief, planner.history            # history: every PoseUpdate

``models`` is one family's :class:`~bayesgrasp.models.GraspModels`, or a mapping from family
name to models: the planners then search every family and keep the best, and the belief update
takes the executed family's models.

(:mod:`.protocol`: every planner of the package has this interface.) ``observe`` is the Bayes
update of the thesis: reweight the particles by the GP measurement
likelihood P(M | A, O) (and, as an option, by P(S = observed | A, O)), resample, then move every
particle with Metropolis steps whose target is the posterior of all observations so far, so
that resampled copies spread out again.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, replace
from typing import List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from .. import optim
from ..belief import ParticleBelief, absolute_planar_pose_paired, relative_planar_pose, resample_indices
from ..models import FAMILIES, GraspModels
from .pose_results import Observation, Plan, PoseUpdate
from .protocol import as_reading


@dataclass(frozen=True)
class PlannerSettings:
    """Settings shared by the planners (defaults reproduce the thesis's set-up)."""

    n_particles: int = 500
    # The searches run on a compressed belief of at most plan_particles distinct particles when
    # the belief holds more: drawn by systematic resampling, duplicates merged (weight = count),
    # so a concentrated belief compresses to a few; 0 = search the whole belief.
    plan_particles: int = 500
    # Initial belief: uniform over estimate +- half_width (x, y in m, yaw in rad).
    half_width: Sequence[float] = (0.04, 0.04, np.radians(45.0))
    # Stability search (Eq. 3.1): PSO over (x, y, yaw).
    pso_particles: int = 32
    pso_iter: int = 30
    # Exploration (Eq. 3.2): used when the best expected stability is below explore_threshold.
    explore_threshold: float = 0.5
    entropy: str = "weight"            # "weight" (the thesis's default) or "kernel"
    entropy_samples: int = 50          # measurement samples per candidate action
    explore_pso_particles: int = 16
    explore_pso_iter: int = 12
    # The exploration search minimises E[H] - explore_stability_weight * P(S) (nats per unit of
    # belief-weighted stability): 0 is the thesis's pure entropy minimisation; a positive weight
    # prefers, among about equally informative grasps, the ones that may also hold (the two are
    # compared in BENCHMARKS.md, "Exploration's stability weight").
    explore_stability_weight: float = 2.0
    # Belief update.
    metropolis_steps: int = 10
    metropolis_step: Sequence[float] = (0.003, 0.003, np.radians(3.0))
    use_outcome: bool = True           # also weigh particles by P(S = observed | A, O)
    outcome_floor: float = 0.05        # P(S) is clipped to [floor, 1 - floor] in that factor
    # Grasp search box: the belief's x, y extent plus this margin (m).
    action_margin: float = 0.03
    threads: int = 1

    def __post_init__(self):
        if self.n_particles < 2:
            raise ValueError(f"n_particles: need at least 2, got {self.n_particles}")
        if self.plan_particles != 0 and self.plan_particles < 2:
            raise ValueError(f"plan_particles: 0 (the whole belief) or at least 2, got {self.plan_particles}")
        hw = np.asarray(self.half_width, dtype=float)
        if hw.shape != (3,) or not np.all(np.isfinite(hw)) or np.any(hw <= 0):
            raise ValueError(f"half_width: expected three positive numbers (m, m, rad), got {self.half_width}")
        if self.entropy not in ("weight", "kernel"):
            raise ValueError(f"entropy: 'weight' or 'kernel', got {self.entropy!r}")
        if not 0.0 <= self.explore_threshold <= 1.0:
            raise ValueError(f"explore_threshold: must be in [0, 1], got {self.explore_threshold}")
        for name in ("pso_particles", "pso_iter", "entropy_samples", "explore_pso_particles", "explore_pso_iter"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name}: must be at least 1, got {getattr(self, name)}")
        if not (np.isfinite(self.explore_stability_weight) and self.explore_stability_weight >= 0):
            raise ValueError(f"explore_stability_weight: must be >= 0, got {self.explore_stability_weight}")
        if self.metropolis_steps < 0:
            raise ValueError(f"metropolis_steps: must be >= 0, got {self.metropolis_steps}")
        ms = np.asarray(self.metropolis_step, dtype=float)
        if ms.shape != (3,) or not np.all(np.isfinite(ms)) or np.any(ms <= 0):
            raise ValueError(f"metropolis_step: expected three positive numbers (m, m, rad), got {self.metropolis_step}")
        if not 0.0 <= self.outcome_floor < 0.5:
            raise ValueError(f"outcome_floor: must be in [0, 0.5), got {self.outcome_floor}")
        if not (np.isfinite(self.action_margin) and self.action_margin >= 0):
            raise ValueError(f"action_margin: must be >= 0 (m), got {self.action_margin}")
        if not isinstance(self.threads, (int, np.integer)) or isinstance(self.threads, bool) or self.threads < 0:
            raise ValueError(f"threads: must be an int >= 0 (0 = all cores), got {self.threads!r}")

    def with_(self, **kw) -> "PlannerSettings":
        return replace(self, **kw)


def family_models(models: Union[GraspModels, Mapping[str, GraspModels]]) -> dict:
    """One family's models or a mapping family -> models, as a dict in FAMILIES order; the
    families must measure the same joints."""
    if isinstance(models, GraspModels):
        return {models.family: models}
    out = {f: models[f] for f in FAMILIES if f in models}
    if not out or len(out) != len(models):
        raise ValueError(f"models: a GraspModels or a mapping from families ({', '.join(FAMILIES)}) to GraspModels; "
                         f"got keys {list(models)}")
    for f, m in out.items():
        if not isinstance(m, GraspModels) or m.family != f:
            raise ValueError(f"models[{f!r}]: expected the {f} family's GraspModels")
    joints = {tuple(m.joint_index) for m in out.values()}
    if len(joints) > 1:
        raise ValueError("models: the families measure different joints")
    return out


class MeasurementWarning(UserWarning):
    """A measurement outside what the hand can read (it is still used)."""


# No revolute joint of a hand file turns more than half a turn from zero.
MAX_JOINT_ANGLE = np.pi


def wrap_angle(a):
    return np.mod(np.asarray(a, dtype=float) + np.pi, 2 * np.pi) - np.pi


#: What an unreachable action's objective loses in the stability search: more than any expected
#: stability (in [0, 1]) can gain, so that a reachable action always wins over an unreachable one.
UNREACHABLE_PENALTY = 2.0


def _unpenalised(v: float) -> float:
    """The expected stability behind a search's value (reachable: in [0, 1]; unreachable: minus the penalty)."""
    return v + UNREACHABLE_PENALTY if v < -0.5 * UNREACHABLE_PENALTY else v


class Planner:
    """Base class: belief, Bayes update and the stability search; subclasses choose the action.

    ``reach``: None (the hand is free-floating), or a callable (models, actions (K, 3) in the world,
    object pose (3,)) -> (K,) bool telling which actions an arm can reach (e.g.
    :class:`bayesgrasp.planners.reach.ActionReach`); set it after construction. Eq. 3.1 is then
    maximised over the reachable actions: an unreachable action is never chosen while the search
    has met a reachable one (if it met none, the most stable action is returned as without an arm).
    The arm is asked only about the actions that beat the best reachable one met so far.
    """

    method = "base"
    reach = None

    def __init__(self, models: Union[GraspModels, Mapping[str, GraspModels]], estimate: Sequence[float],
                 settings: Optional[PlannerSettings] = None, seed: int = 0,
                 table_bounds: Optional[Sequence[float]] = None):
        self.family_models = family_models(models)
        self.families = tuple(self.family_models)
        self.models = self.family_models[self.families[0]]   # the first family's (every family: family_models)
        self.settings = settings or PlannerSettings()
        est = np.asarray(estimate, dtype=float).ravel()
        if est.shape != (3,) or not np.all(np.isfinite(est)):
            raise ValueError(f"estimate: expected a finite pose (x, y, yaw), got {estimate}")
        self.estimate = est.copy()
        self.estimate[2] = wrap_angle(est[2])
        hw = np.asarray(self.settings.half_width, dtype=float)
        low = np.array([est[0] - hw[0], est[1] - hw[1], -np.pi])
        high = np.array([est[0] + hw[0], est[1] + hw[1], np.pi])
        self.seed = int(seed)
        self._rng = np.random.default_rng(self.seed)
        # Uniform over the box around the estimate; yaw within +-hw[2] of the estimate (wrapped).
        n = self.settings.n_particles
        parts = np.column_stack([self._rng.uniform(low[0], high[0], n), self._rng.uniform(low[1], high[1], n),
                                 wrap_angle(est[2] + self._rng.uniform(-hw[2], hw[2], n))])
        self._yaw_lo, self._yaw_hw = est[2], hw[2]
        self.belief = ParticleBelief(parts, low, high, wraps=[False, False, True], seed=self.seed)
        self.tables = {f: m.table() for f, m in self.family_models.items()}
        self.table = self.tables[self.families[0]]
        self.observations: List[Observation] = []
        self.history: List[PoseUpdate] = []
        self._plans = 0
        self._entropy_memo: Optional[Tuple[bytes, float]] = None   # (belief state, its KDE entropy)

    # ---- the prior box --------------------------------------------------------------------------
    def _log_prior(self, poses: np.ndarray) -> np.ndarray:
        """0 inside the initial box (uniform prior), -inf outside."""
        d = np.abs(wrap_angle(poses[:, 2] - self._yaw_lo))
        return np.where(d <= self._yaw_hw, 0.0, -np.inf)

    def _family(self, family: Optional[str]) -> str:
        """A family this planner has models for (None: the first)."""
        if family is None:
            return self.families[0]
        if family not in self.family_models:
            raise ValueError(f"family: this planner has models for {', '.join(self.families)}; got {family!r}")
        return family

    def log_likelihood(self, poses: np.ndarray, obs: Observation) -> np.ndarray:
        """log P(M = m, S = s | A = a, O = pose) for every pose (N, 3), with the models of the
        observation's family."""
        rel = relative_planar_pose(obs.action[None, :], poses)
        ll = self.family_models[obs.family].log_likelihood(rel, obs.measurement)
        if self.settings.use_outcome and obs.stable is not None:
            f = self.settings.outcome_floor
            ps = np.clip(self.tables[obs.family].stability(rel), f, 1.0 - f)
            ll = ll + np.log(ps if obs.stable else 1.0 - ps)   # no factor when not known
        return ll

    def log_posterior(self, poses: np.ndarray) -> np.ndarray:
        """Unnormalised log posterior of poses (N, 3) under every observation so far."""
        lp = self._log_prior(poses)
        for obs in self.observations:
            ok = np.isfinite(lp)
            if ok.any():
                lp[ok] += self.log_likelihood(poses[ok], obs)
        return lp

    # ---- interface ------------------------------------------------------------------------------
    def plan(self) -> Plan:
        t0 = time.perf_counter()
        full = self.belief
        self.belief = self.planning_belief()   # the searches read self.belief
        try:
            p = self._plan()
        finally:
            self.belief = full
        p.seconds = time.perf_counter() - t0
        self._plans += 1
        return p

    def planning_belief(self) -> ParticleBelief:
        """The belief the next plan searches: the belief itself, or with more than
        ``settings.plan_particles`` particles, that many systematic draws from it with duplicates
        merged (weight = number of draws), seeded by the planner's seed and plan count."""
        b, k = self.belief, self.settings.plan_particles
        if k == 0 or len(b) <= k:
            return b
        idx = resample_indices(b.weights, k, "systematic", seed=self.seed + 104729 * (self._plans + 1))
        keep, count = np.unique(idx, return_counts=True)
        return ParticleBelief(b.particles[keep], b.low, b.high, wraps=b.wraps, log_weights=np.log(count),
                              seed=self.seed)

    def _plan(self) -> Plan:
        raise NotImplementedError

    def observe(self, grasp, measurement) -> PoseUpdate:
        """Bayes update after executing ``grasp`` (the :class:`Plan` executed, or its world grasp
        (x, y, yaw) when the planner has one family) and reading ``measurement`` (a
        :class:`~.protocol.Reading`: the phalanx joint angles the models predict and whether the
        grasp held; or the joint angles alone). Nothing changes when an argument is rejected."""
        obs = self._observation(grasp, as_reading(measurement))
        self.observations.append(obs)
        self._update(obs)
        update = PoseUpdate(obs, self.belief.mean(), float(self.belief.ess()))
        self.history.append(update)
        return update

    def _observation(self, grasp, reading) -> Observation:
        """The executed grasp and the reading checked against the planner's families and joints."""
        if isinstance(grasp, Plan):
            family, action = self._family(grasp.family), grasp.action
        elif len(self.families) > 1:
            raise ValueError(f"grasp: pass the executed Plan (which family was executed: {', '.join(self.families)}?)")
        else:
            family, action = self.families[0], grasp
        a = np.asarray(action, dtype=float).ravel()
        m = reading.joints
        if a.shape != (3,) or not np.all(np.isfinite(a)):
            raise ValueError(f"grasp: expected a world top grasp (x, y, yaw), got {action}")
        if m.shape != (self.models.n_joints,):
            raise ValueError(f"measurement: expected {self.models.n_joints} finite joint angles, got {m.shape}")
        if np.any(np.abs(m) > MAX_JOINT_ANGLE):
            warnings.warn(f"measurement: joint angles {m.tolist()} lie beyond +-{MAX_JOINT_ANGLE:.2f} rad, outside "
                          "any joint's range (degrees instead of radians?); the belief will collapse onto the "
                          "few poses least unlikely under it", MeasurementWarning, stacklevel=3)
        return Observation(a.copy(), np.array(m), reading.held, family)

    def _update(self, obs: Observation) -> None:
        s = self.settings
        b = self.belief
        b.reweight(self.log_likelihood(b.particles, obs))
        b.resample("systematic")
        if s.metropolis_steps > 0:
            b.metropolis(self.log_posterior, np.asarray(s.metropolis_step, dtype=float), s.metropolis_steps)

    # ---- the searches ---------------------------------------------------------------------------
    def action_bounds(self, poses: Optional[np.ndarray] = None):
        P = self.belief.particles if poses is None else poses
        m = self.settings.action_margin
        low = np.array([P[:, 0].min() - m, P[:, 1].min() - m, -np.pi])
        high = np.array([P[:, 0].max() + m, P[:, 1].max() + m, np.pi])
        return low, high

    def _seed_actions(self, poses: np.ndarray, weights: np.ndarray, k: int, family: Optional[str] = None) -> np.ndarray:
        """k starting grasps: the model's best relative grasps placed at weighted-random particles."""
        best = self.tables[self._family(family)].best_relative_grasps(64)
        j = self._rng.choice(len(poses), size=k, p=weights / weights.sum())
        rel = best[self._rng.integers(0, len(best), k)]
        return absolute_planar_pose_paired(rel, poses[j])

    def maximise_stability(self, poses: np.ndarray, weights: np.ndarray, family: Optional[str] = None):
        """PSO over (x, y, yaw) of sum_j w_j P(S | A, O_j) (Eq. 3.1) for one family (None: the
        first), over the reachable actions when the planner has a ``reach``. Returns (action,
        value, nfev), the value the action's expected stability."""
        a, v, n = self._maximise(poses, weights, self._family(family))
        return a, _unpenalised(v), n

    def _maximise(self, poses: np.ndarray, weights: np.ndarray, family: str):
        """maximise_stability's search; its value is lowered by UNREACHABLE_PENALTY when the action
        is unreachable."""
        s = self.settings
        table = self.tables[family]
        low, high = self.action_bounds(poses)
        w = np.asarray(weights, dtype=float)
        init = np.clip(self._seed_actions(poses, w, s.pso_particles, family), low, high)
        reachable = self._reachable(family)
        best = [-np.inf]   # the highest value of a reachable action met so far

        def negative(X):
            v = np.array(table.expected_stability(X, poses, w, s.threads), dtype=float)
            if reachable is not None:
                # only an action above the best reachable one could become the search's best: the
                # others keep their value without asking the arm (they can never be returned)
                ask = np.flatnonzero(v > best[0])
                if ask.size:
                    ok = reachable(X[ask])
                    best[0] = max(best[0], float(np.max(v[ask][ok], initial=-np.inf)))
                    v[ask[~ok]] -= UNREACHABLE_PENALTY
            return -v

        r = optim.pso(negative, (low, high), n_particles=s.pso_particles, max_iter=s.pso_iter,
                      seed=int(self._rng.integers(2**31)), init=init)
        return r.x, -r.fun, r.nfev

    def _reachable(self, family: str):
        """actions (K, 3) -> (K,) bool for ``family`` at the belief's mean pose, or None without a reach."""
        if self.reach is None:
            return None
        models, pose = self.family_models[family], self.belief.mean()
        return lambda X: np.asarray(self.reach(models, X, pose), dtype=bool).reshape(len(X))

    def most_stable(self, poses: np.ndarray, weights: np.ndarray):
        """Eq. 3.1 over every family: (family, action, value, total nfev) of the best; ties go
        to the earlier family (top first); a reachable action beats an unreachable one of any
        family (with a ``reach``)."""
        best, total = None, 0
        for f in self.families:
            a, v, n = self._maximise(poses, weights, f)
            total += n
            if best is None or v > best[2]:
                best = (f, a, v)
        return best[0], best[1], _unpenalised(best[2]), total

    def expected_stability(self, action, family: Optional[str] = None) -> float:
        """The belief-weighted P(S) of one action of ``family`` (None: the first)."""
        table = self.tables[self._family(family)]
        return float(table.expected_stability(np.asarray(action, float)[None, :], self.belief.particles,
                                              self.belief.weights, self.settings.threads)[0])

    # ---- summaries ------------------------------------------------------------------------------
    def mode(self) -> np.ndarray:
        """The particle with the highest posterior density (ties: closest to the weighted mean)."""
        P = self.belief.particles
        lp = self.log_posterior(P) + self.belief.log_weights
        best = np.flatnonzero(lp >= lp.max() - 1e-9)
        if len(best) > 1:
            mu = self.belief.mean()
            d = np.hypot(P[best, 0] - mu[0], P[best, 1] - mu[1]) + 0.05 * np.abs(wrap_angle(P[best, 2] - mu[2]))
            best = best[np.argsort(d)]
        return P[best[0]].copy()

    def _kde_entropy(self, b: ParticleBelief, P: np.ndarray) -> float:
        """The belief's KDE entropy, computed once per belief state: an episode step summarises the
        same belief after its update and beside its next plan (the entropy is O(N^2), the rest O(N));
        the state is the particles, weights, box and wrapping flags, compared byte for byte."""
        state = b"".join(np.ascontiguousarray(a, dtype=float).tobytes()
                         for a in (P, b.log_weights, b.low, b.high, np.asarray(b.wraps, dtype=float)))
        if self._entropy_memo is None or self._entropy_memo[0] != state:
            self._entropy_memo = (state, float(b.kde_entropy()))
        return self._entropy_memo[1]

    def summary(self, true_pose: Optional[Sequence[float]] = None) -> dict:
        """The belief in numbers: mean, std per dim, ESS, KDE entropy, and errors to ``true_pose``."""
        b = self.belief
        P, w = b.particles, b.weights
        mu = b.mean()
        d = P - mu
        d[:, 2] = wrap_angle(d[:, 2])
        out = {"mean": mu.tolist(), "std": np.sqrt(np.maximum(w @ (d * d), 0.0)).tolist(), "ess": float(b.ess()),
               "kde_entropy": self._kde_entropy(b, P)}
        if true_pose is not None:
            t = np.asarray(true_pose, dtype=float)
            out["position_error"] = float(np.hypot(mu[0] - t[0], mu[1] - t[1]))
            out["yaw_error"] = float(abs(wrap_angle(mu[2] - t[2])))
        return out
