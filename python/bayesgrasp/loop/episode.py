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
from typing import Callable, Optional, Sequence, Tuple, Union

import numpy as np

from ..models import GraspModels, relative_top_grasps
from ..objects import ObjectModel, load_object
from ..planners import Planner, PlannerSettings, Reading, make_planner
from ..world import ContactRecord, World
from .context import RunContext


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


@dataclass
class Execution:
    """One executed grasp: where it was relative to the object, how it scored, what the fingers
    read. ``success`` is the context's criterion (lifted, or ``stable``: epsilon above the models'
    eps_stable); ``lifted`` is None when no lift test ran."""

    relative_grasp: np.ndarray
    epsilon: float
    stable: bool
    lifted: Optional[bool]
    success: bool
    collision_at_start: bool
    joint_angles: np.ndarray
    hand_pose: Optional[np.ndarray] = None   # (4, 4) world pose of the hand where it closed
    contacts: Tuple[ContactRecord, ...] = ()  # where the hand touched (object and table), with parts


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


def _attempt_record(k: int, plan, ex: Execution, q: np.ndarray, before: dict, models: GraspModels) -> dict:
    return {"attempt": k + 1, "kind": plan.kind, "family": plan.family, "variant": models.variant.as_dict(),
            "action": plan.action.tolist(),
            "relative_grasp": ex.relative_grasp.tolist(), "predicted_stability": float(plan.predicted_stability),
            "objective": float(plan.objective), "expected_entropy": plan.expected_entropy,
            "plan_seconds": plan.seconds, "evaluations": plan.evaluations, "epsilon": ex.epsilon,
            "force_closure": ex.epsilon > 0.0, "stable": ex.stable, "lifted": ex.lifted, "success": ex.success,
            "collision_at_start": ex.collision_at_start, "joint_angles": q.tolist(),
            "hand_pose": None if ex.hand_pose is None else ex.hand_pose.tolist(),
            "joint_positions": ex.joint_angles.tolist(), "belief_before": before}


def _check_pose(true_pose) -> np.ndarray:
    p = np.asarray(true_pose, dtype=float).ravel()
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ValueError(f"true pose: expected three finite numbers (x, y, yaw), got {p}")
    return p


def run_episode(obj: Union[str, ObjectModel], true_pose: Sequence[float], episode: Optional[EpisodeSettings] = None,
                ctx: Optional[RunContext] = None, seed: int = 0, estimate: Optional[Sequence[float]] = None,
                models=None, keep_planner: bool = False,
                on_attempt: Optional[Callable[[dict], None]] = None) -> dict:
    """One run of the loop on ``obj`` whose hidden true pose is ``true_pose`` (x, y, yaw).

    ``models``: one family's GraspModels or {family: GraspModels} (default: the context's
    families, :meth:`RunContext.family_models`). The estimate defaults to
    :func:`initial_estimate`. Returns a JSON-ready dict: success,
    attempts (one dict per attempt), the initial and final belief summaries; with ``keep_planner``
    also "planner" (the Planner object, not JSON), "snapshots" (the particles and weights
    before each attempt and at the end) and "executions" (each attempt's :class:`Execution`, with
    its contacts).
    """
    episode = episode or EpisodeSettings()
    ctx = ctx or RunContext()
    obj_model = load_object(obj) if isinstance(obj, str) else obj
    true_pose = _check_pose(true_pose)
    world = World.single(obj_model, pose=true_pose, hand=ctx.hand)  # raises if off the table
    models = models or ctx.family_models(obj if isinstance(obj, str) else obj_model)
    rng = np.random.default_rng(seed)
    settings = ctx.planner_settings()
    estimate = initial_estimate(true_pose, settings, rng) if estimate is None else estimate
    estimate = np.asarray(estimate, dtype=float)
    planner = make_planner(episode.method, models, estimate, settings, seed=int(rng.integers(2**31)))
    initial = planner.summary(true_pose)
    snapshots, attempts, executions = [], [], []
    for k in range(episode.attempts):
        before = planner.summary(true_pose)
        if keep_planner:
            snapshots.append((planner.belief.particles, planner.belief.weights))
        plan = planner.plan()
        executed = planner.family_models[plan.family]
        ex = execute(world, executed, plan.action, true_pose, ctx)
        q = read_fingers(ex, executed, ctx.measurement_noise, rng)
        rec = _attempt_record(k, plan, ex, q, before, executed)
        executions.append(ex)
        stop = ex.success and episode.stop_when_stable
        if not stop:
            planner.observe(plan, Reading(q, held=ex.success))
            rec["belief_after"] = planner.summary(true_pose)
        attempts.append(rec)
        if on_attempt is not None:
            on_attempt(rec)
        if stop:
            break
    result = _episode_result(obj_model.name, episode.method, true_pose, estimate, seed, attempts, initial,
                             planner, true_pose, snapshots if keep_planner else None)
    if keep_planner:
        result["executions"] = executions
    return result


def _episode_result(name: str, method: str, true_pose, estimate, seed: int, attempts: list, initial: dict,
                    planner: Planner, truth, snapshots: Optional[list]) -> dict:
    result = {"object": name, "method": method, "true_pose": true_pose.tolist(),
              "estimate": np.asarray(estimate).tolist(), "seed": int(seed),
              "success": any(a["success"] for a in attempts),
              "first_success": next((a["attempt"] for a in attempts if a["success"]), None),
              "lifted": any(a["lifted"] for a in attempts if a["lifted"] is not None),
              "attempts": attempts, "initial_belief": initial, "final_belief": planner.summary(truth)}
    if snapshots is not None:
        result["planner"] = planner
        snapshots.append((planner.belief.particles, planner.belief.weights))
        result["snapshots"] = snapshots
    return result
