"""``bayesgrasp episode``: the closed loop with your robot doing the executing (thesis Figs. 3.1,
3.4). ``new`` writes the belief and settings to a directory and prints the first grasp; the robot
executes it; ``observe`` takes its joint reading and the lift verdict, updates the belief and prints
the next grasp; ``show`` prints the history and the belief. Three kinds: pose uncertainty (Pub.
II-IV, --method stability|explore: top grasps, the hand comes down along -z at (x, y, yaw) until it
touches, then closes; the printed ``grasp`` is where it is expected to close, simulated at the
belief's mean); a category task (Pub. V, --category C --task T: one task grasp from one view, the
robot approaches along the printed pose); vision then touch (Pub. VI, --category C --task T
--method fusion: top grasps, each reading updates the models' weights and poses)."""
from __future__ import annotations

import json

import numpy as np

from ..loop.episode import EpisodeSettings
from ..loop.outside_loop import METHODS as POSE_METHODS          # the episodes' own lists
from ..loop.outside_loop_category import CATEGORY_METHODS as _PLANNED_ONCE, EPISODE_CATEGORY_METHODS as CATEGORY_METHODS
from ..planners import category as _category, fusion as _fusion, registry as _registry
from . import camera_input
from .args import (CliError, add_context_options, add_format_options, add_robot_options, bounded_int, context, floats,
                   output_format, robot_arm, task_grasps_arg)

#: --method's help, each method's line as its planner family declares it.
METHOD_HELP = (f"pose (default {EpisodeSettings.method}): {_registry.methods_help(POSE_METHODS)}; with --category "
               f"(default laplace): {_registry.methods_help(_PLANNED_ONCE, _category.METHOD_HELP)}; "
               f"{_registry.methods_help((_fusion.METHOD,), _fusion.METHOD_HELP)}")


def add(sub) -> None:
    e = sub.add_parser("episode", help="the planning loop driven by your robot: new, observe, show",
                       description=__doc__)
    cmds = e.add_subparsers(dest="episode_command", metavar="STEP", required=True)

    n = cmds.add_parser("new", help="start an episode and print the first grasp",
                        description="Writes the belief and settings to --dir and prints the first grasp.")
    n.add_argument("--object", default=None,
                   help="built-in object name (see `bayesgrasp objects`) or mesh file: the object (pose episodes), or "
                        "with --category and no camera data the object whose simulated view is taken")
    n.add_argument("--estimate", default=None, metavar="X,Y,YAW",
                   help="the object's estimated pose on the table (m, m, rad); or give --cloud / --depth")
    n.add_argument("--method", default=None, choices=list(POSE_METHODS + CATEGORY_METHODS), help=METHOD_HELP)
    n.add_argument("--category", default=None, help="a category task or vision-then-touch episode: mug, bottle or knife")
    n.add_argument("--task", default=None, help="the task, with --category (mug: top, side, handle; ...)")
    n.add_argument("--object-pose", default="0,0,0", metavar="X,Y,YAW",
                   help="with --category and no camera data: the pose of --object for its simulated view")
    n.add_argument("--exclude", nargs="*", default=None, metavar="NAME",
                   help="with --category: training models to leave out (default: --object, if it is one)")
    n.add_argument("--task-grasps", default=None, metavar="FILE",
                   help="with --category: demonstrated grasps to use instead of generating them (as for `category`)")
    n.add_argument("--attempts", type=bounded_int(1, 1000), default=EpisodeSettings.attempts, help="grasps at most")
    n.add_argument("--dir", required=True, help="the episode's directory (created; must not hold an episode)")
    add_format_options(n)
    add_context_options(n)
    add_robot_options(n)
    camera_input.add(n)
    n.set_defaults(run=new)

    o = cmds.add_parser("observe", help="feed back the robot's reading and print the next grasp",
                        description="Updates the belief with the fingers' joint angles and the lift verdict of the "
                                    "grasp the robot just executed, and prints the next grasp.")
    o.add_argument("dir", help="the episode's directory")
    o.add_argument("--joints", required=True, metavar="A,B,...",
                   help="every hand joint's value after closing, in the order the grasp lists them: a URDF "
                        "hand's moving joints in the URDF's names and units (the grasp's urdf.joint_names), "
                        "else the hand file's joint_names (rad)")
    o.add_argument("--lifted", required=True, help="yes or no: did the object come up in the lift?")
    o.add_argument("--cache", default=None, help="model cache directory (as at `episode new`)")
    add_format_options(o)
    o.set_defaults(run=observe)

    s = cmds.add_parser("show", help="print the history and the belief", description="Prints the episode's "
                                                                                      "history and its belief.")
    s.add_argument("dir", help="the episode's directory")
    s.add_argument("--cache", default=None, help="model cache directory (as at `episode new`)")
    s.add_argument("--json", action="store_true", help="print one JSON object")
    s.set_defaults(run=show)


