"""One category-grasping episode (thesis §4.2, Fig. 4.1's pipeline): see the new object once,
register its cloud against the category's training models, plan Eq. 4.1's grasp for the task,
approach along the planned pose, close, lift; report the pose, the per-model weights and
contributions, epsilon, lifted and whether the contacts are on the task's parts.

The pieces are named steps: :func:`training_models` (the category's members minus the held-out
one; tools train on hammers and test on knives), :func:`observe` (the camera view, or the whole
surface in the "complete model" mode the thesis warns is biased), :func:`register_models`,
:func:`plan_grasp` (:class:`~bayesgrasp.planners.category.CategoryPlanner`) and :func:`execute`.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..hand import Hand
from ..models.task_grasps import TaskGraspSettings, task_grasps
from ..models.tasks import TaskRule, task_rule
from ..objects import CATEGORY_SIZES, category, load_object
from ..objects.views import DEFAULT_EYE_OFFSET, capture_view
from ..planners.category import METHODS, CategoryPlan, CategoryPlanner, CategorySettings
from ..vision import Registrar, RegistrationResult, model_samples
from ..world import World
from .category_result import TaskGraspOutcome, TaskGraspResult
from .context import RunContext

#: Categories that train on another category's models (the thesis's tools experiment).
#: the category planner's methods (Eq. 4.1 and its part-aware variants), for the loop's users
PLAN_METHODS = METHODS

TRAINING_CATEGORY = {"knife": "hammer"}

#: Failure classes (the thesis's own failure analysis names the first three).
FAILURES = ("collision at start", "no contact", "slipped in the lift", "wrong part")


def training_models(category_name: str, exclude: Sequence[str] = ()) -> List[str]:
    """The training models for a new member of ``category_name``: the category's listed members
    without ``exclude`` (leave-one-out), or the training category's (knives: the hammers)."""
    if category_name not in CATEGORY_SIZES:
        raise ValueError(f"category: one of {', '.join(CATEGORY_SIZES)}; got {category_name!r}")
    source = TRAINING_CATEGORY.get(category_name, category_name)
    models = [m for m in category(source) if m not in set(exclude)]
    if not models:
        raise ValueError(f"category {category_name!r}: no training models left after excluding {list(exclude)}")
    return models


@lru_cache(maxsize=8)
def _registrar(models: Tuple[str, ...], voxel: float) -> Registrar:
    """The training models prepared once per process (the preparation is the costly part)."""
    return Registrar([load_object(m) for m in models], names=list(models), voxel=voxel)


@dataclass
class Observation:
    """What the robot sees: the object's cloud (world frame) and the camera centre."""

    cloud: np.ndarray
    viewpoint: np.ndarray
    complete: bool = False


def observe(obj, pose, eye_offset=DEFAULT_EYE_OFFSET, seed: int = 0, complete: bool = False) -> Observation:
    """One simulated depth view, segmented; or (``complete``) the object's whole surface, placed
    at the pose (the thesis's simulated set-up, biased by the complete model)."""
    if not complete:
        v = capture_view(obj, pose, eye_offset, seed)
        return Observation(v.object_points, np.asarray(v.camera.eye, float))
    o = load_object(obj)
    P, _ = model_samples(o, samples=3000, seed=seed)
    x, y, yaw = pose
    c, s = np.cos(yaw), np.sin(yaw)
    P = P @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]).T + np.array([x, y, 0.0])
    return Observation(P, P.mean(axis=0) + np.asarray(eye_offset, float), complete=True)


def register_models(observation: Observation, models: Sequence[str], seed: int = 0,
                    voxel: float = 0.005) -> List[RegistrationResult]:
    """Each training model registered to the cloud: transform (model -> world) and phi(delta)."""
    return _registrar(tuple(models), float(voxel)).register(observation.cloud, seed=seed,
                                                             viewpoint=observation.viewpoint)


def demonstrated(models: Sequence[str], rule: TaskRule, ctx: RunContext,
                 settings: Optional[TaskGraspSettings] = None):
    """The training models' task grasps for the rule (generated once, cached under the context's cache)."""
    from ..models import default_cache_dir

    cache = Path(ctx.cache_dir or default_cache_dir()).parent / "task_grasps"
    return task_grasps(models, rule, ctx.hand, settings, cache_dir=cache, say=ctx.progress)


