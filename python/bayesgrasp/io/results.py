"""The loop's results as JSON, in one place: what ``to_dict()`` of each result type returns.

The types live in the loop layer where they are computed (``loop/episode_result.py``,
``category_result.py``, ``fusion_result.py``, ``touch_trial.py``); this module reads their
attributes and writes the published shapes, which the CLI, the viewer, the episode files and the
results database read:

    episode_dict(result)          # an episode: the experiments' stored record (results database)
    attempt_grasp(attempt)        # an episode's executed grasp in the grasp schema (also round_grasp, touch_grasp)
    plan_document(result, ...)    # ``bayesgrasp plan`` / ``demo``: the same episode for the user and the viewer
    task_grasp_dict(result)       # a category plan and its execution (a TaskGraspResult), as stored
    category_document(result, ...)   # ``bayesgrasp category``: the same for the user and the viewer
    touch_document(trial, ...)    # ``bayesgrasp touch``: one touch and its fit (a TouchTrial)
    fusion_dict(result)           # a vision-then-touch trial (a FusionResult), as stored
    fuse_document(result, ...)    # ``bayesgrasp fuse``: the same for the user and the viewer
    grasp_document(grasp, ...)    # ``bayesgrasp grasp``: one grasp in a world (a WorldGrasp)

Aliases kept for one release (users read them): in a plan document's attempt, ``plan_type`` is
the episode record's ``kind``, ``top_grasp`` repeats ``action`` for a top grasp (None for other
families) and ``outcome`` repeats ``success`` as "success" / "failure"; read ``action`` and
``success``.
"""
from __future__ import annotations

from dataclasses import fields
from typing import Optional, Sequence

import numpy as np

from .grasp_schema import hand_grasp_record
from .view_fields import belief_json, cloud_json


def _list(a) -> Optional[list]:
    return None if a is None else np.asarray(a).tolist()


def attempt_grasp(a) -> dict:
    """An episode attempt's executed grasp (an :class:`Attempt`) in the grasp schema (world frame,
    where the hand closed)."""
    return hand_grasp_record(a.hand, a.execution.hand_pose, a.execution.joint_angles, a.variant.spread)


def episode_attempt_dict(a) -> dict:
    """One attempt of an episode (an :class:`Attempt`) as the experiments store it."""
    plan, ex = a.plan, a.execution
    rec = {"attempt": a.number, "kind": plan.kind, "family": plan.family, "variant": a.variant.as_dict(),
           "action": _list(plan.action),
           "relative_grasp": _list(ex.relative_grasp), "predicted_stability": float(plan.predicted_stability),
           "objective": float(plan.objective), "expected_entropy": plan.expected_entropy,
           "plan_seconds": plan.seconds, "evaluations": plan.evaluations, "epsilon": ex.epsilon,
           "force_closure": ex.epsilon > 0.0, "stable": ex.stable, "lifted": ex.lifted, "success": ex.success,
           "collision_at_start": ex.collision_at_start, "joint_angles": _list(a.measured),
           "hand_pose": _list(ex.hand_pose),
           "joint_positions": _list(ex.joint_angles), "belief_before": a.belief_before}
    if a.belief_after is not None:
        rec["belief_after"] = a.belief_after
    return rec


def episode_dict(r) -> dict:
    """An episode (an :class:`EpisodeResult`) as JSON: its settings, outcome, attempts and the
    initial and final belief summaries (the planner and the particle snapshots are not JSON)."""
    return {"object": r.object, "method": r.method, "true_pose": _list(r.true_pose),
            "estimate": _list(r.estimate), "seed": int(r.seed),
            "success": r.success, "first_success": r.first_success, "lifted": r.lifted,
            "attempts": [episode_attempt_dict(a) for a in r.attempts],
            "initial_belief": r.initial_belief, "final_belief": r.final_belief}