def new(args) -> int:
    from ..loop.outside_loop import PoseEpisode
    from .plan import _vision_start, started

    fmt = output_format(args)
    if args.category or args.task:
        return _new_category(args, fmt)
    for opt in ("exclude", "task_grasps"):
        if getattr(args, opt) is not None:
            raise CliError(f"--{opt.replace('_', '-')}: only with --category")
    if args.object is None:
        raise CliError("--object: needed (the object whose pose is uncertain)")
    method = args.method or EpisodeSettings.method
    if method not in POSE_METHODS:
        raise CliError(f"--method: {method} needs --category and --task")
    est = floats(args.estimate, 3, "--estimate") if args.estimate else None
    obj = args.object
    if args.units or camera_input.given(args):
        from ..objects import load_object

        obj = load_object(args.object, units=args.units)
    ctx = context(args, reads=("success", "models", "planner"))   # the robot reads the joints and the lift
    arm = robot_arm(args, ctx.hand_model)
    start, _ = _vision_start(args, obj, est, fmt != "text", ctx.seed)
    settings = started(ctx.planner_settings(), start)     # --set planner.FIELD=VALUE
    if start is not None:
        est = start.estimate.tolist()
    if est is None:
        raise CliError("--estimate: needed (or --cloud / --depth to register the object to)")
    ep = PoseEpisode.new(args.dir, obj, est, ctx, method=method, attempts=args.attempts, seed=ctx.seed,
                         planner=settings, units=args.units, arm=arm)
    _print_next(ep, fmt)
    return 0


def _new_category(args, fmt: str) -> int:
    """A category task (Pub. V) or vision-then-touch (Pub. VI) episode from one view."""
    from ..loop.category import observe
    from ..loop.outside_loop_category import CategoryTaskEpisode, FusionEpisode
    from ..objects import load_object

    if not (args.category and args.task):
        raise CliError("--category, --task: give both")
    if args.estimate:
        raise CliError("--estimate: not with --category (the view's registrations place the models)")
    method = args.method or "laplace"
    if method in POSE_METHODS:
        raise CliError(f"--method: {method} is a pose-uncertainty method; with --category one of "
                       f"{', '.join(CATEGORY_METHODS)}")
    view = camera_input.observe(args)
    if view is None and not args.object:
        raise CliError("--cloud, --depth or --object: the view to plan from")
    ctx = context(args, reads=("success", "models") if method == _fusion.METHOD else ())
    arm = robot_arm(args, ctx.hand_model)
    if view is not None:
        obs = camera_input.observation(view)
    else:
        obj = load_object(args.object, units=args.units) if args.units else args.object   # in its unit
        obs = observe(obj, floats(args.object_pose, 3, "--object-pose"), seed=ctx.seed)
    exclude = args.exclude if args.exclude is not None else [m for m in [args.object] if m]
    common = dict(exclude=exclude, seed=ctx.seed, grasps=task_grasps_arg(args), arm=arm)
    if method == _fusion.METHOD:
        ep = FusionEpisode.new(args.dir, obs, args.category, args.task, ctx, attempts=args.attempts, **common)
    else:
        ep = CategoryTaskEpisode.new(args.dir, obs, args.category, args.task, ctx, method=method, **common)
    _print_next(ep, fmt)
    return 0


def _open(args):
    from ..loop.context import stderr_progress
    from ..loop.outside_loop_category import open_episode

    return open_episode(args.dir, cache_dir=args.cache, progress=stderr_progress)


def observe(args) -> int:
    fmt = output_format(args)
    ep = _open(args)
    ep.observe(_reading(ep.hand, args.joints), args.lifted)
    _print_next(ep, fmt)
    return 0


def _reading(hand, text: str):
    """--joints as our joint vector: a URDF hand's reading is in the URDF's terms."""
    if hand.urdf_joint_map is None:
        return floats(text, len(hand.joint_names), "--joints")
    try:
        return hand.joints_from_urdf(floats(text, len(hand.urdf_joint_map), "--joints"))
    except ValueError as e:
        raise CliError(f"--joints: {e}") from None