def execute(obj, pose, plan: CategoryPlan, rule: TaskRule, ctx: RunContext) -> TaskGraspOutcome:
    """The planned grasp executed on the object at its true pose: the open hand approaches along
    the planned pose's direction through its position with its roll, closes, is lift-tested;
    task_ok: the object contacts obey the task's rule; success = lifted and task_ok."""
    if not plan.ok:
        return TaskGraspOutcome(False, plan.reason, lifted=False, task_ok=False, success=False, epsilon=0.0,
                                force_closure=False, failure="no contact")
    world = World.single(obj, pose=pose, hand=ctx.hand_model, table=rule.table)
    A = plan.pose
    g = world.approach(A[:3, 2], A[:3, 3], Hand.approach_roll(A), spread=plan.spread, frame="world", lift=True)
    parts = [c.part for c in g.contacts if not c.on_table]
    task_ok = bool(rule.contacts_ok(parts)) and not g.collision_at_start
    lifted = bool(g.lifted)
    failure = None
    if g.collision_at_start:
        failure = "collision at start"
    elif not parts or g.stopped_by_table:
        failure = "no contact"
    elif not task_ok:
        failure = "wrong part"
    elif not lifted:
        failure = "slipped in the lift"
    return TaskGraspOutcome(True, "", np.asarray(g.hand_pose).tolist(), plan.spread, float(g.epsilon),
                            float(g.epsilon) > 0.0, lifted, task_ok, lifted and task_ok, failure, parts,
                            bool(g.collision_at_start), bool(g.stopped_by_table), np.asarray(g.joint_angles).tolist(),
                            list(g.joint_names))


def not_executed(plan: CategoryPlan) -> TaskGraspOutcome:
    """The outcome of a plan made on camera data with no stand-in to execute it on."""
    return TaskGraspOutcome(False, plan.reason if not plan.ok else "", spread=plan.spread if plan.ok else None,
                            failure=None if plan.ok else "no contact")


@dataclass
class CategoryEpisode:
    """A scene and its registrations, reusable for several tasks and methods (the same view)."""

    obj: Optional[str]
    pose: Tuple[float, float, float]
    models: List[str]
    observation: Observation
    registrations: List[RegistrationResult]
    extra: Dict = field(default_factory=dict)
    #: the training models warped onto this view, per (samples, seed): computed once for every task
    warps: Dict = field(default_factory=dict, repr=False)


def see(obj: Optional[str], pose, category_name: str, exclude: Sequence[str] = (), eye_offset=DEFAULT_EYE_OFFSET,
        seed: int = 0, complete: bool = False, observation: Optional[Observation] = None) -> CategoryEpisode:
    """The episode's view and registrations: ``observation`` (a camera's cloud in the table frame,
    see :mod:`bayesgrasp.io`) when given, else a simulated view of ``obj`` at ``pose``. ``obj`` is
    the simulated stand-in the grasp is executed on; None: plan only."""
    models = training_models(category_name, exclude)
    if observation is None:
        if obj is None:
            raise ValueError("obj: needed for a simulated view when no observation is given")
        observation = observe(obj, pose, eye_offset, seed, complete)
    return CategoryEpisode(None if obj is None else str(obj), tuple(float(v) for v in pose), models, observation,
                           register_models(observation, models, seed))


def plan_and_execute(ep: CategoryEpisode, category_name: str, task: str, method: str, ctx: RunContext,
                     settings: Optional[CategorySettings] = None, seed: int = 0,
                     grasps: Optional[Sequence] = None, reach=None) -> TaskGraspResult:
    """Eq. 4.1 for one task and method on the episode's registrations, then the execution.
    ``grasps``: the demonstrated grasps to use (default: generated from the task's rule, cached);
    ``reach``: the planner's (:attr:`CategoryPlanner.reach`: the grasps an arm reaches)."""
    rule = task_rule(category_name, task)
    grasps = demonstrated(ep.models, rule, ctx) if grasps is None else grasps
    grasps = [g for g in grasps if g.task == task]
    s = replace(settings or CategorySettings(method=method), table=rule.table)
    key = (s.warp_samples, s.clearance_voxel, seed)
    planner = CategoryPlanner(ctx.hand_model, grasps, ep.registrations, cloud=ep.observation.cloud, settings=s, seed=seed,
                              rule=rule, warped=ep.warps.get(key))
    planner.reach = reach
    plan = planner.plan()
    if s.method == "warped":
        ep.warps[key] = planner.warped_models()        # the same view's other tasks reuse them
    outcome = execute(ep.obj, ep.pose, plan, rule, ctx) if ep.obj is not None else not_executed(plan)
    return TaskGraspResult(plan, outcome, method, task, len(grasps))
