"""``bayesgrasp episode``: the closed loop with your robot doing the executing (thesis Figs. 3.1,
3.4). ``new`` writes the belief and settings to a directory and prints the first grasp; the robot
executes it; ``observe`` takes its joint reading and the lift verdict, updates the belief and prints
the next grasp; ``show`` prints the history and the belief. The grasps are top grasps: the hand
comes down along -z at (x, y, yaw) until it touches, then closes (the printed ``grasp`` is where
it is expected to close, simulated at the belief's mean)."""
from __future__ import annotations

import json

import numpy as np

from . import camera_input
from .args import CliError, add_context_options, add_format_options, bounded_int, context, floats, output_format


def add(sub) -> None:
    e = sub.add_parser("episode", help="the planning loop driven by your robot: new, observe, show",
                       description=__doc__)
    cmds = e.add_subparsers(dest="episode_command", metavar="STEP", required=True)

    n = cmds.add_parser("new", help="start an episode and print the first grasp",
                        description="Writes the belief and settings to --dir and prints the first grasp.")
    n.add_argument("--object", required=True, help="built-in object name (see `bayesgrasp objects`) or mesh file")
    n.add_argument("--estimate", default=None, metavar="X,Y,YAW",
                   help="the object's estimated pose on the table (m, m, rad); or give --cloud / --depth")
    n.add_argument("--method", default="explore", choices=["stability", "explore"],
                   help="stability: the most stable grasp (Eq. 3.1); explore: also grasps that inform (Eq. 3.2)")
    n.add_argument("--attempts", type=bounded_int(1, 1000), default=4, help="grasps at most")
    n.add_argument("--dir", required=True, help="the episode's directory (created; must not hold an episode)")
    add_format_options(n)
    add_context_options(n)
    camera_input.add(n)
    n.set_defaults(run=new)

    o = cmds.add_parser("observe", help="feed back the robot's reading and print the next grasp",
                        description="Updates the belief with the fingers' joint angles and the lift verdict of the "
                                    "grasp the robot just executed, and prints the next grasp.")
    o.add_argument("dir", help="the episode's directory")
    o.add_argument("--joints", required=True, metavar="A,B,...",
                   help="every hand joint's angle after closing (rad), in the order of the grasp's joint_names")
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
    from ..experiments.outside_loop import PoseEpisode
    from ..planners import PlannerSettings
    from .plan import _vision_start

    fmt = output_format(args)
    est = floats(args.estimate, 3, "--estimate") if args.estimate else None
    obj = args.object
    if args.units or camera_input.given(args):
        from ..objects import load_object

        obj = load_object(args.object, units=args.units)
    start = _vision_start(args, obj, est, quiet=fmt != "text")
    settings = PlannerSettings()
    if start is not None:
        est = start.estimate.tolist()
        settings = settings.with_(half_width=tuple(start.half_width.tolist()))
    if est is None:
        raise CliError("--estimate: needed (or --cloud / --depth to register the object to)")
    ep = PoseEpisode.new(args.dir, obj, est, context(args), method=args.method, attempts=args.attempts,
                         seed=args.seed, planner=settings)
    _print_next(ep, fmt)
    return 0


def _open(args):
    from ..experiments.context import stderr_progress
    from ..experiments.outside_loop import PoseEpisode

    return PoseEpisode.open(args.dir, cache_dir=args.cache, progress=stderr_progress)


def observe(args) -> int:
    fmt = output_format(args)
    ep = _open(args)
    ep.observe(floats(args.joints, len(ep.hand.joint_names), "--joints"), args.lifted)
    _print_next(ep, fmt)
    return 0


def _print_next(ep, fmt: str) -> None:
    nxt = ep.next
    doc = {"episode": str(ep.directory), "status": ep.state["status"], "attempts_made": len(ep.state["steps"]),
           "next": nxt}
    if fmt == "ros":
        from ..io.grasp_schema import to_ros

        doc = {"episode": doc["episode"], "status": doc["status"],
               "next": None if nxt is None else to_ros(nxt["grasp"], grasp_id=f"attempt-{nxt['attempt']}",
                                                       quality=nxt["predicted_stability"])}
    if fmt != "text":
        print(json.dumps(doc))
        return
    if nxt is None:
        print(f"episode {ep.directory}: {ep.state['status']} after {len(ep.state['steps'])} grasp(s)")
        return
    x, y, yaw = nxt["top_grasp"]
    z = nxt["grasp"]["position"][2]
    print(f"attempt {nxt['attempt']} ({nxt['kind']}): top grasp at ({x:.4f} m, {y:.4f} m, yaw {yaw:.4f} rad), "
          f"expected to close at z {z:.3f} m; predicted P(success) {nxt['predicted_stability']:.2f}")
    print("  joints " + ",".join(nxt["grasp"]["joint_names"]))
    print("  then: bayesgrasp episode observe " + str(ep.directory) + " --joints A,B,... --lifted yes|no")


def show(args) -> int:
    ep = _open(args)
    belief = ep.belief()
    doc = {"episode": str(ep.directory), "object": ep.state["object"], "method": ep.state["method"],
           "status": ep.state["status"], "estimate": ep.state["estimate"], "steps": ep.state["steps"],
           "next": ep.next, "belief": belief}
    if args.json:
        print(json.dumps(doc))
        return 0
    print(f"episode {ep.directory}: {ep.state['object']}, {ep.state['method']}, {ep.state['status']}")
    for s in ep.state["steps"]:
        x, y, yaw = s["top_grasp"]
        print(f"  attempt {s['attempt']}: ({x:.4f}, {y:.4f}, {np.degrees(yaw):.1f} deg) -> "
              f"{'lifted' if s['lifted'] else 'not lifted'}")
    m, sd = belief["mean"], belief["std"]
    print(f"  belief: mean ({m[0]:.4f} m, {m[1]:.4f} m, {np.degrees(m[2]):.1f} deg), std ({100 * sd[0]:.1f} cm, "
          f"{100 * sd[1]:.1f} cm, {np.degrees(sd[2]):.1f} deg), ESS {belief['ess']:.0f}")
    return 0
