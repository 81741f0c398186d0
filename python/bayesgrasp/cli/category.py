"""``bayesgrasp category``: grasp a new object of a known category for a task (thesis §4.2, Eq. 4.1):
one view of the object (a camera's ``--cloud`` or ``--depth``, or a simulated view of
``--scene-object``), registration against the category's training models (the object itself left
out when it is one of them), the grasp of Eq. 4.1, executed on ``--scene-object`` (approach along
the planned pose, close, lift test) and checked against the task's rule; with camera data and no
``--scene-object`` the planned grasp is the output."""
from __future__ import annotations

import json

import numpy as np

from ..planners.category import METHODS
from . import camera_input
from .args import (CliError, Renamed, add_category_options, add_context_options, context, floats, output_file, output_format,
                   task_grasps_arg)


def add(sub) -> None:
    c = sub.add_parser("category", help="plan and execute a task grasp on a new member of a known category",
                       description=__doc__)
    c.add_argument("--category", required=True, help="mug, bottle or knife (knives train on the hammers)")
    c.add_argument("--task", required=True, help="the task (mug: top, side, handle; bottle: side; knife: handle)")
    c.add_argument("--scene-object", default=None,
                   help="the new object (built-in name or mesh file): the simulated view, or with camera data the "
                        "simulated stand-in the grasp is executed on (at --object-pose, in the table frame)")
    c.add_argument("--object-pose", "--pose", dest="object_pose", action=Renamed, old=["--pose"], default="0,0,0",
                   metavar="X,Y,YAW", help="its pose on the table (--pose: the old spelling, deprecated)")
    c.add_argument("--method", default="laplace", choices=list(METHODS),
                   help="Eq. 4.1's density, the best-single-grasp baseline, or part-aware (Eq. 4.1's candidates "
                        "closed on every registered model and re-ranked by where the fingers land)")
    c.add_argument("--complete", action="store_true", help="use the object's whole surface as the cloud")
    add_category_options(c, "the cloud, the registered models and the hand")
    add_context_options(c)
    camera_input.add(c)
    c.set_defaults(run=run)


def run(args) -> int:
    from ..loop.category import plan_and_execute, see
    from ..io.view_fields import cloud_json
    from ..models.tasks import task_rule

    pose = floats(args.object_pose, 3, "--object-pose")
    png = output_file(args.png, "--png")
    task_rule(args.category, args.task)   # a clear error for an unknown category or task
    view = camera_input.observe(args)
    if view is None and not args.scene_object:
        raise CliError("--scene-object: needed without --cloud or --depth")
    if view is not None and args.complete:
        raise CliError("--complete: not with camera data (it replaces the view by the object's whole surface)")
    exclude = args.exclude if args.exclude is not None else [m for m in [args.scene_object] if m]
    ctx = context(args, reads=())      # Eq. 4.1 on the registrations; every grasp is lift-tested
    ep = see(args.scene_object, pose, args.category, exclude=exclude, seed=ctx.seed, complete=args.complete,
             observation=None if view is None else camera_input.observation(view))
    if not any(r.success for r in ep.registrations):
        raise CliError("no training model registered to the cloud (is the object in view, is it of this category?)")
    grasps = task_grasps_arg(args)
    out = plan_and_execute(ep, args.category, args.task, args.method, ctx, seed=ctx.seed, grasps=grasps)
    doc = {"grasp": _grasp_record(out, ctx), "planned_pose": out["pose"], "method": args.method,
           "category": args.category, "task": args.task, "scene_object": args.scene_object, "units": args.units,
           "object_pose": pose if args.scene_object else None, "executed": out["executed"],
           "scene": (args.cloud or args.depth) if view is not None else "simulated view",
           "models": [{"model": m, "weight": out["weights"][m], "contribution": out["contributions"][m],
                       "success": bool(r.success), "transform": np.asarray(r.transform).tolist()}
                      for m, r in zip(ep.models, ep.registrations)],
           "cloud": cloud_json(ep.observation.cloud),
           "epsilon": out["epsilon"], "lifted": out["lifted"], "task_ok": out["task_ok"], "success": out["success"],
           "failure": out["failure"], "reason": out["reason"] or None, "contact_parts": out["contact_parts"]}
    if "part_check" in out:      # part-aware: P(rule | A), P(rule, held | A) and each model's contact parts
        doc["part_check"] = out["part_check"]
    fmt = output_format(args)
    if fmt == "ros":
        from ..io.grasp_schema import to_ros

        print(json.dumps(None if doc["grasp"] is None else
                         to_ros(doc["grasp"], grasp_id=f"{args.category}-{args.task}", quality=out["objective"])))
    elif fmt == "json":
        print(json.dumps(doc))
    else:
        _print(doc)
    if png and out["executed"]:
        _png(ep, out, ctx, png, doc)
        if fmt == "text":
            print(f"saved {png}")
    from .view import show_result

    show_result(args, doc)
    return 0


