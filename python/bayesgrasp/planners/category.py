"""Grasping a new object of a known category for a task (thesis §4.2, Pub. V, Eq. 4.1).

The robot has training models of the category, each with task grasps demonstrated in the model's
frame (:class:`TaskGrasp`), and registrations of the new object's partial cloud against every
model: a transform T_i (model -> scene) and a fitting weight phi(delta_i). It looks for the hand
pose A that maximises

    J(A) = sum_{i,k} P(A | T_ik, O_i; theta_ik) psi(q_ik) phi(delta_i)        (Eq. 4.1)

where T_i theta_ik is grasp k of model i carried into the scene, psi(q) the stability weight of
its quality and P one of three pose densities (:class:`bayesgrasp._core.task.PoseDensity`:
Gaussian, regularised Gaussian, Laplace over the translation distance and rotation angle).

Choices the thesis leaves open (documented here and in the README):

* psi(q) = 1 - exp(-q / q_s) for q > 0 and ``psi_min`` otherwise, q_s the median positive epsilon of
  the task grasps (a grasp twice as good as the typical one counts about as fully stable);
* phi(delta) is the registration's exp(-delta^2 / 2 sigma^2), normalised over the models that
  registered (:func:`bayesgrasp.belief.shape_weights`);
* the search: PSO over 6-D local coordinates (translation, rotation vector) around each model's
  mapped task grasp with the highest psi x phi, as the thesis starts "once per training object from
  that model's grasp"; the best over the starts wins;
* the environment constraint: the open hand at A must be clear of the table and of the observed
  cloud; J is multiplied by exp(-d / d_0) with d the deepest intrusion (``clearance_scale`` d_0),
  so the search is pushed out of collision smoothly.

The baseline ("best single grasp"): the best-fitting model's task grasp of highest psi, mapped by
its registration, no optimisation.

The planner has the package's interface (:mod:`.protocol`). Pub. V plans once; beyond it, a grasp
that did not hold (``observe(plan, Reading(joints, held=False))``) scales every component's weight
by 1 - exp(-(|t - t_f| / b_t + angle(R, R_f) / b_r)), (t_f, R_f) the failed hand pose and b the
density's scales, so the next plan moves away from it; ``belief`` is the models' normalised
weights phi.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import List, Optional, Sequence

import numpy as np

from .. import _core, optim
from ..hand import Hand
from ..models.tasks import TaskGrasp, TaskRule
from ..vision import RegistrationResult
from .category_results import CategoryPlan, CategoryUpdate
from .part_check import check_candidates, choose_by_lift, choose_lazily
from .protocol import as_reading

_task = _core.task

METHODS = ("laplace", "regularised", "gaussian", "baseline", "part-aware", "warped")
#: the methods that close their candidates on the models (part_check): on the models as registered,
#: or on the models warped onto the cloud (vision.deform: Coherent Point Drift)
PART_METHODS = ("part-aware", "warped")
THESIS_METHODS = METHODS[:4]
#: What each method does, in one line (the command line's help reads it). Every method needs the
#: view's registrations and the task grasps; the PART_METHODS also the task's rule.
METHOD_HELP = {"laplace": "Eq. 4.1 with the Laplace density", "regularised": "Eq. 4.1 with the regularised Gaussian",
               "gaussian": "Eq. 4.1 with the basic Gaussian", "baseline": "the best single demonstrated grasp",
               "part-aware": "Eq. 4.1's candidates closed on every registered model and re-ranked by where the "
                             "fingers land (needs the task's rule)",
               "warped": "part-aware on the models warped onto the cloud (Coherent Point Drift)"}


@dataclass(frozen=True)
class CategorySettings:
    """method: laplace, regularised, gaussian or baseline; the density scales (m, rad) and the
    regularised Gaussian's wide component (weight, scale factor); psi_min and psi_scale (None: the
    median positive epsilon of the task grasps); the local search box half-widths (m, rad) and PSO
    size; clearance_margin (m, shapes grown by it) and clearance_scale (m, the penalty's length)."""

    method: str = "laplace"
    translation_scale: float = 0.01
    rotation_scale: float = float(np.radians(10.0))
    wide_weight: float = 0.2
    wide_factor: float = 4.0
    psi_min: float = 0.01
    psi_scale: Optional[float] = None
    search_translation: float = 0.03
    search_rotation: float = float(np.radians(30.0))
    pso_particles: int = 24
    pso_iter: int = 25
    clearance_margin: float = 0.002
    clearance_scale: float = 0.001
    clearance_voxel: float = 0.005  # the cloud is reduced to one point per voxel of this size for the check (m)
    table: bool = True              # the table plane z = 0 is an obstacle (False: the object is held off it)
    min_weight: float = 1e-3        # models whose normalised weight is below this are not search starts
    threads: int = 1
    # part-aware: the search's density, how many candidates are closed on the models (the mapped
    # task grasps, each start's optimum, and perturbations of the best mapped grasps by these
    # half-widths, m and rad) and the weight of the normalised J that breaks ties of P(rule, held | A)
    part_density: str = "laplace"
    part_candidates: int = 64
    part_translation: float = 0.015
    part_rotation: float = float(np.radians(15.0))
    part_tiebreak: float = 0.1
    part_jitter_yaw: Sequence[float] = ()   # rad: the models also closed turned by these (see part_check)
    warp_samples: int = 800                 # warped: surface points of each model warped onto the cloud (CPD)
    # warped: the best candidates (by P(rule, held)) whose choice the lift test on the warped models
    # decides (0: force closure decides), and the residual scale (m) weighing the warps: a model
    # whose warp fits the cloud r m worse than the best one weighs exp(-r / scale) times its phi
    warp_lift_top: int = 4
    warp_residual_scale: float = 0.002

    def __post_init__(self):
        if self.method not in METHODS:
            raise ValueError(f"method: one of {', '.join(METHODS)}; got {self.method!r}")
        for name in ("translation_scale", "rotation_scale", "search_translation", "search_rotation",
                     "clearance_scale"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name}: must be positive, got {v}")
        if not 0 <= self.psi_min <= 1:
            raise ValueError(f"psi_min: must lie in [0, 1], got {self.psi_min}")
        if self.pso_particles < 2 or self.pso_iter < 1:
            raise ValueError("pso_particles: at least 2, pso_iter: at least 1")
        if self.part_density not in THESIS_METHODS[:3]:
            raise ValueError(f"part_density: one of {', '.join(THESIS_METHODS[:3])}; got {self.part_density!r}")
        if self.part_candidates < 1:
            raise ValueError(f"part_candidates: at least 1, got {self.part_candidates}")
        for name in ("part_translation", "part_rotation", "part_tiebreak"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"{name}: must be >= 0, got {v}")
        if self.warp_samples < 10 or self.warp_lift_top < 0:
            raise ValueError(f"warp_samples: at least 10, warp_lift_top: at least 0; got {self.warp_samples}, "
                             f"{self.warp_lift_top}")
        if not (np.isfinite(self.warp_residual_scale) and self.warp_residual_scale > 0):
            raise ValueError(f"warp_residual_scale: must be positive, got {self.warp_residual_scale}")

    def density(self):
        d = _task.PoseDensity()
        kind = self.part_density if self.method in PART_METHODS else self.method
        d.kind = {"laplace": _task.DensityKind.laplace, "regularised": _task.DensityKind.regularised,
                  "gaussian": _task.DensityKind.gaussian, "baseline": _task.DensityKind.laplace}[kind]
        d.translation_scale, d.rotation_scale = self.translation_scale, self.rotation_scale
        d.wide_weight, d.wide_factor = self.wide_weight, self.wide_factor
        d.validate()
        return d


def psi(epsilon, scale: float, floor: float) -> np.ndarray:
    """Stability weight of task grasps from their epsilon: 1 - exp(-q / scale) for q > 0, else floor."""
    q = np.asarray(epsilon, dtype=float)
    return np.where(q > 0, np.maximum(1.0 - np.exp(-np.maximum(q, 0) / scale), floor), floor)


def voxel_points(P: np.ndarray, voxel: float) -> np.ndarray:
    """One point (the first) per occupied voxel: the cloud the clearance check needs."""
    if len(P) == 0:
        return np.zeros((0, 3))
    _, first = np.unique(np.floor(P / voxel).astype(np.int64), axis=0, return_index=True)
    return np.ascontiguousarray(P[np.sort(first)])


def normalised_weights(registrations: Sequence[RegistrationResult]) -> np.ndarray:
    """phi(delta_i) normalised over the models that registered (0 for the others)."""
    phi = np.array([r.phi if r.success else 0.0 for r in registrations], dtype=float)
    s = phi.sum()
    return phi / s if s > 0 else phi


def _warped_pieces(model, warp) -> list:
    """The model's convex pieces (its cached decomposition) moved by the warp: the warped shape's
    pieces for the lift test, made when a lift test first needs them."""
    from ..decomposition import convex_decomposition

    return [warp.warp_points(p) for p in convex_decomposition(model.vertices, model.faces, name=model.name)]


def warp_models(registrations: Sequence[RegistrationResult], weights, cloud, samples: int = 800,
                seed: int = 0) -> list:
    """Per registration: its training model warped onto ``cloud`` (N, 3) by CPD from the
    registration's transform (an ObjectModel in the model's own frame, the same triangles and part
    labels: an estimate of the new object's shape; ``params["warp_residual"]`` the RMS distance (m)
    of the cloud to it; its lift-test pieces the model's own moved by the same warp, made when first
    needed), or None
    (weight 0, not registered, or fewer than 10 points: the model as registered)."""
    from ..objects import ObjectModel, load_object
    from ..vision.deform import warp_mesh

    cloud = np.asarray(cloud, float).reshape(-1, 3)
    out = []
    for r, w in zip(registrations, weights):
        if w <= 0 or not r.success or len(cloud) < 10:
            out.append(None)
            continue
        m = load_object(r.model)
        warp = warp_mesh(m, r.transform, cloud, samples=samples, seed=seed)
        out.append(ObjectModel(f"{m.name}~warped", warp.vertices, m.faces, density=m.density,
                               source=f"{m.source} warped onto the cloud", parts=m.parts, part_names=m.part_names,
                               params={"warp_residual": float(warp.result.residual)},
                               convex_pieces=partial(_warped_pieces, m, warp)))
    return out


class CategoryPlanner:
    """Eq. 4.1 for one scene: the mixture of the mapped task grasps, searched in C++ batches.

    ``reach``: None, or a callable (hand poses (N, 4, 4) in the table frame) -> (N,) bool telling
    which grasps an arm reaches (e.g. ``lambda P: check_reach(arm, P, mesh).reachable``); set it
    after construction. Eq. 4.1 then takes reachability as a constraint, as it takes the table: a
    grasp the arm cannot reach is worth nothing in the search and is never sent.
    """

    reach = None

    def __init__(self, hand: Hand, task_grasps: Sequence[TaskGrasp], registrations: Sequence[RegistrationResult],
                 cloud=None, settings: Optional[CategorySettings] = None, seed: int = 0,
                 rule: Optional[TaskRule] = None, warped: Optional[Sequence] = None):
        """``rule``: the task's rule, needed by the part-aware methods (the part check);
        ``warped``: :meth:`warped_models` computed before for the same registrations, cloud and
        seed (another task on the same view), else they are computed when needed."""
        self.hand = hand if isinstance(hand, Hand) else Hand.load(hand)
        self.settings = settings or CategorySettings()
        if self.settings.method in PART_METHODS and rule is None:
            raise ValueError(f"method {self.settings.method}: needs the task's rule (rule=task_rule(category, task))")
        self.rule = rule
        self.registrations = list(registrations)
        if not self.registrations:
            raise ValueError("registrations: need at least one registered model")
        names = [r.model for r in self.registrations]
        self.grasps = [g for g in task_grasps if g.model in names]
        cloud = np.zeros((0, 3)) if cloud is None else np.asarray(cloud, float)
        if cloud.ndim != 2 or cloud.shape[1] != 3 or not np.isfinite(cloud).all():
            raise ValueError(f"cloud: expected finite (N, 3) points, got shape {cloud.shape}")
        self.cloud = voxel_points(cloud, self.settings.clearance_voxel)
        self.seed = int(seed)
        self.weights = normalised_weights(self.registrations)
        self.failed: List[np.ndarray] = []
        if warped is not None and len(warped) != len(self.registrations):
            raise ValueError(f"warped: one per registration ({len(self.registrations)}), got {len(warped)}")
        self._warped = None if warped is None else list(warped)
        self._build_mixture()

    @property
    def belief(self) -> dict:
        """The models' normalised registration weights phi (the shape belief Eq. 4.1 sums over)."""
        return {r.model: float(w) for r, w in zip(self.registrations, self.weights)}

    def observe(self, grasp, measurement) -> CategoryUpdate:
        """After executing ``grasp`` (the :class:`CategoryPlan` or its 4x4 hand pose): a grasp that
        did not hold (``measurement``: a :class:`~.protocol.Reading`) lowers the weight of the task
        grasps near it (module docstring); one that held, or an unknown outcome, changes nothing."""
        pose = np.asarray(grasp.pose if isinstance(grasp, CategoryPlan) else grasp, dtype=float)
        if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
            raise ValueError(f"grasp: expected the executed CategoryPlan or a finite 4x4 hand pose, got {pose.shape}")
        held = as_reading(measurement).held
        before = float(self.component_weight.sum())
        if held is False:
            self.failed.append(pose.copy())
            self._build_mixture()
        return CategoryUpdate(held, before, float(self.component_weight.sum()))

    def _failure_factor(self) -> np.ndarray:
        """Per task grasp, prod over failed poses of 1 - Laplace(mapped grasp; failed pose)."""
        s = self.settings
        f = np.ones(len(self.mapped))
        for F in self.failed:
            dt = np.linalg.norm(self.mapped[:, :3, 3] - F[:3, 3], axis=1)
            cos = (np.einsum("nij,ij->n", self.mapped[:, :3, :3], F[:3, :3]) - 1.0) / 2.0
            f *= 1.0 - np.exp(-(dt / s.translation_scale + np.arccos(np.clip(cos, -1.0, 1.0)) / s.rotation_scale))
        return f

    # ---- the mixture ----------------------------------------------------------------------------
    def _build_mixture(self) -> None:
        s = self.settings
        index = {r.model: i for i, r in enumerate(self.registrations)}
        eps = np.array([g.epsilon for g in self.grasps], dtype=float)
        pos = eps[eps > 0]
        scale = s.psi_scale if s.psi_scale is not None else (float(np.median(pos)) if len(pos) else 0.1)
        self.psi = psi(eps, scale, s.psi_min)
        self.model_of = np.array([index[g.model] for g in self.grasps], dtype=int)
        self.mapped = np.array([self.registrations[i].transform @ g.pose for i, g in zip(self.model_of, self.grasps)])
        self.component_weight = self.psi * self.weights[self.model_of] if len(self.grasps) else np.zeros(0)
        if self.failed and len(self.grasps):
            self.component_weight = self.component_weight * self._failure_factor()
        self.mixture = None
        if len(self.grasps) and self.component_weight.sum() > 0:
            self.mixture = _task.GraspMixture(self.mapped, self.component_weight, self.model_of.tolist(),
                                              len(self.registrations))

    def _reason(self) -> str:
        if not self.grasps:
            return "no demonstrated grasps for the registered models"
        if not any(r.success for r in self.registrations):
            return "no model registered"
        if self.mixture is None:
            return "every task grasp has zero weight"
        return ""

    # ---- objective --------------------------------------------------------------------------------
    def _penalised(self, reference: np.ndarray, X: np.ndarray, spread: float, density) -> np.ndarray:
        s = self.settings
        J = self.mixture.evaluate_local(reference, X, density, s.threads)
        poses = _task.poses_from_local(reference, X)
        d = self.intrusion(poses, spread)
        return J * np.exp(-d / s.clearance_scale) * ~self.below_table(poses)

    def excluded(self, poses: np.ndarray) -> np.ndarray:
        """(N,) the grasps never sent: a target under the table, or (with a ``reach``) out of the arm's reach."""
        out = self.below_table(poses).copy()
        if self.reach is not None and not out.all():
            idx = np.flatnonzero(~out)
            out[idx] = ~np.asarray(self.reach(np.asarray(poses, float)[idx]), bool).reshape(len(idx))
        return out

    def _searched(self, ref: np.ndarray, spread: float, density):
        """The PSO's objective about the mapped grasp ``ref``: minus the penalised Eq. 4.1, an
        unreachable grasp worth 0 (with a ``reach``). The arm is asked only about the grasps above the
        best reachable one met so far: the others can never be the search's best."""
        best = [-np.inf]

        def negative(X):
            v = np.array(self._penalised(ref, X, spread, density), dtype=float)
            if self.reach is not None:
                ask = np.flatnonzero(v > max(best[0], 0.0))
                if ask.size:
                    ok = np.asarray(self.reach(_task.poses_from_local(ref, X[ask])), bool).reshape(ask.size)
                    best[0] = max(best[0], float(np.max(v[ask][ok], initial=-np.inf)))
                    v[ask[~ok]] = 0.0
            return -v
        return negative

    def below_table(self, poses: np.ndarray) -> np.ndarray:
        """(N,) whether each hand pose's target (its position) lies under the table top, z < 0: such a
        grasp cannot be executed (the simulator refuses it), so it is never chosen. All False without a table."""
        P = np.asarray(poses, float)
        return (P[:, 2, 3] < 0.0) if self.settings.table else np.zeros(len(P), bool)

    def intrusion(self, poses: np.ndarray, spread: float) -> np.ndarray:
        """Deepest intrusion (m) of the table or the cloud into the open hand at each pose (N, 4, 4)."""
        opts = _task.ClearanceOptions()
        opts.margin = self.settings.clearance_margin
        opts.table = self.settings.table
        q = self.hand.open_joints(spread)
        c = _task.hand_clearance(self.hand.core, q, np.asarray(poses, float), self.cloud, opts, self.settings.threads)
        return np.maximum(np.asarray(c.table), np.asarray(c.cloud))

    def evaluate(self, poses) -> _core.task.MixtureValues:
        """J (without the clearance factor) and per-model shares at hand poses (N, 4, 4)."""
        return self.mixture.evaluate(np.asarray(poses, float), self.settings.density(), True, self.settings.threads)

    # ---- planning ---------------------------------------------------------------------------------
    def starts(self) -> List[int]:
        """One start per model with weight above min_weight: its mapped grasp of highest psi x phi."""
        out = []
        for i in range(len(self.registrations)):
            idx = np.flatnonzero((self.model_of == i) & (self.component_weight > 0))
            if len(idx) and self.weights[i] >= self.settings.min_weight:
                out.append(int(idx[np.argmax(self.component_weight[idx])]))
        return out

    def plan(self) -> CategoryPlan:
        reason = self._reason()
        if reason:
            return self._empty(reason)
        if self.settings.method == "baseline":
            return self._baseline()
        s = self.settings
        density = s.density()
        box = np.array([s.search_translation] * 3 + [s.search_rotation] * 3)
        best, best_val, best_start, nfev = None, -np.inf, None, 0
        optima = []
        rng = np.random.default_rng(self.seed)
        for c in self.starts():
            ref, spread = self.mapped[c], self.grasps[c].spread
            init = rng.uniform(-box, box, (s.pso_particles, 6))
            init[0] = 0.0  # the mapped grasp itself
            r = optim.pso(self._searched(ref, spread, density), (-box, box),
                          n_particles=s.pso_particles, max_iter=s.pso_iter, seed=int(rng.integers(2**31)), init=init)
            nfev += r.nfev
            optima.append(_task.poses_from_local(ref, r.x[None, :])[0])
            if -r.fun > best_val and not self.excluded(optima[-1][None])[0]:
                best_val, best_start = -r.fun, c
                best = optima[-1]
        if s.method in PART_METHODS:
            return self._part_aware(optima, rng, nfev)
        if best is None:
            return self._empty("every start's optimum has its target below the table"
                               + (" or out of the arm's reach" if self.reach is not None else ""))
        return self._result(best, best_val, best_start, nfev)

    # ---- part-aware: Eq. 4.1's candidates re-ranked by where the fingers land ------------------------
    def candidates(self, optima: Sequence[np.ndarray], rng: np.random.Generator) -> np.ndarray:
        """(K, 4, 4): each start's optimum, every mapped task grasp, then perturbations of the
        mapped grasps (heaviest first) up to ``part_candidates``."""
        s = self.settings
        fixed = list(optima) + list(self.mapped)
        n_more = max(0, s.part_candidates - len(fixed))
        if n_more == 0:
            return np.asarray(fixed[:max(s.part_candidates, len(optima))])
        order = np.argsort(-self.component_weight, kind="stable")
        refs = order[np.arange(n_more) % len(order)]
        box = np.array([s.part_translation] * 3 + [s.part_rotation] * 3)
        X = rng.uniform(-box, box, (n_more, 6))
        more = np.empty((n_more, 4, 4))
        for c in np.unique(refs):
            more[refs == c] = _task.poses_from_local(self.mapped[c], X[refs == c])
        return np.concatenate([np.asarray(fixed), more])

    def _part_aware(self, optima: Sequence[np.ndarray], rng: np.random.Generator, nfev: int) -> CategoryPlan:
        """Every candidate closed on every registered model (:mod:`.part_check`); the chosen one
        maximises P(rule, held | A) + part_tiebreak * J(A) / max J among the candidates that pass
        on some model (P > 0), and J alone if none passes."""
        s = self.settings
        A = self.candidates(optima, rng)
        A = A[~self.excluded(A)]            # a target under the table (or out of the arm's reach) is never sent
        if not len(A):
            return self._empty("every candidate's target lies below the table"
                               + (" or out of the arm's reach" if self.reach is not None else ""))
        v = self.evaluate(A)
        comp = np.asarray(v.dominant, int)
        spreads = np.array([self.grasps[c].spread if c >= 0 else self.grasps[0].spread for c in comp], float)
        J = np.asarray(v.value, float) * np.exp(-self._intrusions(A, spreads) / s.clearance_scale)
        warped = s.method == "warped"
        shapes = self.warped_models() if warped else None
        weights = self.warp_weights() if warped else self.weights
        check = check_candidates(self.hand, self.rule, A, spreads, self.registrations, weights, s.threads,
                                 resolve=False, jitter_yaw=tuple(s.part_jitter_yaw), shapes=shapes)
        k = choose_lazily(check, J, s.part_tiebreak)
        extra = {}
        if warped:
            extra["warps"] = {r.model: {"weight": float(w), "residual": m.params["warp_residual"]}
                              for r, w, m in zip(self.registrations, weights, shapes) if m is not None}
            if s.warp_lift_top > 0:
                k, decided = self._decide_by_lift(check, J, k)
                extra.update(decided)
        plan = self._result(A[k], float(J[k]), None, nfev + len(A) * int(np.count_nonzero(weights > 0)))
        plan.extra.update({"p_rule": float(check.p_rule[k]), "p_success": float(check.p_success[k]),
                           "candidates": int(len(A)), "passing_rule": int(np.count_nonzero(check.p_rule > 0)),
                           "held_checked": int(np.count_nonzero(check.known)), **extra,
                           "contact_parts_on_models": {r.model: check.parts[k][i]
                                                       for i, r in enumerate(self.registrations) if weights[i] > 0}})
        return plan

    def _decide_by_lift(self, check, J: np.ndarray, k: int) -> tuple:
        """:func:`~.part_check.choose_by_lift` over the ``warp_lift_top`` best candidates; ``k``
        (force closure's choice) when none of them lifts on any warped model."""
        chosen, tested, p = choose_by_lift(check, J, self.settings.warp_lift_top, self.settings.part_tiebreak)
        return (k if chosen is None else chosen), {"lift_checked": tested, "p_lifted": p}

    def warp_weights(self) -> np.ndarray:
        """The models' weights for the warped check: phi times exp(-(r_i - min r) / scale), r_i
        the RMS distance of the observed points to model i's warp (the better a warp fits the view,
        the more its shape counts), normalised; models without a warp keep phi."""
        r = np.array([np.nan if m is None else m.params.get("warp_residual", np.nan) for m in self.warped_models()])
        w = self.weights.copy()
        have = np.isfinite(r) & (w > 0)
        if have.any():
            w[have] *= np.exp(-(r[have] - r[have].min()) / self.settings.warp_residual_scale)
        total = w.sum()
        return w / total if total > 0 else w

    def warped_models(self) -> list:
        """Per registration: its training model warped onto the observed cloud (:func:`warp_models`),
        computed once."""
        if self._warped is None:
            self._warped = warp_models(self.registrations, self.weights, self.cloud, self.settings.warp_samples,
                                       self.seed)
        return self._warped

    def _intrusions(self, poses: np.ndarray, spreads: np.ndarray) -> np.ndarray:
        d = np.zeros(len(poses))
        for sp in np.unique(spreads):
            idx = np.flatnonzero(spreads == sp)
            d[idx] = self.intrusion(poses[idx], float(sp))
        return d

    def _baseline(self) -> CategoryPlan:
        i = int(np.argmax(self.weights))
        idx = np.flatnonzero(self.model_of == i)
        if not len(idx):
            return self._empty(f"the best-fitting model {self.registrations[i].model} has no task grasp")
        idx = idx[~self.excluded(self.mapped[idx])]
        if not len(idx):
            return self._empty(f"every task grasp of {self.registrations[i].model} maps below the table"
                               + (" or out of the arm's reach" if self.reach is not None else ""))
        c = int(idx[np.argmax(self.psi[idx])])
        return self._result(self.mapped[c], None, c, 0)

    def _result(self, pose: np.ndarray, objective: Optional[float], start: Optional[int], nfev: int) -> CategoryPlan:
        v = self.evaluate(pose[None])
        dom = int(v.dominant[0])
        comp = dom if dom >= 0 else (0 if start is None else start)
        spread = float(self.grasps[comp].spread)
        d = float(self.intrusion(pose[None], spread)[0])
        mix = float(v.value[0])
        names = [r.model for r in self.registrations]
        return CategoryPlan(
            pose=pose, spread=spread, method=self.settings.method,
            objective=mix * float(np.exp(-d / self.settings.clearance_scale)) if objective is None else float(objective),
            mixture=mix, weights=dict(zip(names, self.weights.tolist())),
            contributions=dict(zip(names, np.asarray(v.per_model)[0].tolist())),
            dominant_model=names[self.model_of[comp]], dominant_grasp=comp,
            start_model=None if start is None else names[self.model_of[start]], evaluations=nfev, intrusion=d)

    def _empty(self, reason: str) -> CategoryPlan:
        names = [r.model for r in self.registrations]
        return CategoryPlan(pose=np.full((4, 4), np.nan), spread=float("nan"), method=self.settings.method,
                            objective=0.0, mixture=0.0, weights=dict(zip(names, self.weights.tolist())),
                            contributions={n: 0.0 for n in names}, dominant_model=None, dominant_grasp=-1,
                            start_model=None, reason=reason)