def _plan_attempt_dict(a, snapshot) -> dict:
    plan, ex = a.plan, a.execution
    action = _list(plan.action)
    return {"plan_type": plan.kind, "family": plan.family, "variant": a.variant.as_dict(),
            "top_grasp": action if plan.family == "top" else None,
            "action": action, "grasp": attempt_grasp(a), "predicted_stability": float(plan.predicted_stability),
            "expected_entropy": plan.expected_entropy, "entropy": a.belief_before["kde_entropy"],
            "epsilon": ex.epsilon, "stable": ex.stable, "lifted": ex.lifted,
            "success": ex.success, "outcome": "success" if ex.success else "failure",
            "plan_seconds": plan.seconds,
            "joint_angles": _list(a.measured), "belief": belief_json(*snapshot),
            "contacts": [c.to_dict() for c in ex.contacts if not c.on_table]}


def _final_belief_dict(f: dict, snapshot) -> dict:
    return {"mean": f["mean"], "std": f["std"], "entropy": f["kde_entropy"], "ess": f["ess"],
            "position_error": f["position_error"], "yaw_error": f["yaw_error"], **belief_json(*snapshot)}


def plan_document(r, object_name: str, units: Optional[str], criterion: str, vision: Optional[dict] = None) -> dict:
    """``bayesgrasp plan``'s JSON of an episode run with ``keep_planner`` (its snapshots give each
    attempt the belief it was planned from): ``object_name`` as the user gave it, the mesh's
    ``units``, the success ``criterion``; ``vision`` (:func:`vision_dict`) when the belief came
    from camera data. Each attempt carries the executed grasp in the grasp schema and its
    contacts with the object (with parts); the aliases are in the module's doc."""
    doc = {"object": object_name, "units": units, "method": r.method, "true_pose": _list(r.true_pose),
           "estimate": _list(r.estimate), "success_criterion": criterion, "success": r.success,
           "attempts": [_plan_attempt_dict(a, s) for a, s in zip(r.attempts, r.snapshots)],
           "final_belief": _final_belief_dict(r.final_belief, r.snapshots[-1])}
    if vision is not None:
        doc["vision"] = vision
    return doc


def vision_dict(start, scene: str, object_points) -> dict:
    """A vision start (:class:`~bayesgrasp.loop.vision_start.VisionStart`) in a plan document:
    the camera data's file, the estimate and spread it gave, the registration and the cloud."""
    return {"scene": scene, "estimate": _list(start.estimate), "half_width": _list(start.half_width),
            "registration": start.registration.as_dict(), "cloud": cloud_json(object_points)}


def task_grasp_outcome_dict(o) -> dict:
    """A :class:`~bayesgrasp.loop.category_result.TaskGraspOutcome`: every field, None where not measured."""
    return {f.name: getattr(o, f.name) for f in fields(o)}


def task_grasp_dict(r) -> dict:
    """A :class:`~bayesgrasp.loop.category_result.TaskGraspResult` as the experiments store it:
    the outcome's fields, then the plan's (its ``method`` replaced by the method asked for), the
    task and the number of demonstrated grasps."""
    return {**task_grasp_outcome_dict(r.outcome), **r.plan.to_dict(), "method": r.method, "task": r.task,
            "task_grasps": r.task_grasps}


def tasks_dict(tasks) -> dict:
    """{task: {method: TaskGraspResult}} (a category run's plans for every task and method) as stored."""
    return {t: {m: task_grasp_dict(r) for m, r in by_method.items()} for t, by_method in tasks.items()}


def _registered_models(r, models: Sequence[str], registrations) -> list:
    w, c = r.plan.weights, r.plan.contributions
    return [{"model": m, "weight": w[m], "contribution": c[m], "success": bool(g.success),
             "transform": _list(g.transform)} for m, g in zip(models, registrations)]


