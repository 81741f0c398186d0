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


def _print_attempt(a: dict) -> None:
    lift = "" if a["lifted"] is None else (", lifted" if a["lifted"] else ", dropped in the lift test")
    ent = "" if a["expected_entropy"] is None else f", expected entropy {a['expected_entropy']:.2f}"
    x, y, yaw = a["action"]
    b = a["belief_before"]
    print(f"  attempt {a['attempt']}: {a['kind']:<9} grasp ({100 * x:6.1f} cm, {100 * y:6.1f} cm, "
          f"{np.degrees(yaw):6.1f} deg)  predicted P(S) {a['predicted_stability']:.2f}{ent}  "
          f"[belief: error {100 * b['position_error']:.1f} cm, entropy {b['kde_entropy']:.2f}]  "
          f"-> epsilon {a['epsilon']:.3f}: {'STABLE' if a['stable'] else 'not stable'}{lift}  "
          f"({1e3 * a['plan_seconds']:.0f} ms to plan)", flush=True)


def _loop(obj, pose, method, seed, cache, attempts=4, estimate=None, noise=0.0, hand="barrett_bh8",
          quiet=False) -> dict:
    from .planners import get_models, run_episode

    if attempts < 1:
        raise CliError(f"--attempts: must be at least 1, got {attempts}")
    _world(obj, pose, hand=hand)  # a clear error for an unknown object or a pose off the table
    say = None if quiet else (lambda m: print(m, file=sys.stderr, flush=True))
    models = get_models(obj, hand, cache_dir=cache, progress=say)
    return run_episode(obj, pose, method=method, seed=seed, attempts=attempts, estimate=estimate,
                       measurement_noise=noise, hand=hand, models=models, keep_planner=True,
                       on_attempt=None if quiet else _print_attempt)


def _belief_png(r: dict, path) -> Path:
    from .experiments.report import plot_belief_evolution

    return plot_belief_evolution(r["snapshots"], r["true_pose"], Path(path),
                                 f"{r['object']}, {r['method']}: true pose "
                                 f"({100 * r['true_pose'][0]:.1f} cm, {100 * r['true_pose'][1]:.1f} cm, "
                                 f"{np.degrees(r['true_pose'][2]):.0f} deg)", r["attempts"])


def _json_ready(r: dict) -> dict:
    return {k: v for k, v in r.items() if k not in ("planner", "snapshots")}


def demo(args) -> int:
    """The main job: a mug at a displaced pose the robot knows only to +-4 cm and +-45 deg;
    plan, grasp, read the fingers, update the belief, re-plan until the grasp is stable."""
    out = _out_dir(args.out)
    rng = np.random.default_rng(args.seed)
    pose = [float(rng.uniform(-0.08, 0.08)), float(rng.uniform(-0.08, 0.08)), float(rng.uniform(-np.pi, np.pi))]
    print(f"{args.object} at a hidden pose ({100 * pose[0]:.1f} cm, {100 * pose[1]:.1f} cm, "
          f"{np.degrees(pose[2]):.0f} deg); belief: 500 particles, +-4 cm, +-45 deg; method {args.method}")
    r = _loop(args.object, pose, args.method, args.seed, args.cache)
    f = r["final_belief"]
    print(f"{'success' if r['success'] else 'no stable grasp'} after {len(r['attempts'])} attempt(s); "
          f"final belief error {100 * f['position_error']:.1f} cm, {np.degrees(f['yaw_error']):.0f} deg")
    png = _belief_png(r, out / "belief_evolution.png")
    (out / "demo.json").write_text(json.dumps(_json_ready(r), indent=1))
    print(f"saved {png} and {out / 'demo.json'}")
    return 0


def plan(args) -> int:
    pose = _floats(args.true_pose, 3, "--true-pose")
    est = _floats(args.estimate, 3, "--estimate") if args.estimate else None
    if not (np.isfinite(args.noise) and args.noise >= 0):
        raise CliError(f"--noise: must be >= 0, got {args.noise}")
    if args.png:
        _out_dir(str(Path(args.png).parent))
    r = _loop(args.object, pose, args.method, args.seed, args.cache, args.attempts, est, args.noise, args.hand,
              quiet=args.json)
    if args.png:
        _belief_png(r, args.png)
    if args.json:
        f = r["final_belief"]
        out = {"object": args.object, "method": args.method, "true_pose": pose, "estimate": r["estimate"],
               "success": r["success"],
               "attempts": [{"plan_type": a["kind"], "grasp": a["action"], "predicted_stability": a["predicted_stability"],
                             "expected_entropy": a["expected_entropy"], "entropy": a["belief_before"]["kde_entropy"],
                             "epsilon": a["epsilon"], "lifted": a["lifted"],
                             "outcome": "stable" if a["stable"] else "unstable", "plan_seconds": a["plan_seconds"],
                             "joint_angles": a["joint_angles"]} for a in r["attempts"]],
               "final_belief": {"mean": f["mean"], "std": f["std"], "entropy": f["kde_entropy"], "ess": f["ess"],
                                "position_error": f["position_error"], "yaw_error": f["yaw_error"]}}
        print(json.dumps(out))
    else:
        print(f"{'success' if r['success'] else 'no stable grasp'} after {len(r['attempts'])} attempt(s)")
    return 0


def experiment(args) -> int:
    from .experiments.pose_uncertainty import EXPERIMENTS, run

    if args.name not in EXPERIMENTS:
        raise CliError(f"unknown experiment {args.name!r}; one of: {', '.join(EXPERIMENTS)}")
    if args.runs is not None and args.runs < 1:
        raise CliError(f"--runs: must be at least 1, got {args.runs}")
    if args.workers < 1:
        raise CliError(f"--workers: must be at least 1, got {args.workers}")
    if args.objects:
        from .objects import load_object

        for o in args.objects:
            load_object(o)  # a clear error for an unknown object
    out = _out_dir(args.out or f"out/experiments/{args.name}")
    import time

    t0 = time.perf_counter()
    summary = run(args.name, out, runs=args.runs, workers=args.workers, base_seed=args.seed, objects=args.objects,
                  cache_dir=args.cache, lift=not args.no_lift)
    print((out / "summary.md").read_text())
    print(f"{args.name}: done in {time.perf_counter() - t0:.0f} s; tables, plots and results.sqlite in {out}")
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
