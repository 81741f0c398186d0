"""The closed loop of thesis Figs. 3.1 and 3.4: plan, execute at the hidden true pose in the
simulator, read the joint angles, update the belief, re-plan, until the grasp is stable or the
attempts run out.

:func:`run_episode` is a pure function of its arguments (object, true pose, episode settings,
context, seed): the experiments call it run by run, in any process. One attempt is four named
steps: :func:`plan` is the planner's, then :func:`execute` (the grasp at the true pose, scored),
:func:`read_fingers` (the measured joint angles) and the planner's ``observe``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional, Sequence, Union

import numpy as np

from ..models import GraspModels, relative_top_grasps
from ..objects import ObjectModel, load_object
from ..planners import Planner, PlannerSettings, Reading, make_planner
from ..world import World
from .context import RunContext
from .episode_result import Attempt, EpisodeResult, Execution


@dataclass(frozen=True)
class EpisodeSettings:
    """method: a planner name (see :data:`bayesgrasp.planners.PLANNERS`); attempts: grasps at most;
    stop_when_stable: stop at the first successful grasp (False: every attempt is made, the
    thesis's fixed number of grasps, and the belief is updated after successful grasps too). The
    rest comes from the run context, each setting from there only: what success is
    (:attr:`RunContext.success`), the planner's settings (:meth:`RunContext.planner_settings`),
    the noise on the measured joint angles (:attr:`RunContext.measurement_noise`), the models'
    settings."""

    method: str = "explore"
    attempts: int = 4
    stop_when_stable: bool = True

    def __post_init__(self):
        if self.attempts < 1:
            raise ValueError(f"attempts: must be at least 1, got {self.attempts}")


def initial_estimate(true_pose: np.ndarray, settings: PlannerSettings, rng: np.random.Generator) -> np.ndarray:
    """The "vision" estimate: the true pose plus noise uniform within the belief's half-widths, so
    that the true pose lies inside the initial belief."""
    hw = np.asarray(settings.half_width, dtype=float)
    return true_pose + rng.uniform(-hw, hw)


def execute(world: World, models: GraspModels, action: np.ndarray, true_pose: np.ndarray,
            ctx: RunContext) -> Execution:
    """The world grasp ``action`` of the models' family executed on the object at its true pose
    and scored: with success "lift" every grasp is lift-tested and success means lifted; with
    "epsilon" success means epsilon above the models' eps_stable, and the lift test (if
    ``ctx.lift``) runs on stable grasps only."""
    rel = relative_top_grasps(action, true_pose)[0, 0]
    by_lift = ctx.success == "lift"
    variant = models.variant
    g = variant.simulate(world, rel[None, :], lift=by_lift)
    eps = float(g.epsilon[0])
    stable = eps > models.settings.eps_stable
    lifted = bool(g.lifted[0]) if by_lift else None
    if not by_lift and ctx.lift and stable:
        lifted = bool(variant.simulate(world, rel[None, :], lift=True).lifted[0])
    return Execution(rel, eps, bool(stable), lifted, bool(lifted) if by_lift else bool(stable),
                     bool(g.collision_at_start[0]), np.asarray(g.joint_angles[0], dtype=float),
                     np.asarray(g.hand_pose[0], dtype=float), tuple(g.contact_records(0, world.hand.links)))


def read_fingers(execution: Execution, models: GraspModels, noise: float, rng: np.random.Generator) -> np.ndarray:
    """The measurement M: the modelled joint angles, plus Gaussian noise of std ``noise`` rad (a
    jaw's travel: ``noise`` x 0.05 m, the models' measurement_scale)."""
    q = execution.joint_angles[models.joint_index]
    if noise > 0:
        q = q + rng.normal(0.0, noise, q.shape) * np.asarray(models.info["measurement_scale"], dtype=float)
    return q


def _attempt(k: int, planner: Planner, world: World, true_pose: np.ndarray, ctx: RunContext,
             rng: np.random.Generator) -> Attempt:
    """Attempt ``k`` (from 0): the plan, its execution at the true pose and the fingers' reading."""
    before = planner.summary(true_pose)
    plan = planner.plan()
    executed = planner.family_models[plan.family]
    ex = execute(world, executed, plan.action, true_pose, ctx)
    q = read_fingers(ex, executed, ctx.measurement_noise, rng)
    return Attempt(k + 1, plan, executed.variant, ex, q, world.hand, before)


def _check_pose(true_pose) -> np.ndarray:
    p = np.asarray(true_pose, dtype=float).ravel()
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ValueError(f"true pose: expected three finite numbers (x, y, yaw), got {p}")
    return p


def run_episode(obj: Union[str, ObjectModel], true_pose: Sequence[float], episode: Optional[EpisodeSettings] = None,
                ctx: Optional[RunContext] = None, seed: int = 0, estimate: Optional[Sequence[float]] = None,
                models=None, keep_planner: bool = False,
                on_attempt: Optional[Callable[[Attempt], None]] = None, reach=None) -> EpisodeResult:
    """One run of the loop on ``obj`` whose hidden true pose is ``true_pose`` (x, y, yaw).

    ``models``: one family's GraspModels or {family: GraspModels} (default: the context's
    families, :meth:`RunContext.family_models`). The estimate defaults to
    :func:`initial_estimate`. ``on_attempt`` is called with each :class:`Attempt` when it is done.
    Returns an :class:`EpisodeResult` (its ``to_dict()`` is the stored record); with
    ``keep_planner`` it also holds the planner and the belief's snapshots (particles and weights
    before each attempt and at the end). ``reach``: the planner's (:attr:`Planner.reach`, e.g. a
    :class:`~bayesgrasp.planners.reach.ActionReach`): it then plans over the grasps an arm reaches.
    """
    episode = episode or EpisodeSettings()
    ctx = ctx or RunContext()
    obj_model = load_object(obj) if isinstance(obj, str) else obj
    true_pose = _check_pose(true_pose)
    world = World.single(obj_model, pose=true_pose, hand=ctx.hand_model)  # raises if off the table
    models = models or ctx.family_models(obj if isinstance(obj, str) else obj_model)
    rng = np.random.default_rng(seed)
    settings = ctx.planner_settings()
    estimate = initial_estimate(true_pose, settings, rng) if estimate is None else estimate
    estimate = np.asarray(estimate, dtype=float)
    planner = make_planner(episode.method, models, estimate, settings, seed=int(rng.integers(2**31)))
    planner.reach = reach
    initial = planner.summary(true_pose)
    snapshots, attempts = [], []
    for k in range(episode.attempts):
        if keep_planner:
            snapshots.append((planner.belief.particles, planner.belief.weights))
        attempt = _attempt(k, planner, world, true_pose, ctx, rng)
        stop = attempt.success and episode.stop_when_stable
        if not stop:
            planner.observe(attempt.plan, Reading(attempt.measured, held=attempt.success))
            attempt.belief_after = planner.summary(true_pose)
        attempts.append(attempt)
        if on_attempt is not None:
            on_attempt(attempt)
        if stop:
            break
    if keep_planner:
        snapshots.append((planner.belief.particles, planner.belief.weights))
    return EpisodeResult(obj_model.name, episode.method, true_pose, estimate, int(seed), attempts, initial,
                         planner.summary(true_pose), planner if keep_planner else None,
                         snapshots if keep_planner else None)
