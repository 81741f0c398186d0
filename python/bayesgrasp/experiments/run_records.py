"""What one run of each experiment returns, typed, and its stored JSON (``to_dict``): the runner
(:func:`.runner._run`) calls ``to_dict()`` in the worker and stores the dict in the results
database; the reports read the stored dicts. The loop's own results inside (a
:class:`~bayesgrasp.loop.category_result.TaskGraspResult`, a
:class:`~bayesgrasp.loop.fusion_result.FusionResult`, a
:class:`~bayesgrasp.loop.touch_trial.PoseErrors`) serialise through :mod:`bayesgrasp.io.results`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Dict, Optional, Sequence, Tuple

import numpy as np
from scipy import stats

from ..io.results import fusion_dict, fusion_round_dict, pose_errors_dict, tasks_dict

if TYPE_CHECKING:
    from ..loop.category_result import TaskGraspResult
    from ..loop.fusion_result import FusionResult, FusionRound
    from ..loop.touch_trial import PoseErrors, TouchTrial
    from ..vision import RegistrationResult


# ---- pub5, pub5_complete, pub5_scales (category_grasping, category_scales) -----------------------------
@dataclass(frozen=True)
class CategoryRun:
    """One pub5 run: a held-out object seen once, every method planned for every task on that view.

    object, category : str
    pose : tuple — the table pose (x, y, yaw); eye_offset : tuple — the camera from the object's centre
    complete : bool — the whole surface as the cloud (pub5_complete)
    cloud_points : int
    registrations : sequence of RegistrationResult — each training model's (model, phi, success)
    tasks : {task: {method: TaskGraspResult}}
    """

    object: str
    category: str
    pose: tuple
    eye_offset: tuple
    complete: bool
    cloud_points: int
    registrations: Sequence["RegistrationResult"]
    tasks: Dict[str, Dict[str, "TaskGraspResult"]]

    def to_dict(self) -> dict:
        return {"object": self.object, "category": self.category, "pose": list(self.pose),
                "eye_offset": list(self.eye_offset), "complete": self.complete, "cloud_points": self.cloud_points,
                "registrations": [{"model": r.model, "phi": r.phi, "success": r.success} for r in self.registrations],
                "tasks": tasks_dict(self.tasks)}


@dataclass(frozen=True)
class ScalesRun:
    """One pub5_scales run: a view of a mug and the four densities at one grid point's ``scales``
    (s_t in m, s_R in rad; Eq. 4.1); ``tasks`` as in :class:`CategoryRun`."""

    object: str
    category: str
    pose: tuple
    scales: Tuple[float, float]
    tasks: Dict[str, Dict[str, "TaskGraspResult"]]

    def to_dict(self) -> dict:
        return {"object": self.object, "category": self.category, "pose": list(self.pose),
                "scales": list(self.scales), "tasks": tasks_dict(self.tasks)}


# ---- entropy_order, landscapes, the entropy gain (pose_uncertainty) ------------------------------------
#: entropy_order's three grasps: lowest, median and highest predicted expected entropy.
PICKS = ("best", "good", "worst")


@dataclass(frozen=True)
class EntropyPick:
    """One of entropy_order's three grasps: its action (x, y, yaw), the expected entropy predicted
    from the belief (Eq. 3.2) and the weight entropy realised after executing it."""

    name: str
    action: np.ndarray
    predicted: float
    realised: float


@dataclass(frozen=True)
class EntropyOrderRun:
    """One entropy_order run (Fig. 3.6): the grid's predicted landscape from the initial belief and
    the three grasps executed from it, in :data:`PICKS` order."""

    true_pose: np.ndarray
    grid: int
    candidates: np.ndarray   # (grid^2, 3) actions
    landscape: np.ndarray    # their predicted expected entropies
    particles: np.ndarray    # the initial belief
    picks: Tuple[EntropyPick, ...]

    @property
    def order_kept(self) -> bool:
        """The realised entropies are in the predicted order."""
        pr, re = [p.predicted for p in self.picks], [p.realised for p in self.picks]
        return bool(np.all(np.argsort(re) == np.argsort(pr)))

    @property
    def best_below_worst(self) -> bool:
        return bool(self.picks[0].realised < self.picks[-1].realised)

    @property
    def kendall_tau(self) -> float:
        """Rank agreement of the predicted and realised entropies of the three."""
        return float(stats.kendalltau([p.predicted for p in self.picks], [p.realised for p in self.picks]).statistic)

    def to_dict(self) -> dict:
        return {"true_pose": self.true_pose.tolist(), "predicted": {p.name: float(p.predicted) for p in self.picks},
                "realised": {p.name: p.realised for p in self.picks},
                "actions": {p.name: np.asarray(p.action).tolist() for p in self.picks}, "grid": self.grid,
                "landscape": self.landscape.tolist(), "candidates": self.candidates.tolist(),
                "particles": self.particles.tolist(), "order_kept": self.order_kept,
                "best_below_worst": self.best_below_worst, "kendall_tau": self.kendall_tau}


@dataclass(frozen=True)
class EntropyGain:
    """From one initial belief, the most informative grasp (Eq. 3.2) and a random one, each executed:
    posterior-mean position errors (m) and weight entropies (nats) before and after."""

    true_pose: np.ndarray
    error_before: float
    entropy_before: float
    informative: np.ndarray
    entropy_informative: float
    error_after_informative: float
    random: np.ndarray
    entropy_random: float
    error_after_random: float

    def to_dict(self) -> dict:
        return {"true_pose": self.true_pose.tolist(), "error_before": self.error_before,
                "entropy_before": self.entropy_before, "entropy_informative": self.entropy_informative,
                "error_after_informative": self.error_after_informative, "entropy_random": self.entropy_random,
                "error_after_random": self.error_after_random, "informative": self.informative.tolist(),
                "random": self.random.tolist()}


@dataclass(frozen=True)
class OneDof:
    """The cube with uncertainty in x only: the expected entropy along x with 1,000 and 10,000
    measurement samples."""

    x: np.ndarray
    h1000: np.ndarray
    h10000: np.ndarray

    @staticmethod
    def _roughness(h) -> float:
        """Mean |second difference|."""
        return float(np.mean(np.abs(np.diff(h, 2))))

    def to_dict(self) -> dict:
        xs = self.x
        return {"x": xs.tolist(), "h1000": self.h1000.tolist(), "h10000": self.h10000.tolist(),
                "roughness_1000": self._roughness(self.h1000), "roughness_10000": self._roughness(self.h10000),
                "argmin_gap": float(abs(xs[np.argmin(self.h1000)] - xs[np.argmin(self.h10000)])),
                "correlation": float(stats.pearsonr(self.h1000, self.h10000).statistic)}


@dataclass(frozen=True)
class LandscapesRun:
    """One landscapes run: the weight- and kernel-based expected entropies over a grid of actions
    and their correlations; ``one_dof`` for the cube only."""

    true_pose: np.ndarray
    grid: int
    actions: np.ndarray
    weight: np.ndarray
    kernel: np.ndarray
    one_dof: Optional[OneDof] = None

    def to_dict(self) -> dict:
        out = {"true_pose": self.true_pose.tolist(), "grid": self.grid, "actions": self.actions.tolist(),
               "weight": self.weight.tolist(), "kernel": self.kernel.tolist(),
               "pearson": float(stats.pearsonr(self.weight, self.kernel).statistic),
               "spearman": float(stats.spearmanr(self.weight, self.kernel).statistic)}
        if self.one_dof is not None:
            out["one_dof"] = self.one_dof.to_dict()
        return out


# ---- pub1, pub1_variants (single_touch) ----------------------------------------------------------------
@dataclass(frozen=True)
class TouchCase:
    """One of pub1's cases: the problem, the fit (a TouchTrial's) and the pose errors before and
    after it. ``trace``: every tenth (evaluations, best fitness) of the search."""

    truth: np.ndarray
    initial: np.ndarray
    trial: "TouchTrial"
    before: "PoseErrors"     # of the guess
    after: "PoseErrors"      # of the estimate

    def to_dict(self) -> dict:
        t, r = self.trial, self.trial.fit
        return {"truth": self.truth.tolist(), "initial": self.initial.tolist(), "estimate": t.estimate.tolist(),
                "status": r.status.name, "contacts": int(t.readings.contact_count), "fitness": r.fitness,
                "initial_fitness": r.initial_fitness, "evaluations": int(r.evaluations), "seconds": r.seconds,
                "cpu_seconds": r.cpu_seconds,
                "trace": [list(map(int, r.trace_evaluations[::10])), list(r.trace_fitness[::10])],
                "before": pose_errors_dict(self.before), "after": pose_errors_dict(self.after)}


@dataclass(frozen=True)
class PlannedGrasp:
    """A planned top grasp (x, y, yaw) executed on the true object."""

    action: np.ndarray
    success: bool
    epsilon: float
    lifted: Optional[bool]

    def to_dict(self) -> dict:
        return {"action": self.action.tolist(), "success": self.success, "epsilon": self.epsilon,
                "lifted": self.lifted}


@dataclass(frozen=True)
class SecondGrasp:
    """Fig. 2.1: the most stable grasp planned on the initial guess and on the updated estimate."""

    initial: PlannedGrasp
    updated: PlannedGrasp

    def to_dict(self) -> dict:
        return {"initial": self.initial.to_dict(), "updated": self.updated.to_dict()}


@dataclass(frozen=True)
class TouchRun:
    """One pub1 run (``label`` "optimizer": the optimiser's name) or pub1_variants run (``label``
    "method": optimiser/contact term or hand): its cases by name, and Fig. 2.1's second grasp
    (pub1 only)."""

    object: str
    label: str
    name: str
    cases: Dict[str, TouchCase]
    second_grasp: Optional[SecondGrasp] = None

    def to_dict(self) -> dict:
        out = {"object": self.object, self.label: self.name,
               "cases": {c: rec.to_dict() for c, rec in self.cases.items()}}
        if self.second_grasp is not None:
            out["second_grasp"] = self.second_grasp.to_dict()
        return out


# ---- pub6 and its variants (tactile_fusion) -------------------------------------------------------------
@dataclass(frozen=True)
class FusionRun:
    """One pub6 trial: the FusionResult, the held-out object and its table pose, and the
    vision-only baseline's grasp (a FusionRound: G(0) planned from vision)."""

    result: "FusionResult"
    object: str
    pose: tuple
    vision_only: "FusionRound"

    def to_dict(self) -> dict:
        return {**fusion_dict(self.result), "object": self.object, "pose": list(self.pose),
                "vision_only": fusion_round_dict(self.vision_only)}