def category_document(r, grasp: Optional[dict], episode, category: str, units: Optional[str], scene: str) -> dict:
    """``bayesgrasp category``'s JSON of a :class:`TaskGraspResult` on ``episode`` (a
    :class:`~bayesgrasp.loop.category.CategoryEpisode`: its stand-in object and pose, training
    models, registrations and cloud): ``grasp`` the plan in the grasp schema, ``scene`` where
    the view came from. A part-aware plan adds ``part_check`` (P(rule | A), P(rule, held | A)
    and each model's contact parts)."""
    o = r.outcome
    doc = {"grasp": grasp, "planned_pose": r.planned_pose, "method": r.method,
           "category": category, "task": r.task, "scene_object": episode.obj, "units": units,
           "object_pose": list(episode.pose) if episode.obj else None, "executed": o.executed, "scene": scene,
           "models": _registered_models(r, episode.models, episode.registrations),
           "cloud": cloud_json(episode.observation.cloud),
           "epsilon": o.epsilon, "lifted": o.lifted, "task_ok": o.task_ok, "success": o.success,
           "failure": o.failure, "reason": o.reason or None, "contact_parts": o.contact_parts}
    if r.plan.extra:
        doc["part_check"] = r.plan.extra
    return doc


def pose_errors_dict(e) -> dict:
    """A :class:`~bayesgrasp.loop.touch_trial.PoseErrors`."""
    return {"position_error": e.position_error, "orientation_error": e.orientation_error, "size_error": e.size_error}


def touch_grasp(t) -> dict:
    """A :class:`~bayesgrasp.loop.touch_trial.TouchTrial`'s executed touch in the grasp schema
    (world frame, where the hand closed)."""
    return hand_grasp_record(t.planner.model.hand, t.readings.hand_pose, t.readings.joints, t.touch.spread)


#: the fit's fields a touch document leaves out (the guess and estimate are given once, timing aside)
_FIT_LEFT_OUT = ("initial", "state", "stopped", "cpu_seconds")


def _touch_readings(t) -> dict:
    rd = t.readings
    return {"joint_angles": _list(rd.joints), "joint_names": list(t.planner.model.hand.core.joint_names),
            "contact_links": t.contact_links, "hand_pose": _list(rd.hand_pose)}


def touch_document(t, object_name: str, units: Optional[str], case: str) -> dict:
    """``bayesgrasp touch``'s JSON of a :class:`~bayesgrasp.loop.touch_trial.TouchTrial`:
    ``object_name`` as the user gave it, the mesh's ``units``, the ``case`` (the unknowns)."""
    settings, g = t.planner.settings, t.touch
    return {
        "object": object_name, "units": units, "case": case, "optimizer": settings.optimizer,
        "contact_term": settings.contact_term,
        "true_state": _list(t.truth), "initial": _list(t.initial), "estimate": _list(t.estimate),
        "top_grasp": {"x": g.x, "y": g.y, "yaw": g.yaw, "spread": g.spread},
        "grasp": touch_grasp(t), "readings": _touch_readings(t),
        **{k: v for k, v in t.fit.to_dict().items() if k not in _FIT_LEFT_OUT},
        "errors_before": pose_errors_dict(t.errors_before),
        "errors_after": pose_errors_dict(t.errors_after),
    }


def round_grasp(x, hand, spread: float) -> dict:
    """A :class:`~bayesgrasp.loop.fusion_result.FusionRound`'s executed grasp in the grasp schema
    (world frame, where ``hand`` closed at ``spread``)."""
    return hand_grasp_record(hand, x.execution.hand_pose, x.execution.joint_angles, spread)


def fusion_round_dict(r) -> dict:
    """A :class:`~bayesgrasp.loop.fusion_result.FusionRound` as stored: the executed grasp, the
    belief it was planned from, and Eq. 4.6's value and factors (None for G(0))."""
    e, plan = r.execution, r.plan
    return {"round": r.number, "action": _list(e.action), "lifted": e.lifted, "epsilon": e.epsilon,
            "hand_pose": _list(e.hand_pose), "joint_positions": _list(e.joint_angles),
            "weights": r.weights, "poses": r.poses,
            "underflow": r.underflow, "objective": None if plan is None else plan.objective,
            **({} if plan is None or plan.part is None else {"part": plan.part}),
            "stability": None if plan is None else plan.stability, "task": None if plan is None else plan.task}