def _grasp_record(out: dict, ctx):
    """The plan in the grasp schema (world = the table frame): executed, where the hand closed and
    its closed fingers; planned only, the planned pose with the open preshape (None: no grasp)."""
    from ..io.grasp_schema import hand_grasp_record

    if out["pose"] is None:
        return None
    hand = ctx.hand_model
    if out["executed"]:
        return hand_grasp_record(hand, out["hand_pose"], out["joint_angles"], out["spread"])
    return hand_grasp_record(hand, out["pose"], hand.open_joints(out["spread"]), out["spread"])


def _print(doc: dict) -> None:
    print(f"{doc['scene_object'] or doc['scene']} ({doc['category']}, task {doc['task']}), method {doc['method']}")
    for m in doc["models"]:
        print(f"  {m['model']:<10} weight {m['weight']:.3f}  contribution {m['contribution']:.4f}")
    if doc["reason"]:
        print(f"  no grasp: {doc['reason']}")
        return
    pc = doc.get("part_check")
    if pc:
        print(f"  part check: the rule holds on models of weight {pc['p_rule']:.2f} (and the grasp holds: "
              f"{pc['p_success']:.2f}); {pc['passing_rule']} of {pc['candidates']} candidates obeyed the rule on "
              "some model")
        if "warps" in pc:
            print("  warped onto the view: " + ", ".join(f"{n} weight {w['weight']:.2f} ({1000 * w['residual']:.1f} mm)"
                                                       for n, w in pc["warps"].items()))
        if pc.get("lift_checked"):
            print(f"  lift test on the warped shapes decided among the {pc['lift_checked']} best: the chosen grasp "
                  f"lifts on models of weight {pc['p_lifted']:.2f}")
    if not doc["executed"]:
        x, y, z = (doc["grasp"]["pose"][i][3] for i in range(3))
        print(f"  planned grasp at ({100 * x:.1f}, {100 * y:.1f}, {100 * z:.1f}) cm in the table frame, spread "
              f"{doc['grasp']['spread']:.2f} rad (not executed: no --scene-object)")
        return
    print(f"  epsilon {doc['epsilon']:.4f}, {'lifted' if doc['lifted'] else 'dropped'}, contacts on "
          f"{', '.join(doc['contact_parts']) or 'nothing'}: {'task-compatible' if doc['task_ok'] else 'wrong part'}"
          f" -> {'SUCCESS' if doc['success'] else 'failure (' + str(doc['failure']) + ')'}")


def _png(ep, out: dict, ctx, png, doc: dict) -> None:
    from ..objects import load_object
    from ..viz import plot_category_grasp

    plot_category_grasp(ep.observation.cloud, [load_object(m) for m in ep.models],
                        [r.transform for r in ep.registrations], [out["weights"][m] for m in ep.models],
                        ctx.hand_model, np.asarray(out["joint_angles"]), np.asarray(out["hand_pose"]), png,
                        title=f"{doc['scene_object']}, {doc['task']}, {doc['method']}: "
                              f"{'success' if doc['success'] else doc['failure']}")
