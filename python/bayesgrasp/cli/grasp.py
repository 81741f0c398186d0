"""``bayesgrasp grasp``: close the hand on an object from a top grasp, an approach direction or a
given hand pose; quality and lift test.

Exactly one of:

* ``--top X,Y,YAW``: palm down at (x, y) with yaw, descending along -z to the first contact;
* ``--approach DX,DY,DZ [--roll R] [--at X,Y,Z]``: the open hand moves along the direction (its
  +z) on the line through the target (default: the centre of the object's bounding box) until the
  first contact with the object or the table, then closes; the roll turns the hand about
  -direction (roll 0: the palm-down top-grasp hand tilted by the smallest rotation taking -z
  onto the direction; ``--approach 0,0,-1 --roll YAW --at X,Y,0`` is ``--top X,Y,YAW``);
* ``--hand-pose FILE.json``: the hand closes at a 4x4 pose (a JSON list of 4 rows,
  ``{"pose": [...]}``, or what ``grasp --json`` wrote: the same grasp again).

Everything is in the object's frame unless ``--frame world``.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, List, Optional, Tuple

import numpy as np

from ..io.results import mass_source
from .args import (CliError, Renamed, add_format_options, add_hand_option, add_object_options, add_robot_options,
                   add_view_option, floats, object_arg, output_file, output_format, robot_arm)

if TYPE_CHECKING:
    from ..lift_trace import LiftTrace


def add(sub) -> None:
    g = sub.add_parser("grasp", help="close the hand from a top grasp, an approach or a hand pose and report the result",
                       description=__doc__)
    g.add_argument("--object", required=True, help="built-in object name (see `bayesgrasp objects`) or mesh file")
    mode = g.add_mutually_exclusive_group(required=True)
    mode.add_argument("--top", metavar="X,Y,YAW", help="top grasp: metres, metres, radians")
    mode.add_argument("--approach", metavar="DX,DY,DZ", help="approach direction (any length but zero)")
    mode.add_argument("--hand-pose", "--pose", dest="hand_pose", action=Renamed, old=["--pose"], metavar="FILE.json",
                      help="4x4 hand pose: a JSON list of 4 rows, {\"pose\": ...} or the output of grasp --json "
                           "(--pose: the old spelling, deprecated)")
    g.add_argument("--roll", type=float, default=None, help="with --approach: roll about -direction (radians; default 0)")
    g.add_argument("--at", metavar="X,Y,Z", default=None,
                   help="with --approach: a point on the palm's line of motion (default: the centre of the object's "
                        "bounding box)")
    g.add_argument("--frame", choices=["object", "world"], default="object",
                   help="frame of --top, --approach/--roll/--at and --hand-pose (default: the object's)")
    g.add_argument("--object-pose", default="0,0,0", metavar="X,Y,YAW", help="object pose on the table")
    g.add_argument("--spread", type=float, default=None, help="finger spread (radians); default: the hand's")
    g.add_argument("--standoff", type=float, default=0.0,
                   help="with --top / --approach: back off this far from the first contact before closing (m)")
    add_hand_option(g)
    add_object_options(g)
    g.add_argument("--keep-origin", action="store_true", help="keep a loaded mesh's own origin")
    g.add_argument("--no-lift", action="store_true", help="skip the physical lift test")
    g.add_argument("--lift-trace", action="store_true",
                   help="record the lift test's trace (the object's path in the hand) in the JSON, for `view`")
    add_robot_options(g)
    add_format_options(g)
    add_view_option(g)
    g.add_argument("--png", default=None, metavar="FILE", help="write a PNG of the hand, the object and the contacts")
    g.set_defaults(run=run)


@dataclass
class Approach:
    """--approach: the direction (the hand's +z), the roll about -direction and a point on the
    palm's line of motion (None: the centre of the object's bounding box, filled in when grasping)."""

    direction: List[float]
    roll: float
    target: Optional[List[float]]


@dataclass
class GraspRequest:
    """What to do, from the options: ``mode`` "top", "approach" or "pose", and its one input."""

    mode: str
    top: Optional[List[float]] = None
    approach: Optional[Approach] = None
    pose: Optional[list] = None


def run(args) -> int:
    from ..io.results import grasp_document
    from ..io.grasp_schema import to_ros

    if args.approach is None and (args.roll is not None or args.at is not None):
        raise CliError(f"{'--roll' if args.roll is not None else '--at'}: only with --approach")
    png = output_file(args.png, "--png")
    pose = floats(args.object_pose, 3, "--object-pose")
    request = _request(args)
    world = _world(args, pose)
    arm = robot_arm(args, world.hand)
    grasp = _grasp(world, args, request)
    spread = world.spread if args.spread is None else args.spread
    out = grasp_document(grasp, request, world, object_name=args.object, object_pose=pose, frame=args.frame,
                         units=args.units, spread=spread)
    if arm is not None:
        out["grasp"]["arm"] = _arm_check(arm, world, grasp, out["grasp"]["pregrasp"]["distance"])
    if args.lift_trace:
        from ..io.view_fields import lift_trace_json

        trace, lifted = _lift_trace(world, args, grasp)
        out["lift_trace"] = lift_trace_json(trace, grasp.hand_pose, lifted)
    fmt = output_format(args)
    if fmt == "ros":
        print(json.dumps(to_ros(out["grasp"], grasp_id=f"{args.object}-{request.mode}", quality=grasp.epsilon)))
    elif fmt == "json":
        print(json.dumps(out))
    else:
        _print(grasp, request, world, args, pose)
        if arm is not None:
            _print_arm(out["grasp"]["arm"])
    if png:
        from ..viz import plot_grasp

        verdict = {True: "lifted", False: "FAILED: not lifted", None: "lift not tested"}[grasp.lifted]
        plot_grasp(world, grasp, png, title=f"{world.hand.name} on {args.object}: {_describe(request)}\n{verdict}, "
                                            f"epsilon {grasp.epsilon:.3f}")
        if fmt == "text":
            print(f"saved {png}")
    from .view import show_result

    show_result(args, out)
    return 0


def _arm_check(arm, world, g, pregrasp_distance: float) -> dict:
    """The grasp's palm pose (world frame) checked with the arm: its pre-grasp as far back as the grasp
    record's, the links against the table and the object (the grasp schema's ``arm``)."""
    from ..arm import ReachOptions, arm_record, check_reach

    r = check_reach(arm, np.asarray(g.hand_pose), (world.vertices, world.faces),
                    ReachOptions(pregrasp_distance=pregrasp_distance))
    return arm_record(arm, r, 0)


def _lift_trace(world, args, g) -> Tuple["LiftTrace", bool]:
    """The lift test run again with its trace recorded (same hand pose, joints and physics, so the
    same verdict as the grasp's): (its trace, lifted)."""
    from ..lift_trace import LiftTrace

    if args.no_lift:
        raise CliError("--lift-trace: not with --no-lift")
    r = world.lift_tester().run(np.asarray(g.hand_pose), np.asarray(g.joint_angles), trace_every=10)
    return LiftTrace.from_core(r.trace), bool(r.lifted) and not g.collision_at_start


def _request(args) -> GraspRequest:
    """What to do, parsed from the options (CliError naming the option)."""
    if args.top is not None:
        return GraspRequest("top", top=floats(args.top, 3, "--top"))
    if args.approach is not None:
        direction = floats(args.approach, 3, "--approach")
        target = None if args.at is None else floats(args.at, 3, "--at")
        return GraspRequest("approach", approach=Approach(direction, float(args.roll or 0.0), target))
    return GraspRequest("pose", pose=_read_pose(args.hand_pose, args.frame))


def _read_pose(path: str, frame: str = "object") -> list:
    """The 4x4 pose of a --hand-pose file: a list of 4 rows, ``{"pose": ...}``, or the JSON that
    ``grasp --json`` writes (its hand pose in --frame: ``hand_pose_object`` or ``hand_pose``)."""
    try:
        doc = json.loads(Path(path).read_text())
    except OSError as e:
        raise CliError(f"--hand-pose: cannot read {path}: {e.strerror or e}") from None
    except ValueError as e:
        raise CliError(f"--hand-pose: {path} is not JSON: {e}") from None
    if isinstance(doc, dict) and "hand_pose_object" in doc and "hand_pose" in doc:   # grasp --json's output
        m = doc["hand_pose_object" if frame == "object" else "hand_pose"]
    else:
        m = doc.get("pose") if isinstance(doc, dict) else doc
    try:
        M = np.asarray(m, dtype=float)
    except (TypeError, ValueError):
        M = np.zeros(0)
    if M.shape != (4, 4):
        raise CliError(f"--hand-pose: {path} must hold a 4x4 matrix (a list of 4 rows of 4 numbers, or {{\"pose\": ...}})")
    return M.tolist()


def _world(args, pose):
    """The world with --object (in --units, weighing --mass) and, unless --no-lift, its lift test
    prepared; a problem with the mesh is a CliError naming ``--object FILE``."""
    from ..world import World

    obj = object_arg(args)
    world = World.single(obj, pose=pose, keep_origin=args.keep_origin, hand=args.hand, standoff=args.standoff)
    if not args.no_lift:
        try:
            world.lift_tester()
        except ValueError as e:
            raise CliError(f"--object {args.object}: {e}") from None
    return world


def _grasp(world, args, request):
    """The world's grasp for the request; the world's ValueErrors (direction of zero length,
    target off the table, a pose that is not rigid, ...) are prefixed with the option."""
    lift = not args.no_lift
    try:
        if request.mode == "top":
            x, y, yaw = request.top
            if args.frame == "object":
                return world.grasp(x, y, yaw, spread=args.spread, lift=lift)
            return world.approach([0.0, 0.0, -1.0], [x, y, 0.0], roll=yaw, spread=args.spread, frame="world", lift=lift)
        if request.mode == "approach":
            a = request.approach
            if a.target is None:
                a.target = _box_centre(world, args.frame)
            return world.approach(a.direction, a.target, roll=a.roll, spread=args.spread, frame=args.frame, lift=lift)
        return world.grasp_pose(request.pose, spread=args.spread, frame=args.frame, lift=lift)
    except ValueError as e:
        option = {"top": "--top", "approach": "--approach", "pose": "--hand-pose"}[request.mode]
        raise CliError(f"{option}: {e}") from None


def _box_centre(world, frame: str) -> list:
    """Centre of the object's bounding box in the frame."""
    V = world.object.vertices if frame == "object" else world.vertices
    return ((V.min(axis=0) + V.max(axis=0)) / 2).tolist()


def _describe(request: GraspRequest) -> str:
    if request.mode == "top":
        return f"top grasp {request.top}"
    if request.mode == "approach":
        a = request.approach
        fmt = lambda v: "(" + ", ".join(f"{x:.3g}" for x in v) + ")"  # noqa: E731
        return f"approach {fmt(a.direction)}, roll {a.roll:.3g}, through {fmt(a.target)}"
    return "closing at the given pose"


def _print_arm(rec: dict) -> None:
    """The arm's verdict: its joints at the grasp (degrees), or why it cannot reach it."""
    name = Path(rec["urdf"]).name
    if not rec["reachable"]:
        print(f"  arm {name}: cannot reach this grasp ({rec['reason']})")
        return
    print(f"  arm {name}: reaches it (grasp, pre-grasp and approach); joints at the grasp: "
          + ", ".join(f"{n}={np.degrees(v):.1f} deg" for n, v in zip(rec["joint_names"], rec["joint_positions"])))


def _print(g, request: GraspRequest, world, args, pose) -> None:
    """The text report of a WorldGrasp; a jaw's travel is printed in mm, an angle in degrees."""
    obj = world.object
    print(f"{world.hand.name} on {args.object} at object pose {pose}, {_describe(request)} ({args.frame} frame)")
    print(f"  object mass {float(obj.mass):.3f} kg, from {mass_source(obj)}")
    if g.collision_at_start:
        print("  the open hand starts in collision: no grasp")
    if g.stopped_by_table:
        print("  the approach was stopped by the table before it touched the object")
    print("  joints: " + ", ".join(f"{n}={1000 * v:.1f} mm" if jaw else f"{n}={np.degrees(v):.1f} deg"
                                   for n, v, jaw in zip(world.hand.core.joint_names, g.joint_angles,
                                                        world.hand.prismatic_joints)))
    print(f"  contacts: {len(g.contacts)}")
    for c in g.contacts:
        where = "table" if c.on_table else (c.part or "object")
        p = ", ".join(f"{v:.4f}" for v in c.point)
        n = ", ".join(f"{v:.3f}" for v in c.normal)
        print(f"    {c.link_name:<18} {where:<6} point ({p})  normal ({n})  penetration {c.penetration:.2e}")
    print(f"  epsilon {g.epsilon:.4f}   volume {g.volume:.3e}")
    if g.lifted is not None:
        print(f"  lift test: {'lifted' if g.lifted else 'dropped'} "
              f"(moved {100 * g.lift_displacement:.1f} cm relative to the palm)")
