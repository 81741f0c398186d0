"""``bayesgrasp fuse``: vision, then touch (thesis §4.3, Pub. VI): one view gives every training
model a weight and a pose; each executed top grasp's joint angles update them (Eqs. 4.4-4.5); the
next grasp maximises stability x task (Eq. 4.6); until a grasp is lifted or the rounds run out.
The view is a camera's (``--cloud``, ``--depth``) or a simulated one of ``--scene-object``; the
grasps are executed on ``--scene-object`` at ``--object-pose``, the simulated stand-in for the robot."""
from __future__ import annotations

import json

import numpy as np

from . import camera_input
from ..planners.fusion import TASK_TERMS
from .args import (CliError, Renamed, add_category_options, add_context_options, add_robot_options, bounded_int, context,
                   floats, output_file, output_format, robot_arm, task_grasps_arg)


def add(sub) -> None:
    f = sub.add_parser("fuse", help="vision then touch: update model poses and weights from the fingers, re-plan",
                       description=__doc__)
    f.add_argument("--category", default="mug", help="the category (its training models are its members)")
    f.add_argument("--task", default="top", help="the task whose demonstrated top grasps define P(T)")
    f.add_argument("--scene-object", required=True,
                   help="the new object (built-in name or mesh file), seen (without camera data) and grasped")
    f.add_argument("--object-pose", "--pose", dest="object_pose", action=Renamed, old=["--pose"], default="0,0,0",
                   metavar="X,Y,YAW", help="its pose on the table (--pose: the old spelling, deprecated)")
    f.add_argument("--rounds", type=bounded_int(0, 1000), default=3, help="tactile rounds after the first grasp")
    f.add_argument("--start", choices=["vision", "random"], default="vision",
                   help="G(0): planned from the view (Eq. 4.6's task term) or at random above the object")
    f.add_argument("--belief", choices=["map", "particles"], default="map",
                   help="per-model MAP poses (the thesis) or a joint particle belief over (model, pose)")
    f.add_argument("--task-term", choices=list(TASK_TERMS), default="laplace",
                   help="P(T | G): the thesis's Laplace densities at the placed task grasps, part-aware (also "
                        "the share of models on which the grasp obeys the task's rule and holds) or warped (that "
                        "check on the models warped onto the view)")
    f.add_argument("--avoid-failed", action="store_true",
                   help="lower Eq. 4.6 near a grasp that did not hold until the belief's object moves away")
    f.add_argument("--recursive", action="store_true", help="Eq. 4.5 recursive: w_i ~ w_i(t-1) L_i")
    f.add_argument("--noise", type=float, default=0.0, help="joint-angle noise sd (rad) in the likelihood")
    add_category_options(f, "the weights and the models' poses per round")
    add_context_options(f)
    camera_input.add(f)
    add_robot_options(f)
    f.set_defaults(run=run)


def run(args) -> int:
    from ..io.results import fuse_document, fuse_rounds, round_grasp
    from ..loop.fusion_trial import FusionTrial
    from ..planners.fusion import FusionSettings

    pose = floats(args.object_pose, 3, "--object-pose")
    if args.rounds < 0:
        raise CliError(f"--rounds: must be >= 0, got {args.rounds}")
    if not (np.isfinite(args.noise) and args.noise >= 0):
        raise CliError(f"--noise: must be >= 0, got {args.noise}")
    png = output_file(args.png, "--png")
    view = camera_input.observe(args)
    ctx = context(args, reads=("success", "models"))     # the training models' P(S) and GPs
    settings = FusionSettings(belief=args.belief, recursive=args.recursive, measurement_noise=args.noise,
                              task_term=args.task_term, avoid_failed=args.avoid_failed)
    grasps = task_grasps_arg(args)
    trial = FusionTrial(args.scene_object, pose, ctx, task=args.task, settings=settings,
                        exclude=args.exclude if args.exclude is not None else [args.scene_object], seed=ctx.seed,
                        category=args.category, grasps=grasps,
                        observation=None if view is None else camera_input.observation(view))
    fmt = output_format(args)
    arm = robot_arm(args, ctx.hand_model)
    if arm is not None:
        from ..loop.reach import top_reach

        trial.reach = top_reach(arm, ctx.hand_model, trial.episode.observation.cloud)
    r = trial.run(args.start, rounds=args.rounds, on_round=None if fmt != "text" else _print_round(trial.names),
                  stop_at_lift=True)
    grasps = [round_grasp(x, ctx.hand_model, trial.spread) for x in r.rounds]
    if arm is not None:
        _arm_checks(arm, grasps, trial)
    rounds = fuse_rounds(r, grasps)
    scene = (args.cloud or args.depth) if view is not None else "simulated view"
    doc = fuse_document(r, rounds, trial.episode, settings, category=args.category, task=args.task, units=args.units,
                        scene=scene)
    if fmt == "ros":
        from ..io.grasp_schema import to_ros

        print(json.dumps({"rounds": [to_ros(g, grasp_id=f"round-{x.number}") for x, g in zip(r.rounds, grasps)]}))
    elif fmt == "json":
        print(json.dumps(doc))
    else:
        print(f"{'success' if r.success else 'no grasp lifted'} after {len(r.rounds)} grasp(s)")
        if arm is not None:
            k = sum(g["arm"]["reachable"] for g in grasps)
            print(f"arm: {k} of {len(grasps)} executed grasp(s) reachable")
    if png:
        from ..viz import plot_fusion_rounds

        plot_fusion_rounds(trial.names, rounds, pose, png, title=f"{args.scene_object}: vision then touch")
        if fmt == "text":
            print(f"saved {png}")
    from .view import show_result

    show_result(args, doc)
    return 0


def _arm_checks(arm, grasps: list, trial) -> None:
    """Each executed grasp (table frame) checked with the arm against the table and the stand-in's
    mesh at its pose: the grasp schema's ``arm``, added to each grasp record."""
    from ..arm import ReachOptions, arm_record, check_reach

    if not grasps:
        return
    mesh = None if trial.world is None else (trial.world.vertices, trial.world.faces)
    P = np.stack([np.asarray(g["pose"], dtype=float) for g in grasps])
    r = check_reach(arm, P, mesh, ReachOptions(pregrasp_distance=grasps[0]["pregrasp"]["distance"]))
    for i, g in enumerate(grasps):
        g["arm"] = arm_record(arm, r, i)


def _print_round(names):
    """A line per :class:`~bayesgrasp.loop.fusion_result.FusionRound` as it is done."""
    def show(rec):
        e = rec.execution
        w = ", ".join(f"{n} {v:.2f}" for n, v in zip(names, rec.weights))
        x, y, yaw = (float(v) for v in e.action)
        print(f"  round {rec.number}: grasp ({100 * x:.1f} cm, {100 * y:.1f} cm, {np.degrees(yaw):.0f} deg) "
              f"-> epsilon {e.epsilon:.3f}, {'LIFTED' if e.lifted else 'dropped'}; weights {w}", flush=True)
    return show
