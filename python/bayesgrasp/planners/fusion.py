"""Vision, then touch (thesis §4.3, Pub. VI, Eqs. 4.2-4.6): per-model pose and shape-weight
updates from the fingers, and the grasp that is most likely both stable and task-compatible.

The belief is, per training model i of the category, a shape-fit weight w_i and a planar pose
p_i = (x, y, yaw) of that model on the table (:class:`bayesgrasp.belief.model_mixture.ModelMixtureBelief`). Vision gives w_i(0)
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

Round 1 uses the task term alone (Fig. 4.4); once the fingers have been read, the product. The
planner has the package's interface (:mod:`.protocol`): ``plan()`` -> :class:`FusionPlan`,
``observe(grasp, reading)`` -> the belief's
:class:`~bayesgrasp.belief.model_mixture.UpdateResult`, ``belief``. The search is PSO over
(x, y, yaw), its swarm seeded with the previous round's grasp and the mapped task grasps.

Beyond the thesis (``belief="particles"``): a joint particle belief over (model, pose) in place
of the per-model MAP poses - particles per model, weighted by the measurement likelihood, the model
weights being the particle weights' sums - with the same interface.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, List, Optional, Sequence

import numpy as np

from .. import optim
from ..belief import absolute_planar_pose_paired
from ..belief.model_mixture import MixtureSettings, ModelMixtureBelief, wrap
from .part_check import choose_lazily
from .protocol import as_reading

TASK_TERMS = ("laplace", "part-aware", "warped")
PART_TERMS = ("part-aware", "warped")

#: Vision then touch as a method name, with its line of help (the command line reads it).
METHOD = "fusion"
METHOD_HELP = {METHOD: "vision then touch: the weights and poses updated from each reading (Eq. 4.6)"}


@dataclass(frozen=True)
class FusionSettings(MixtureSettings):
    """The belief's settings (:class:`~bayesgrasp.belief.model_mixture.MixtureSettings`: belief,
    recursive, iterations, prior_std, measurement_noise, particles_per_model, threads) and the
    planner's: laplace_translation / laplace_rotation: Eq. 4.6's task-term scales b_t (m), b_yaw
    (rad); search_margin: the grasp search box is the weighted model poses' x, y extent plus this
    (m); PSO size; the task term and its part check."""

    laplace_translation: float = 0.01
    laplace_rotation: float = float(np.radians(10.0))
    search_margin: float = 0.03
    pso_particles: int = 32
    pso_iter: int = 30
    # task_term "part-aware" (beyond the thesis): Eq. 4.6's optimum, the mapped task grasps and
    # perturbations of them (half-widths m, rad) up to part_candidates, closed on every model at its
    # pose; the chosen one maximises P(S | G) P(T | G) x P(rule, held | G) (stability counts from
    # round 1 on) and passes the task's rule on some model whenever one does (planners.part_check.choose)
    # task_term "warped" (issue 53): the same check on the training models warped onto the view
    # (planners.category.warp_models), the shapes placed by the belief's poses
    task_term: str = "laplace"
    part_candidates: int = 48
    part_translation: float = 0.01
    part_rotation: float = float(np.radians(20.0))
    # avoid_failed: a grasp that did not hold lowers Eq. 4.6 near it, x (1 - Laplace(G; failed)) with
    # the scales failed_translation (m) and failed_rotation (rad), until the belief moves: the
    # heaviest model's pose more than failed_translation away from where it was when the grasp was chosen
    avoid_failed: bool = False
    failed_translation: float = 0.01
    failed_rotation: float = float(np.radians(20.0))

    def __post_init__(self):
        super().__post_init__()
        if self.task_term not in TASK_TERMS:
            raise ValueError(f"task_term: one of {', '.join(TASK_TERMS)}; got {self.task_term!r}")
        if self.part_candidates < 1:
            raise ValueError(f"part_candidates: at least 1, got {self.part_candidates}")
        for name in ("part_translation", "part_rotation"):
            if not (np.isfinite(getattr(self, name)) and getattr(self, name) >= 0):
                raise ValueError(f"{name}: must be >= 0, got {getattr(self, name)}")
        for name in ("laplace_translation", "laplace_rotation", "search_margin", "failed_translation",
                     "failed_rotation"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name}: must be positive, got {getattr(self, name)}")


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

    def to_dict(self) -> dict:
        return {"action": np.asarray(self.action).tolist(), "objective": self.objective, "stability": self.stability,
                "task": self.task, "round": self.round, "evaluations": self.evaluations, "seeds": self.seeds,
                **({} if self.part is None else {"part": self.part})}


class FusionPlanner:
    """Eq. 4.6 over a :class:`ModelMixtureBelief` with the models' top task grasps (planar).

    ``reach``: None, or a callable (top grasps (K, 3) x, y, yaw in the world) -> (K,) bool telling
    which grasps an arm reaches; set it after construction. Eq. 4.6 then takes reachability as a
    constraint: an unreachable grasp is worth 0 in the search (the arm is asked only about grasps
    above the best reachable one met so far) and, among the part-aware candidates, is never chosen
    while a reachable one is there.
    """

    reach = None

    def __init__(self, belief: ModelMixtureBelief, task_grasps: Sequence[np.ndarray], seed: int = 0,
                 part_check: Optional[Callable[[np.ndarray, "ModelMixtureBelief"], object]] = None):
        """``part_check(grasps (K, 3), belief)`` -> a :class:`~.part_check.PartCheck` of the grasps
        (held may be left to compute lazily): needed by task_term part-aware. The planner's settings
        are the belief's when it was made with FusionSettings, else the defaults."""
        self.settings = belief.settings if isinstance(belief.settings, FusionSettings) else FusionSettings()
        if self.settings.task_term in PART_TERMS and part_check is None:
            raise ValueError(f"task_term {self.settings.task_term}: needs a part check "
                             "(see planners.part_check.check_top_grasps)")
        self.part_check = part_check
        if len(task_grasps) != len(belief.names):
            raise ValueError("task_grasps: need one (K_i, 3) array of planar top task grasps per model")
        self.belief = belief
        self.task_grasps = [np.atleast_2d(np.asarray(t, dtype=float)).reshape(-1, 3) for t in task_grasps]
        if not any(len(t) for t in self.task_grasps):
            raise ValueError("task_grasps: no model has a demonstrated top grasp for the task")
        self._rng = np.random.default_rng(seed)
        self.round = 0
        self.observations = 0
        self.previous: Optional[np.ndarray] = None
        #: grasps that did not hold (x, y, yaw), each with the heaviest model's pose when it was chosen
        self.failed: List[tuple] = []

    def observe(self, grasp, measurement):
        """Eqs. 4.4-4.5 after executing ``grasp`` (the :class:`FusionPlan` executed or its top grasp
        (x, y, yaw, world)) and reading ``measurement`` (a :class:`~.protocol.Reading` or the joint
        angles the models predict); the next plan weighs stability in. Returns the belief's
        UpdateResult; nothing changes when an argument is rejected."""
        action = grasp.action if isinstance(grasp, FusionPlan) else grasp
        reading = as_reading(measurement)
        anchor = self._anchor()                  # where the belief put the object when the grasp was chosen
        update = self.belief.update(action, reading.joints)
        self.observations += 1
        if reading.held is False:
            self.failed.append((np.asarray(action, float).copy(), anchor))
        return update

    def _anchor(self) -> np.ndarray:
        """The heaviest model's pose: where the belief puts the object."""
        return self.belief.poses[int(np.argmax(self.belief.weights))].copy()

    def failure_factor(self, grasps) -> np.ndarray:
        """prod over the remembered failures of 1 - Laplace(G; failed grasp) (1 without
        ``avoid_failed``); a failure is forgotten once the belief's object has moved by more than
        failed_translation from where it was when the failed grasp was chosen."""
        G = np.atleast_2d(np.asarray(grasps, dtype=float))
        f = np.ones(len(G))
        s = self.settings
        if not s.avoid_failed:
            return f
        here = self._anchor()
        for F, anchor in self.failed:
            if np.hypot(*(here[:2] - anchor[:2])) > s.failed_translation:
                continue
            d = np.hypot(G[:, 0] - F[0], G[:, 1] - F[1]) / s.failed_translation \
                + np.abs(wrap(G[:, 2] - F[2])) / s.failed_rotation
            f *= 1.0 - np.exp(-d)
        return f

    def mapped_task_grasps(self) -> List[np.ndarray]:
        """Every model's top task grasps placed by its current pose: per model a (K_i, 3) array."""
        return [absolute_planar_pose_paired(t, np.repeat(pose[None, :], len(t), axis=0)) if len(t) else t
                for t, pose in zip(self.task_grasps, self.belief.poses)]

    def task(self, grasps) -> np.ndarray:
        """P(T | G, w, p) = sum_i w_i sum_k Laplace(G; p_i o theta_ik) for top grasps (N, 3)."""
        s = self.settings
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
        """Eq. 4.6 (the task term alone in round 1), x :meth:`failure_factor`."""
        t = self.task(grasps) * self.failure_factor(grasps)
        return t * self.belief.stability(grasps) if with_stability else t

    def plan(self) -> FusionPlan:
        """Round 1: the task term alone; once the fingers have been read (a grasp observed before
        the first plan counts as round 1), stability x task (Fig. 4.4)."""
        s = self.settings
        self.round = max(self.round, self.observations) + 1
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
        r = optim.pso(self._searched(with_s), (low, high), n_particles=s.pso_particles,
                      max_iter=s.pso_iter, seed=int(self._rng.integers(2**31)), init=init)
        a = np.asarray(r.x, dtype=float)
        a[2] = wrap(a[2])
        objective, part, nfev = float(-r.fun), None, int(r.nfev)
        if s.task_term in PART_TERMS:
            C = self._candidates(a, seeds, low, high)
            J = self.objective(C, True)          # the re-ranking weighs stability from round 1 on
            if self.reach is not None:           # an unreachable candidate only when none is reachable
                ok = np.asarray(self.reach(C), bool).reshape(len(C))
                if ok.any():
                    C, J = C[ok], J[ok]
            check = self.part_check(C, self.belief)
            k = choose_lazily(check, J, product=True)
            a, objective, part, nfev = C[k], float(J[k]), float(check.p_success[k]), nfev + len(C)
        self.previous = a.copy()
        st, tk = float(self.belief.stability(a[None])[0]), float(self.task(a[None])[0])
        return FusionPlan(action=a, objective=objective, stability=st, task=tk, round=self.round,
                          evaluations=nfev, seeds=n, part=part)

    def _searched(self, with_stability: bool):
        """The PSO's objective: minus Eq. 4.6, an unreachable grasp worth 0 (with a ``reach``)."""
        best = [-np.inf]

        def negative(X):
            v = np.array(self.objective(X, with_stability), dtype=float)
            if self.reach is not None:
                ask = np.flatnonzero(v > max(best[0], 0.0))
                if ask.size:
                    ok = np.asarray(self.reach(X[ask]), bool).reshape(ask.size)
                    best[0] = max(best[0], float(np.max(v[ask][ok], initial=-np.inf)))
                    v[ask[~ok]] = 0.0
            return -v
        return negative

    def _candidates(self, optimum: np.ndarray, seeds: np.ndarray, low, high) -> np.ndarray:
        """Eq. 4.6's optimum, the seeds (the previous grasp, the mapped task grasps) and perturbations
        of the seeds up to part_candidates (x, y clipped to the search box, yaw wrapped)."""
        s = self.settings
        C = np.vstack([optimum[None, :], seeds])[:max(1, s.part_candidates)]
        more = s.part_candidates - len(C)
        if more > 0:
            ref = seeds[np.arange(more) % len(seeds)]
            d = self._rng.uniform(-1, 1, (more, 3)) * [s.part_translation, s.part_translation, s.part_rotation]
            C = np.vstack([C, ref + d])
        C[:, :2] = np.clip(C[:, :2], low[:2], high[:2])
        C[:, 2] = wrap(C[:, 2])
        return C
