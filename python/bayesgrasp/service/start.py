"""A new episode or a one-shot plan from a request body: the kind of episode its fields ask for,
started through the loop as ``bayesgrasp episode new`` starts it (the same calls, so the same
grasps), or a category task's grasp as ``bayesgrasp category`` plans it, with the server's model
cache."""
from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np

from ..loop.category import Observation, observe
from ..loop.context import context_from_plain
from ..loop.outside_loop import METHODS as POSE_METHODS, PoseEpisode, check_builtin_hand, check_builtin_object
from ..loop.outside_loop_category import FUSION, EPISODE_CATEGORY_METHODS, CategoryTaskEpisode, FusionEpisode
from .bodies import NewEpisode, Planning
from .errors import ApiError


def _refuse(field: str, why: str):
    raise ApiError(422, "invalid_body", f"{field}: {why}")


def _context(body: Planning, cache_dir: Optional[str], reads=("models", "planner")):
    for group in ("models", "planner"):
        if getattr(body, group) and group not in reads:
            _refuse(group, "this kind of episode does not read these settings")
    check_builtin_hand(body.hand)
    try:
        return context_from_plain(body.hand, cache_dir, body.seed, body.models, body.planner)
    except ValueError as e:
        _refuse("settings", str(e))


def _pose_inputs(body: Planning):
    if body.object is None:
        _refuse("object", "needed (the object whose pose is uncertain), or give category and task")
    if body.estimate is None:
        _refuse("estimate", "needed: the object's estimated x, y (m) and yaw (rad) on the table")
    for field in ("cloud", "viewpoint", "exclude"):
        if getattr(body, field) is not None:
            _refuse(field, "only with category and task")
    method = body.method or "explore"
    if method not in POSE_METHODS:
        _refuse("method", f"one of {', '.join(POSE_METHODS)} for a pose episode (a category method needs category "
                          f"and task), got {method!r}")
    return check_builtin_object(body.object), method


def _view(body: Planning, seed: int) -> Observation:
    """The view to plan from: the client's cloud, or the simulated view of a built-in object."""
    if body.cloud is not None:
        if body.viewpoint is None:
            _refuse("viewpoint", "needed with cloud (the camera centre, m)")
        return Observation(np.asarray(body.cloud, float), np.asarray(body.viewpoint, float))
    if body.object is None:
        _refuse("cloud", "cloud + viewpoint, or object: the view to plan from")
    return observe(check_builtin_object(body.object), tuple(body.object_pose), seed=seed)


def _category_method(body: Planning) -> str:
    if body.estimate is not None:
        _refuse("estimate", "not with category (the view's registrations place the models)")
    method = body.method or "laplace"
    if method not in EPISODE_CATEGORY_METHODS:
        _refuse("method", f"with category one of {', '.join(EPISODE_CATEGORY_METHODS)}, got {method!r}")
    return method


def _arm(body: Planning, hand):
    """The built-in arm ``body.robot`` at ``robot_base`` with its ``flange`` and ``mount`` (default:
    the hand's base on the flange), as ``--robot`` makes it; None without ``robot``."""
    from ..arm import Arm, builtin_arms, default_mount, mount_pose

    if body.robot is None:
        for field in ("flange", "mount"):
            if getattr(body, field) is not None:
                _refuse(field, "only with robot")
        return None
    if body.robot not in builtin_arms():
        _refuse("robot", f"not a built-in arm, got {body.robot!r} (built-in: {', '.join(builtin_arms())})")
    try:
        mount = default_mount(hand) if body.mount is None else mount_pose(body.mount)
        return Arm.load(body.robot, flange=body.flange, mount=mount, base=body.robot_base)
    except ValueError as e:
        msg = str(e)
        field = next((f for f in ("flange", "mount", "base") if msg.startswith(f)), "robot")
        _refuse("robot_base" if field == "base" else field, msg.split(": ", 1)[-1])


