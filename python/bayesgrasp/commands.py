"""Implementations of the ``bayesgrasp`` sub-commands (argument parsing is in :mod:`bayesgrasp.cli`)."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from .cli import CliError, _floats, _out_dir


def _world(object_name: str, pose, hand: str = "barrett_bh8", keep_origin: bool = False, **kwargs):
    from .world import World

    # load_object names the problem (unknown name, missing file, not a mesh) in a ValueError
    return World.single(object_name, pose=pose, keep_origin=keep_origin, hand=hand, **kwargs)


def grasp(args) -> int:
    top = _floats(args.top, 3, "--top")
    pose = _floats(args.object_pose, 3, "--object-pose")
    world = _world(args.object, pose, hand=args.hand, keep_origin=args.keep_origin)
    g = world.grasp(*top, spread=args.spread, lift=not args.no_lift)
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
        return 0
    print(f"{world.hand.name} on {args.object} at object pose {pose}, top grasp {top}")
    if g["collision_at_start"]:
        print("  the open hand starts in collision: no grasp")
    print("  joint angles (deg): " + ", ".join(f"{n}={np.degrees(v):.1f}"
                                                 for n, v in zip(out["joint_names"], g["joint_angles"])))
    print(f"  contacts: {len(g['contacts'])}")
    for c in g["contacts"]:
        where = "table" if c["on_table"] else "object"
        p = ", ".join(f"{v:.4f}" for v in c["point"])
        n = ", ".join(f"{v:.3f}" for v in c["normal"])
        print(f"    {c['link_name']:<18} {where:<6} point ({p})  normal ({n})  penetration {c['penetration']:.2e}")
    print(f"  epsilon {g['epsilon']:.4f}   volume {g['volume']:.3e}")
    if g["lifted"] is not None:
        print(f"  lift test: {'lifted' if g['lifted'] else 'dropped'} "
              f"(moved {100 * g['lift_displacement']:.1f} cm relative to the palm)")
    return 0


def objects(args) -> int:
    from .objects import list_objects

    for name in list_objects():
        print(name)
    return 0


def demo(args) -> int:
    """Sweep top grasps over a built-in object, print the best ten by epsilon, lift-test them and
    save a PNG of the best grasp."""
    out = _out_dir(args.out)
    world = _world(args.object, (0.0, 0.0, 0.0))
    ext = world.object.extent
    xs = np.linspace(-0.3 * ext[0], 0.3 * ext[0], 7)
    ys = np.linspace(-0.3 * ext[1], 0.3 * ext[1], 7)
    yaws = np.linspace(0.0, np.pi, 12, endpoint=False)
    spreads = [0.0, np.pi / 3, np.pi / 2]
    grid = np.array([(x, y, a) for x in xs for y in ys for a in yaws])
    rows = []
    for spread in spreads:
        b = world.grasp_batch(grid, spread=spread, threads=0)
        for i in range(len(grid)):
            if not b["collision_at_start"][i]:
                rows.append((float(b["epsilon"][i]), float(b["volume"][i]), spread, *grid[i]))
    rows.sort(key=lambda r: -r[0])
    print(f"{len(grid) * len(spreads)} top grasps on {args.object} "
          f"({int(np.sum([r[0] > 0 for r in rows]))} force-closure); best ten by epsilon:")
    best = rows[:10]
    if not best:
        raise CliError("no collision-free grasp found")
    # Lift-test the best ten, in C++ threads, one batch per spread.
    print("lift-testing the best ten (Bullet) ...", file=sys.stderr)
    lifted = {}
    for spread in sorted({r[2] for r in best}):
        idx = [k for k, r in enumerate(best) if r[2] == spread]
        b = world.grasp_batch(np.array([best[k][3:] for k in idx]), spread=spread, lift=True, threads=0)
        lifted.update({k: bool(v) for k, v in zip(idx, b["lifted"])})
    print(f"{'rank':>4} {'x (m)':>8} {'y (m)':>8} {'yaw':>6} {'spread':>7} {'epsilon':>8} {'volume':>10} lifted")
    table = []
    for k, (eps, vol, spread, x, y, yaw) in enumerate(best):
        table.append({"x": x, "y": y, "yaw": yaw, "spread": spread, "epsilon": eps, "volume": vol,
                      "lifted": lifted[k]})
        print(f"{k + 1:>4} {x:>8.4f} {y:>8.4f} {np.degrees(yaw):>5.0f}° {np.degrees(spread):>6.0f}° "
              f"{eps:>8.4f} {vol:>10.3e} {'yes' if lifted[k] else 'no'}")
    top = best[0]
    g = world.grasp(*top[3:], spread=top[2])
    png = world.plot_grasp(g, out / "best_grasp.png",
                           title=f"best of {len(rows)} top grasps on {args.object}: epsilon {top[0]:.3f}")
    (out / "best_grasps.json").write_text(json.dumps(table, indent=1))
    print(f"saved {png} and {out / 'best_grasps.json'}")
    return 0


def register(args) -> int:
    from .vision import register_command

    pose = _floats(args.pose, 3, "--pose")
    if not (args.voxel > 0 and np.isfinite(args.voxel)):
        raise CliError(f"--voxel: must be positive, got {args.voxel}")
    if args.png:
        _out_dir(str(Path(args.png).parent or "."))
    register_command(args.scene_object, pose, args.models, json_out=args.json, png=args.png,
                     voxel=args.voxel, seed=args.seed)
    return 0
