"""``bayesgrasp grasp``: close the hand on an object at a top-grasp pose; quality and lift test."""
from __future__ import annotations

import json

import numpy as np

from .args import floats


def add(sub) -> None:
    g = sub.add_parser("grasp", help="close the hand at a top-grasp pose and report the result")
    g.add_argument("--object", required=True, help="built-in object name (see `bayesgrasp objects`) or mesh file")
    g.add_argument("--top", required=True, metavar="X,Y,YAW",
                   help="top grasp relative to the object's origin: metres, metres, radians")
    g.add_argument("--object-pose", default="0,0,0", metavar="X,Y,YAW", help="object pose on the table")
    g.add_argument("--spread", type=float, default=None, help="finger spread (radians); default: the hand's")
    g.add_argument("--hand", default="barrett_bh8", help="hand file name or path")
    g.add_argument("--keep-origin", action="store_true", help="keep a loaded mesh's own origin")
    g.add_argument("--no-lift", action="store_true", help="skip the physical lift test")
    g.add_argument("--json", action="store_true", help="print one JSON object")
    g.set_defaults(run=run)


def run(args) -> int:
    from ..world import World

    top = floats(args.top, 3, "--top")
    pose = floats(args.object_pose, 3, "--object-pose")
    # load_object names the problem (unknown name, missing file, not a mesh) in a ValueError
    world = World.single(args.object, pose=pose, keep_origin=args.keep_origin, hand=args.hand)
    g = world.grasp(*top, spread=args.spread, lift=not args.no_lift).to_dict()
    out = {
        "object": args.object, "object_pose": pose, "top": top, "hand": world.hand.name,
        "joint_angles": [float(v) for v in g["joint_angles"]],
        "joint_names": list(world.hand.core.joint_names),
        "contacts": g["contacts"], "epsilon": g["epsilon"], "volume": g["volume"],
        "lifted": g["lifted"], "lift_displacement": g["lift_displacement"],
        "collision_at_start": g["collision_at_start"],
        "hand_pose": np.asarray(g["hand_pose"]).tolist(),
    }
    if args.json:
        print(json.dumps(out))
    else:
        _print(out, args.object, pose, top)
    return 0


def _print(out: dict, name: str, pose, top) -> None:
    print(f"{out['hand']} on {name} at object pose {pose}, top grasp {top}")
    if out["collision_at_start"]:
        print("  the open hand starts in collision: no grasp")
    print("  joint angles (deg): " + ", ".join(f"{n}={np.degrees(v):.1f}"
                                                 for n, v in zip(out["joint_names"], out["joint_angles"])))
    print(f"  contacts: {len(out['contacts'])}")
    for c in out["contacts"]:
        where = "table" if c["on_table"] else "object"
        p = ", ".join(f"{v:.4f}" for v in c["point"])
        n = ", ".join(f"{v:.3f}" for v in c["normal"])
        print(f"    {c['link_name']:<18} {where:<6} point ({p})  normal ({n})  penetration {c['penetration']:.2e}")
    print(f"  epsilon {out['epsilon']:.4f}   volume {out['volume']:.3e}")
    if out["lifted"] is not None:
        print(f"  lift test: {'lifted' if out['lifted'] else 'dropped'} "
              f"(moved {100 * out['lift_displacement']:.1f} cm relative to the palm)")