def start_episode(directory: Path, body: NewEpisode, cache_dir: Optional[str]):
    """The episode ``body`` asks for, written to ``directory`` with its first grasp planned."""
    if bool(body.category) != bool(body.task):
        _refuse("category, task", "give both")
    if not body.category:
        obj, method = _pose_inputs(body)
        ctx = _context(body, cache_dir)
        return PoseEpisode.new(directory, obj, body.estimate, ctx, method=method, attempts=body.attempts,
                               seed=ctx.seed, planner=ctx.planner_settings(), arm=_arm(body, ctx.hand_model))
    method = _category_method(body)
    ctx = _context(body, cache_dir, reads=("models",) if method == FUSION else ())
    view = _view(body, ctx.seed)
    exclude = body.exclude if body.exclude is not None else [m for m in [body.object] if m]   # as the CLI
    common = dict(exclude=exclude, seed=ctx.seed, grasps=None, arm=_arm(body, ctx.hand_model))
    if method == FUSION:
        return FusionEpisode.new(directory, view, body.category, body.task, ctx, attempts=body.attempts, **common)
    return CategoryTaskEpisode.new(directory, view, body.category, body.task, ctx, method=method, **common)


def first_grasp(body: Planning, cache_dir: Optional[str]) -> dict:
    """The first grasp of the pose episode ``body`` describes (as :func:`start_episode` would plan
    it), written nowhere."""
    obj, method = _pose_inputs(body)
    if body.robot is not None:
        _refuse("robot", "a one-shot pose plan takes no arm; start an episode with robot")
    ctx = _context(body, cache_dir)
    return PoseEpisode.first_grasp(obj, body.estimate, ctx, method=method, seed=ctx.seed,
                                   planner=ctx.planner_settings())


def category_answer(body: Planning, cache_dir: Optional[str]) -> dict:
    """What ``bayesgrasp category --json`` prints for the category task ``body`` describes (the
    view: ``cloud`` + ``viewpoint``, or the simulated view of ``object`` at ``object_pose``;
    ``object``, when given, is the stand-in the grasp is executed on), written nowhere."""
    from ..io.results import category_document
    from ..loop.category import PLAN_METHODS as METHODS
    from ..loop.category import plan_and_execute, see, task_rule
    from ..loop.reach import table_reach, with_arm_on

    if not (body.category and body.task):
        _refuse("category, task", "give both")
    if body.estimate is not None:
        _refuse("estimate", "not with category (the view's registrations place the models)")
    method = body.method or "laplace"
    if method not in METHODS:
        _refuse("method", f"a one-shot category plan is one of {', '.join(METHODS)}, got {method!r}"
                          + (" (vision then touch is an episode: POST /v1/episodes)" if method == FUSION else ""))
    try:
        task_rule(body.category, body.task)
    except ValueError as e:
        field, _, why = str(e).partition(": ")
        _refuse(field, why)
    obj = None if body.object is None else check_builtin_object(body.object)
    ctx = _context(body, cache_dir, reads=())
    arm = _arm(body, ctx.hand_model)
    view = _view(body, ctx.seed)
    exclude = body.exclude if body.exclude is not None else [m for m in [obj] if m]   # as the CLI
    try:
        ep = see(obj, tuple(body.object_pose), body.category, exclude=exclude, seed=ctx.seed, observation=view)
    except ValueError as e:
        field, _, why = str(e).partition(": ")
        _refuse(field, why)
    if not any(r.success for r in ep.registrations):
        raise ApiError(422, "not_registered", "no training model registered to the cloud (is the object in view, "
                                              "is it of this category?)")
    r = plan_and_execute(ep, body.category, body.task, method, ctx, seed=ctx.seed,
                         reach=None if arm is None else table_reach(arm))
    grasp = r.grasp(ctx.hand_model)
    if arm is not None and grasp is not None:
        grasp = with_arm_on(arm, grasp, obj, ep.pose, ctx.hand)
    return category_document(r, grasp, ep, body.category, None, "simulated view" if body.cloud is None else "cloud")