def _quality(nxt: dict) -> float:
    """The planner's score of a grasp: predicted P(success) (pose) or the objective (category kinds)."""
    return float(nxt["predicted_stability"] if "predicted_stability" in nxt else nxt["objective"])


def _score(nxt: dict) -> str:
    if "predicted_stability" in nxt:
        return f"predicted P(success) {nxt['predicted_stability']:.2f}"
    return f"objective {nxt['objective']:.3g}"


def _print_next(ep, fmt: str) -> None:
    nxt = ep.next
    doc = {"episode": str(ep.directory), "kind": ep.kind, "status": ep.state["status"],
           "attempts_made": len(ep.state["steps"]), "next": nxt}
    if fmt == "ros":
        from ..io.grasp_schema import to_ros

        doc = {"episode": doc["episode"], "status": doc["status"],
               "next": None if nxt is None else to_ros(nxt["grasp"], grasp_id=f"attempt-{nxt['attempt']}",
                                                       quality=_quality(nxt))}
    if fmt != "text":
        print(json.dumps(doc))
        return
    if nxt is None:
        print(f"episode {ep.directory}: {ep.state['status']} after {len(ep.state['steps'])} grasp(s)")
        return
    g = nxt["grasp"]
    if "top_grasp" in nxt:
        x, y, yaw = nxt["top_grasp"]
        print(f"attempt {nxt['attempt']} ({nxt['kind']}): top grasp at ({x:.4f} m, {y:.4f} m, yaw {yaw:.4f} rad), "
              f"expected to close at z {g['position'][2]:.3f} m; {_score(nxt)}")
    else:
        p, a = g["position"], g["approach"]
        print(f"attempt {nxt['attempt']} ({nxt['kind']}): palm at ({p[0]:.4f}, {p[1]:.4f}, {p[2]:.4f}) m, approach "
              f"({a[0]:.3f}, {a[1]:.3f}, {a[2]:.3f}), spread {g['spread']:.3f} rad; {_score(nxt)}")
    print("  joints " + ",".join(g["urdf"]["joint_names"] if "urdf" in g else g["joint_names"]))
    if "arm" in g:          # with --robot: the arm's joints at the grasp, or why it cannot reach it
        arm = g["arm"]
        print("  arm joints " + ",".join(f"{v:.4f}" for v in arm["joint_positions"]) if arm["reachable"] else
              f"  arm: cannot reach this grasp ({arm['reason']}); no reachable grasp was found")
    print("  then: bayesgrasp episode observe " + str(ep.directory) + " --joints A,B,... --lifted yes|no")


def show(args) -> int:
    ep = _open(args)
    belief = ep.belief()
    st = ep.state
    doc = {"episode": str(ep.directory), "kind": ep.kind, "method": st["method"], "status": st["status"],
           "steps": st["steps"], "next": ep.next, "belief": belief}
    doc.update({k: st[k] for k in ("object", "estimate", "category", "task") if k in st})
    if args.json:
        print(json.dumps(doc))
        return 0
    what = st.get("object") or f"{st['category']} / {st['task']}"
    print(f"episode {ep.directory}: {what}, {st['method']}, {st['status']}")
    for s in st["steps"]:
        if "top_grasp" in s:
            x, y, yaw = s["top_grasp"]
            where = f"({x:.4f}, {y:.4f}, {np.degrees(yaw):.1f} deg)"
        else:
            where = "palm at ({:.4f}, {:.4f}, {:.4f}) m".format(*(row[3] for row in s["planned_pose"][:3]))
        print(f"  attempt {s['attempt']}: {where} -> {'lifted' if s['lifted'] else 'not lifted'}")
    if "mean" in belief:
        m, sd = belief["mean"], belief["std"]
        print(f"  belief: mean ({m[0]:.4f} m, {m[1]:.4f} m, {np.degrees(m[2]):.1f} deg), std ({100 * sd[0]:.1f} cm, "
              f"{100 * sd[1]:.1f} cm, {np.degrees(sd[2]):.1f} deg), ESS {belief['ess']:.0f}")
    else:
        print("  weights: " + ", ".join(f"{m} {w:.3f}" for m, w in (belief["weights"] or {}).items()))
    return 0
