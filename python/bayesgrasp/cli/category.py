"""``bayesgrasp category``: grasp a new object of a known category for a task (thesis §4.2, Eq. 4.1):
one view of the object (a camera's ``--cloud`` or ``--depth``, or a simulated view of
``--scene-object``), registration against the category's training models (the object itself left
out when it is one of them), the grasp of Eq. 4.1, executed on ``--scene-object`` (approach along
the planned pose, close, lift test) and checked against the task's rule; with camera data and no
``--scene-object`` the planned grasp is the output."""
from __future__ import annotations

import json

import numpy as np

from ..planners.category import METHOD_HELP, METHODS
from ..planners.registry import methods_help
from . import camera_input
from .args import (CliError, Renamed, add_category_options, add_context_options, add_robot_options, context, floats,
                   output_file, output_format, robot_arm, task_grasps_arg)


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
    c.add_argument("--method", default="laplace", choices=list(METHODS), help=methods_help(METHODS, METHOD_HELP))
    c.add_argument("--complete", action="store_true", help="use the object's whole surface as the cloud")
    add_category_options(c, "the cloud, the registered models and the hand")
    add_context_options(c)
    camera_input.add(c)
    add_robot_options(c)
    c.set_defaults(run=run)


def run(args) -> int:
    from ..io.results import category_document
    from ..loop.category import plan_and_execute, see
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
    ctx.say(f"category: registering the {args.category} models to the view")
    ep = see(args.scene_object, pose, args.category, exclude=exclude, seed=ctx.seed, complete=args.complete,
             observation=None if view is None else camera_input.observation(view))
    if not any(r.success for r in ep.registrations):
        raise CliError("no training model registered to the cloud (is the object in view, is it of this category?)")
    grasps = task_grasps_arg(args)
    arm = robot_arm(args, ctx.hand_model)
    from ..loop.reach import table_reach, with_arm_on

    ctx.say(f"category: planning the {args.task} grasp ({args.method}) and lift-testing it")
    r = plan_and_execute(ep, args.category, args.task, args.method, ctx, seed=ctx.seed, grasps=grasps,
                         reach=None if arm is None else table_reach(arm))
    grasp = r.grasp(ctx.hand_model)
    if arm is not None and grasp is not None:
        grasp = with_arm_on(arm, grasp, args.scene_object, pose, ctx.hand)   # with the stand-in, if any
    scene = (args.cloud or args.depth) if view is not None else "simulated view"
    doc = category_document(r, grasp, ep, args.category, args.units, scene)
    fmt = output_format(args)
    if fmt == "ros":
        from ..io.grasp_schema import to_ros

        print(json.dumps(None if grasp is None else
                         to_ros(grasp, grasp_id=f"{args.category}-{args.task}", quality=r.plan.objective)))
    elif fmt == "json":
        print(json.dumps(doc))
    else:
        _print(r, ep, args.category, scene)
        if grasp is not None and "arm" in grasp:
            a = grasp["arm"]
            print(f"  arm: {'reaches the grasp' if a['reachable'] else 'cannot reach the grasp (' + a['reason'] + ')'}")
    if png and r.outcome.executed:
        _png(ep, r, ctx, png)
        if fmt == "text":
            print(f"saved {png}")
    from .view import show_result

    show_result(args, doc)
    return 0


def _print_part_check(pc: dict) -> None:
    """The part-aware plan's check (the planner's ``extra``): P(rule | A), P(rule, held | A)."""
    print(f"  part check: the rule holds on models of weight {pc['p_rule']:.2f} (and the grasp holds: "
          f"{pc['p_success']:.2f}); {pc['passing_rule']} of {pc['candidates']} candidates obeyed the rule on "
          "some model")
    if "warps" in pc:
        print("  warped onto the view: " + ", ".join(f"{n} weight {w['weight']:.2f} ({1000 * w['residual']:.1f} mm)"
                                                   for n, w in pc["warps"].items()))
    if pc.get("lift_checked"):
        print(f"  lift test on the warped shapes decided among the {pc['lift_checked']} best: the chosen grasp "
              f"lifts on models of weight {pc['p_lifted']:.2f}")


def _print(r, ep, category: str, scene: str) -> None:
    """The result in lines: each model's weight and contribution, the part check, the outcome."""
    plan, o = r.plan, r.outcome
    print(f"{ep.obj or scene} ({category}, task {r.task}), method {r.method}")
    for m in ep.models:
        print(f"  {m:<10} weight {plan.weights[m]:.3f}  contribution {plan.contributions[m]:.4f}")
    if o.reason:
        print(f"  no grasp: {o.reason}")
        return
    if plan.extra:
        _print_part_check(plan.extra)
    if not o.executed:
        x, y, z = plan.pose[:3, 3]
        print(f"  planned grasp at ({100 * x:.1f}, {100 * y:.1f}, {100 * z:.1f}) cm in the table frame, spread "
              f"{o.spread:.2f} rad (not executed: no --scene-object)")
        return
    print(f"  epsilon {o.epsilon:.4f}, {'lifted' if o.lifted else 'dropped'}, contacts on "
          f"{', '.join(o.contact_parts) or 'nothing'}: {'task-compatible' if o.task_ok else 'wrong part'}"
          f" -> {'SUCCESS' if o.success else 'failure (' + str(o.failure) + ')'}")


def _png(ep, r, ctx, png) -> None:
    from ..objects import load_object
    from ..viz import plot_category_grasp

    o = r.outcome
    plot_category_grasp(ep.observation.cloud, [load_object(m) for m in ep.models],
                        [g.transform for g in ep.registrations], [r.plan.weights[m] for m in ep.models],
                        ctx.hand_model, np.asarray(o.joint_angles), np.asarray(o.hand_pose), png,
                        title=f"{ep.obj}, {r.task}, {r.method}: {'success' if o.success else o.failure}")
