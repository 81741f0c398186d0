"""``bayesgrasp plan`` and ``bayesgrasp demo``: the closed planning loop under pose uncertainty
(thesis ch. 3) on an object at a hidden true pose."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..loop.episode import EpisodeSettings
from ..planners.registry import PLANNERS, methods_help
from . import camera_input
from .args import (CliError, add_context_options, add_families_option, add_format_options, add_object_options,
                   add_robot_options, add_view_option, bounded_int, context, floats, object_arg, out_dir, output_file,
                   output_format, parse_set, robot_arm)

METHODS = list(PLANNERS)
METHOD_HELP = methods_help(METHODS)


def add(sub) -> None:
    d = sub.add_parser("demo", help="the main job: grasping a mug whose pose is uncertain",
                       description="The main job: a mug at a hidden pose known to +-4 cm and +-45 deg; plan, grasp, "
                                   "read the fingers, update the belief, re-plan until it is lifted; writes "
                                   "belief_evolution.png and demo.json to --out.")
    d.add_argument("--object", default="mug", help="built-in object name or mesh file")
    d.add_argument("--method", default=EpisodeSettings.method, choices=METHODS, help=METHOD_HELP)
    d.add_argument("--out", default="out/demo", help="directory for the PNG and results")
    add_context_options(d)
    add_families_option(d)
    add_object_options(d)
    d.set_defaults(run=demo)

    p = sub.add_parser("plan", help="run the planning loop on an object at a hidden true pose",
                       description="The closed loop of thesis Figs. 3.1 and 3.4 on any object (built-in or mesh file) "
                                   "whose true pose is hidden from the planner: plan, execute in the simulator, read "
                                   "the joint angles, update the belief, re-plan; until a grasp is lifted or the "
                                   "attempts run out. To execute on your own robot, use `bayesgrasp episode`.")
    p.add_argument("--object", required=True, help="built-in object name or mesh file")
    p.add_argument("--true-pose", required=True, metavar="X,Y,YAW", help="the hidden pose: metres, metres, radians")
    p.add_argument("--method", default=EpisodeSettings.method, choices=METHODS, help=METHOD_HELP)
    p.add_argument("--estimate", default=None, metavar="X,Y,YAW",
                   help="the initial pose estimate (default: from --cloud / --depth by registering the object's "
                        "mesh, its spread set by the fit; else the true pose + uniform noise within the belief)")
    p.add_argument("--attempts", type=bounded_int(1, 1000), default=EpisodeSettings.attempts, help="grasps at most")
    p.add_argument("--noise", type=float, default=0.0, help="joint-angle measurement noise std (rad)")
    p.add_argument("--png", default=None, help="write a PNG of the belief's evolution")
    add_format_options(p)
    add_view_option(p)
    add_context_options(p)
    add_families_option(p)
    add_object_options(p, units=False)
    camera_input.add(p)
    add_robot_options(p)
    p.set_defaults(run=plan)


def _print_attempt(a) -> None:
    """One line per attempt (an :class:`~bayesgrasp.loop.episode_result.Attempt`) as it is done."""
    p, ex, b = a.plan, a.execution, a.belief_before
    lift = "" if ex.lifted is None else (", lifted" if ex.lifted else ", dropped in the lift test")
    ent = "" if p.expected_entropy is None else f", expected entropy {p.expected_entropy:.2f}"
    verdict = "SUCCESS" if ex.success else "failed"
    x, y, yaw = (float(v) for v in p.action)
    print(f"  attempt {a.number}: {p.kind:<9} {p.family} grasp ({100 * x:6.1f} cm, {100 * y:6.1f} cm, "
          f"{np.degrees(yaw):6.1f} deg)  predicted P(S) {p.predicted_stability:.2f}{ent}  "
          f"[belief: error {100 * b['position_error']:.1f} cm, entropy {b['kde_entropy']:.2f}]  "
          f"-> epsilon {ex.epsilon:.3f} ({'stable' if ex.stable else 'not stable'}){lift}: {verdict}  "
          f"({1e3 * p.seconds:.0f} ms to plan)", flush=True)


def _loop(args, ctx, pose, attempts: int = EpisodeSettings.attempts, estimate=None, noise: float = 0.0,
          quiet: bool = False, start=None, obj=None, reach=None):
    """The episode on ``obj`` (default: --object by name) in the command's run context ``ctx``;
    ``start``: the vision start (its spread is the belief's); ``reach``: the planner's (the arm)."""
    from dataclasses import replace

    from ..loop.episode import EpisodeSettings, run_episode
    from ..world import World

    if attempts < 1:
        raise CliError(f"--attempts: must be at least 1, got {attempts}")
    if noise and "measurement_noise" in parse_set(getattr(args, "set", [])).episode:
        raise CliError("--noise and --set episode.measurement_noise: two names for one setting; give one")
    obj = args.object if obj is None else obj
    World.single(obj, pose=pose, hand=ctx.hand_model)  # a clear error for an unknown object or a pose off the table
    models = ctx.family_models(obj)
    ctx = replace(ctx, planner=started(ctx.planner_settings(), start), measurement_noise=noise or ctx.measurement_noise)
    episode = EpisodeSettings(method=args.method, attempts=attempts)
    return run_episode(obj, pose, episode, ctx, seed=ctx.seed, estimate=estimate, models=models,
                       keep_planner=True, on_attempt=None if quiet else _print_attempt, reach=reach)


def _belief_png(r, path) -> Path:
    from ..experiments.pose_uncertainty_plots import plot_belief_evolution

    x, y, yaw = r.true_pose
    return plot_belief_evolution(r.snapshots, r.true_pose.tolist(), Path(path),
                                 f"{r.object}, {r.method}: true pose ({100 * x:.1f} cm, {100 * y:.1f} cm, "
                                 f"{np.degrees(yaw):.0f} deg)", [a.to_dict() for a in r.attempts])


def demo(args) -> int:
    """The main job: a mug at a displaced pose the robot knows only to +-4 cm and +-45 deg;
    plan, grasp, read the fingers, update the belief, re-plan until the grasp is stable."""
    from ..io.results import plan_document

    out = out_dir(args.out)
    obj = object_arg(args) if args.units or args.mass is not None else args.object   # a mesh in its unit, weighed
    ctx = context(args)
    pose, skipped = _demo_pose(args, ctx, obj)
    s = ctx.planner_settings()
    print(f"{args.object} at a hidden pose ({100 * pose[0]:.1f} cm, {100 * pose[1]:.1f} cm, "
          f"{np.degrees(pose[2]):.0f} deg); belief: {s.n_particles} particles, +-{100 * s.half_width[0]:g} cm, "
          f"+-{np.degrees(s.half_width[2]):g} deg; method {args.method}")
    if skipped:
        print(f"  (the hidden pose is draw {skipped + 1} of seed {ctx.seed}: at the first {skipped}, the first grasp "
              f"lifted and the belief would not have moved)")
    if ctx.progress:
        ctx.progress("demo: the loop at the hidden pose (each attempt is printed when it has been executed)")
    r = _loop(args, ctx, pose, obj=obj)
    f = r.final_belief
    print(f"{'success' if r.success else 'no successful grasp'} after {len(r.attempts)} attempt(s); "
          f"final belief error {100 * f['position_error']:.1f} cm, {np.degrees(f['yaw_error']):.0f} deg")
    png = _belief_png(r, out / "belief_evolution.png")
    doc = plan_document(r, args.object, args.units, ctx.success)
    (out / "demo.json").write_text(json.dumps(doc, indent=1))
    if ctx.progress:
        ctx.progress(f"demo: drawing the {len(r.attempts)} attempt(s) in the 3D view")
    pictures = _attempt_pictures(doc, out, say=ctx.progress)
    print(f"saved {png}, {out / 'demo.json'} (see it in 3D: bayesgrasp view {out / 'demo.json'}) and "
          f"{len(pictures)} picture(s) of the hand on the {args.object}: {', '.join(p.name for p in pictures)}")
    return 0


#: hidden poses the demo draws at most, looking for one whose first grasp misses
DEMO_DRAWS = 12


def _demo_pose(args, ctx, obj) -> tuple:
    """The demo's hidden pose, drawn from --seed (+-8 cm, any yaw), and the number of draws skipped:
    a draw whose first planned grasp already lifts shows nothing of the belief (it never updates),
    so the next is taken, up to DEMO_DRAWS (then the last). The check is the loop's own first
    attempt (the same seed, so the demo repeats it exactly)."""
    from ..loop.episode import run_episode

    say = ctx.progress or (lambda msg: None)
    rng = np.random.default_rng(ctx.seed)
    models = ctx.family_models(obj)
    for k in range(DEMO_DRAWS):
        pose = [float(rng.uniform(-0.08, 0.08)), float(rng.uniform(-0.08, 0.08)), float(rng.uniform(-np.pi, np.pi))]
        say(f"demo: hidden pose draw {k + 1}: trying its first grasp (a draw whose first grasp lifts is skipped)")
        first = run_episode(obj, pose, EpisodeSettings(method=args.method, attempts=1), ctx, seed=ctx.seed,
                            models=models)
        if not first.attempts[0].success:
            return pose, k
    return pose, DEMO_DRAWS - 1


def _attempt_pictures(doc: dict, out: Path, say=None) -> list:
    """attempt_K.png per attempt: the 3D view's screenshot (headless Chromium), or the same scene
    drawn by matplotlib when no browser is installed or the browser fails (e.g. its renderer times
    out on a loaded machine; said on stderr)."""
    import sys

    from ..viewer import scene_from_result
    from ..viewer.static import render_steps

    scene = scene_from_result(doc)
    paths = {k: out / f"attempt_{k + 1}.png" for k in range(len(scene.steps))}
    try:
        from selenium.common.exceptions import WebDriverException

        from ..viewer.snapshot import NoBrowser, find_browser, snapshot_steps
    except ImportError as e:
        print(f"no browser for the 3D view's screenshots ({e}); drawing them with matplotlib", file=sys.stderr)
        return render_steps(scene, paths)
    try:
        find_browser()
        return snapshot_steps(scene, paths, port=8090, say=say)
    except (NoBrowser, WebDriverException) as e:
        reason = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        print(f"the 3D view's screenshots failed ({reason}); drawing them with matplotlib", file=sys.stderr)
        return render_steps(scene, paths)


def plan(args) -> int:
    pose = floats(args.true_pose, 3, "--true-pose")
    fmt = output_format(args)
    quiet = fmt != "text"
    est = floats(args.estimate, 3, "--estimate") if args.estimate else None
    if not (np.isfinite(args.noise) and args.noise >= 0):
        raise CliError(f"--noise: must be >= 0, got {args.noise}")
    png = output_file(args.png, "--png")
    obj = args.object
    if args.units or args.mass is not None or camera_input.given(args):   # the mesh read once, in its unit
        obj = object_arg(args)
    ctx = context(args)
    arm = robot_arm(args, ctx.hand_model)
    reach = None
    if arm is not None:
        from ..planners.reach import ActionReach

        reach = ActionReach(arm, obj, ctx.hand)
    start, view = _vision_start(args, obj, est, quiet, ctx.seed)
    if start is not None:
        est = start.estimate.tolist()
    r = _loop(args, ctx, pose, args.attempts, est, args.noise, quiet=quiet, start=start, obj=obj, reach=reach)
    arms = None if arm is None else _arm_records(arm, obj, pose, r, ctx.hand)
    if png:
        _belief_png(r, png)
    if fmt == "ros":
        from ..io.grasp_schema import to_ros
        from ..io.results import attempt_grasp

        grasps = [attempt_grasp(a) for a in r.attempts]
        for g, rec in zip(grasps, arms or []):      # with --robot: each grasp in the arm's terms
            g["arm"] = rec
        print(json.dumps({"attempts": [to_ros(g, grasp_id=f"attempt-{a.number}", quality=a.plan.predicted_stability)
                                       for a, g in zip(r.attempts, grasps)]}))
    if fmt == "json" or args.view is not None:   # plan's JSON, with the vision start when there is one
        from ..io.results import plan_document, vision_dict

        vision = None if start is None else vision_dict(start, args.cloud or args.depth, view.object_points)
        doc = plan_document(r, args.object, args.units, ctx.success, vision=vision)
        for a, rec in zip(doc["attempts"], arms or []):   # with --robot: each attempt's grasp in the arm's terms
            a["grasp"]["arm"] = rec
    if fmt == "json":
        print(json.dumps(doc))
    elif fmt == "text":
        print(f"{'success' if r.success else 'no successful grasp'} after {len(r.attempts)} attempt(s)")
        if arms is not None:
            k = sum(a["reachable"] for a in arms)
            print(f"arm {Path(arm.urdf).name}: {k} of {len(arms)} executed grasp(s) reachable"
                  + "".join(f"; attempt {i + 1}: {a['reason']}" for i, a in enumerate(arms) if not a["reachable"]))
    if args.view is not None:
        from .view import show_result

        show_result(args, doc)
    return 0


def _arm_records(arm, obj, pose, r, hand) -> list:
    """Each executed grasp (at the true pose, where the hand closed) checked with the arm: the grasp
    schema's ``arm`` per attempt."""
    from ..arm import ReachOptions, arm_record, check_reach
    from ..io.grasp_schema import PREGRASP_DISTANCE
    from ..world import World

    if not r.attempts:
        return []
    world = World.single(obj, pose=pose, hand=hand)
    P = np.stack([np.asarray(a.execution.hand_pose, dtype=float) for a in r.attempts])
    res = check_reach(arm, P, (world.vertices, world.faces), ReachOptions(pregrasp_distance=PREGRASP_DISTANCE))
    return [arm_record(arm, res, i) for i in range(len(P))]


def started(settings, start):
    """The planner settings with the vision start's belief spread (``start`` None: as they are)."""
    return settings if start is None else settings.with_(half_width=tuple(start.half_width.tolist()))


def _vision_start(args, obj, estimate, quiet: bool, seed: int):
    """The estimate and belief spread from registering ``obj`` (--object's mesh) to the camera
    data (the registration seeded by ``seed``), and the camera data (None, None without them)."""
    view = camera_input.observe(args)
    if view is None:
        return None, None
    if estimate is not None:
        raise CliError("--estimate: not with --cloud or --depth (the estimate comes from registering to them)")
    if "half_width" in parse_set(getattr(args, "set", [])).planner:
        raise CliError("--set planner.half_width: not with --cloud or --depth (the belief's spread comes from "
                       "registering to them)")
    from ..loop.vision_start import vision_start

    start = vision_start(obj, view.object_points, view.viewpoint, seed=seed)
    if not quiet:
        x, y, yaw = start.estimate
        hx, _, hyaw = start.half_width
        print(f"vision: {args.object} registered to {args.cloud or args.depth} at ({100 * x:.1f} cm, {100 * y:.1f} cm, "
              f"{np.degrees(yaw):.0f} deg), fit {1000 * start.registration.delta:.1f} mm -> belief "
              f"+-{100 * hx:.1f} cm, +-{np.degrees(hyaw):.0f} deg")
    return start, view