def fusion_dict(r) -> dict:
    """A :class:`~bayesgrasp.loop.fusion_result.FusionResult` as stored."""
    return {"mode": r.mode, "rounds": [fusion_round_dict(x) for x in r.rounds],
            "registrations": [{"model": n, "weight": float(w)} for n, w in zip(r.names, r.vision_weights)]}


def _fuse_round(x, names, grasp: dict) -> dict:
    e = x.execution
    return {"round": x.number, "top_grasp": _list(e.action), "grasp": grasp, "epsilon": e.epsilon, "lifted": e.lifted,
            "weights": dict(zip(names, x.weights)), "poses": dict(zip(names, x.poses)), "underflow": x.underflow,
            **({"part": x.plan.part} if x.plan is not None and x.plan.part is not None else {})}


def fuse_rounds(r, grasps: Sequence[dict]) -> list:
    """The rounds of ``bayesgrasp fuse``'s JSON, each with its executed grasp (``grasps``, in the
    grasp schema) and the belief as {model: value}; ``top_grasp`` is the round's action."""
    return [_fuse_round(x, r.names, g) for x, g in zip(r.rounds, grasps)]


def fuse_document(r, rounds: list, episode, settings, *, category: Optional[str], task: str, units: Optional[str],
                  scene: str) -> dict:
    """``bayesgrasp fuse``'s JSON: ``rounds`` from :func:`fuse_rounds`; ``episode`` the trial's
    view (its stand-in object and pose, cloud); ``settings`` its FusionSettings (belief,
    task_term, avoid_failed); ``category`` and ``task`` as the user gave them."""
    return {"scene_object": episode.obj, "units": units, "object_pose": list(episode.pose),
            "category": category, "task": task, "start": r.mode, "belief": settings.belief,
            "task_term": settings.task_term, "avoid_failed": settings.avoid_failed, "rounds": rounds,
            "success": r.success, "scene": scene, "cloud": cloud_json(episode.observation.cloud)}


_MASS_METHODS = {"mesh": "its closed mesh", "fill": "the solid its open mesh bounds (sampled)",
                 "shell": "its open mesh as a thin shell"}


def mass_source(obj) -> str:
    """Where an object's mass comes from: given (--mass) or how its mesh was weighed."""
    return "given (--mass)" if obj.given_mass is not None else _MASS_METHODS[obj.mass_method]


def mass_dict(obj) -> dict:
    """The mass the lift test uses (kg), where it comes from, and the density."""
    return {"kg": float(obj.mass), "from": mass_source(obj), "density": float(obj.density)}


def _approach_dict(a) -> Optional[dict]:
    return None if a is None else {"direction": a.direction, "roll": a.roll, "target": a.target}


def grasp_document(g, request, world, *, object_name: str, object_pose, frame: str, units: Optional[str],
                   spread: float) -> dict:
    """``bayesgrasp grasp``'s JSON of a :class:`~bayesgrasp.world.WorldGrasp` made in ``world``
    for ``request`` (its ``mode`` and the one input: ``top``, ``approach`` or ``pose``, in
    ``frame``); ``grasp`` is the same grasp in the grasp schema."""
    return {
        "object": object_name, "object_pose": object_pose, "top": request.top, "hand": world.hand.name,
        "joint_angles": [float(v) for v in g.joint_angles], "joint_names": list(world.hand.core.joint_names),
        "contacts": [c.to_dict() for c in g.contacts], "epsilon": g.epsilon, "volume": g.volume,
        "lifted": g.lifted, "lift_displacement": g.lift_displacement, "collision_at_start": g.collision_at_start,
        "hand_pose": _list(g.hand_pose), "mode": request.mode, "input_frame": frame,
        "approach": _approach_dict(request.approach), "pose": request.pose,
        "stopped_by_table": g.stopped_by_table, "hand_pose_object": _list(g.hand_pose_object),
        "mass": mass_dict(world.object), "units": units,
        "grasp": hand_grasp_record(world.hand, g.hand_pose, g.joint_angles, spread),
    }
