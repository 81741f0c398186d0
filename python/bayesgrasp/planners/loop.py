"""The closed loop of thesis Figs. 3.1 and 3.4: plan, execute at the hidden true pose in the
simulator, read the joint angles, update the belief, re-plan, until the grasp is stable or the
attempts run out.

:func:`run_episode` is a pure function of its arguments (object, true pose, method, seed,
settings): the experiments call it run by run, in any process.
"""
from __future__ import annotations

from pathlib import Path
from typing import Optional, Sequence, Union

import numpy as np

from ..cache import cache_root
from ..models import GraspModels, ModelSettings, build_models, relative_top_grasps
from ..objects import ObjectModel, load_object
from ..world import World
from .base import Planner, PlannerSettings
from .baselines import MLPosePlanner, OpenLoopPlanner
from .exploration import ExplorationPlanner
from .stability import StabilityPlanner

#: Planner classes by method name.
PLANNERS = {"stability": StabilityPlanner, "explore": ExplorationPlanner, "ml_pose": MLPosePlanner,
            "open_loop": OpenLoopPlanner}


def default_cache_dir() -> Path:
    """Where models are cached: $BAYESGRASP_CACHE/models, else ~/.cache/bayesgrasp/models."""
    return cache_root() / "models"


_MODELS: dict = {}


def get_models(obj: Union[str, ObjectModel], hand: str = "barrett_bh8", settings: Optional[ModelSettings] = None,
               cache_dir=None, progress=None) -> GraspModels:
    """build_models with a per-process memo (a worker builds or loads each object's models once)."""
    settings = settings or ModelSettings()
    cache_dir = default_cache_dir() if cache_dir is None else cache_dir
    key = (obj if isinstance(obj, str) else id(obj), hand, settings, str(cache_dir))
    if key not in _MODELS:
        _MODELS[key] = build_models(obj, hand, settings, cache_dir=cache_dir, progress=progress)
    return _MODELS[key]


def make_planner(method: str, models: GraspModels, estimate, settings: Optional[PlannerSettings] = None,
                 seed: int = 0) -> Planner:
    if method not in PLANNERS:
        raise ValueError(f"method: one of {', '.join(PLANNERS)}; got {method!r}")
    return PLANNERS[method](models, estimate, settings, seed=seed)


def run_episode(obj: Union[str, ObjectModel], true_pose: Sequence[float], method: str = "explore", seed: int = 0,
                attempts: int = 4, settings: Optional[PlannerSettings] = None,
                model_settings: Optional[ModelSettings] = None, estimate: Optional[Sequence[float]] = None,
                measurement_noise: float = 0.0, lift: bool = True, hand: str = "barrett_bh8", cache_dir=None,
                models: Optional[GraspModels] = None, keep_planner: bool = False, on_attempt=None,
                stop_when_stable: bool = True) -> dict:
    """One run of the loop on ``obj`` whose hidden true pose is ``true_pose`` (x, y, yaw).

    The "vision" estimate defaults to the true pose plus noise uniform within the belief's
    half-widths, so the true pose lies inside the initial belief. Each attempt plans, executes
    the grasp at the true pose in the simulator (joint angles + Gaussian noise of std
    ``measurement_noise`` rad), scores it (stable = epsilon > the models' eps_stable; force closure
    = epsilon > 0; lift test when stable), and updates the belief if the grasp was not stable.

    Returns a JSON-ready dict: success, attempts (one dict per attempt), the initial and final
    belief summaries; with ``keep_planner`` also "planner" (the Planner object, not JSON) and
    "snapshots" (the particles and weights before each attempt and at the end). With
    ``stop_when_stable`` False every attempt is made (the thesis's fixed number of grasps) and the
    belief is updated after stable grasps too.
    """
    if attempts < 1:
        raise ValueError(f"attempts: must be at least 1, got {attempts}")
    if not (np.isfinite(measurement_noise) and measurement_noise >= 0):
        raise ValueError(f"measurement_noise: must be >= 0, got {measurement_noise}")
    settings = settings or PlannerSettings()
    obj_model = load_object(obj) if isinstance(obj, str) else obj
    true_pose = np.asarray(true_pose, dtype=float).ravel()
    if true_pose.shape != (3,) or not np.all(np.isfinite(true_pose)):
        raise ValueError(f"true pose: expected three finite numbers (x, y, yaw), got {true_pose}")
    world = World.single(obj_model, pose=true_pose, hand=hand)  # raises if off the table
    models = models or get_models(obj if isinstance(obj, str) else obj_model, hand, model_settings, cache_dir)
    rng = np.random.default_rng(seed)
    hw = np.asarray(settings.half_width, dtype=float)
    if estimate is None:
        estimate = true_pose + rng.uniform(-hw, hw)
    estimate = np.asarray(estimate, dtype=float)
    planner = make_planner(method, models, estimate, settings, seed=int(rng.integers(2**31)))
    initial = planner.summary(true_pose)
    snapshots = []
    eps_stable = models.settings.eps_stable
    out_attempts = []
    success = False
    for k in range(attempts):
        before = planner.summary(true_pose)
        if keep_planner:
            snapshots.append((planner.belief.particles, planner.belief.weights))
        plan = planner.plan()
        rel = relative_top_grasps(plan.action, true_pose)[0, 0]
        g = world.grasp_batch(rel[None, :], spread=models.spread)
        eps = float(g.epsilon[0])
        stable = eps > eps_stable
        lifted = None
        if lift and stable:
            lifted = bool(world.grasp_batch(rel[None, :], spread=models.spread, lift=True).lifted[0])
        q = np.asarray(g.joint_angles[0], dtype=float)[models.joint_index]
        if measurement_noise > 0:
            q = q + rng.normal(0.0, measurement_noise, q.shape)
        rec = {"attempt": k + 1, "kind": plan.kind, "action": plan.action.tolist(), "relative_grasp": rel.tolist(),
               "predicted_stability": float(plan.predicted_stability), "objective": float(plan.objective),
               "expected_entropy": plan.expected_entropy, "plan_seconds": plan.seconds,
               "evaluations": plan.evaluations, "epsilon": eps, "force_closure": eps > 0.0, "stable": bool(stable),
               "lifted": lifted, "collision_at_start": bool(g.collision_at_start[0]),
               "joint_angles": q.tolist(), "belief_before": before}
        success = success or stable
        if not (stable and stop_when_stable):
            planner.observe(plan.action, q, stable=stable)
            rec["belief_after"] = planner.summary(true_pose)
        out_attempts.append(rec)
        if on_attempt is not None:
            on_attempt(rec)
        if stable and stop_when_stable:
            break
    result = {"object": obj_model.name, "method": method, "true_pose": true_pose.tolist(),
              "estimate": np.asarray(estimate).tolist(), "seed": int(seed), "success": success,
              "first_success": next((a["attempt"] for a in out_attempts if a["stable"]), None),
              "lifted": any(a["lifted"] for a in out_attempts if a["lifted"] is not None),
              "attempts": out_attempts, "initial_belief": initial, "final_belief": planner.summary(true_pose)}
    if keep_planner:
        result["planner"] = planner
        snapshots.append((planner.belief.particles, planner.belief.weights))
        result["snapshots"] = snapshots
    return result
