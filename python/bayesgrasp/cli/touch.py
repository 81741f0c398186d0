"""``bayesgrasp touch``: what one touch tells about an object (thesis ch. 2, Pub. I).

The object stands at its true pose (and scale); the robot believes it at the estimate, executes a
top grasp at the estimated centre along the estimated yaw, reads the contacts, joint angles and
hand height, and fits its model (pose, and the size with --size) to the readings with one
optimiser. Prints the executed grasp, the readings, the estimate and its errors (orientation
modulo the object's symmetry), and the optimiser's trace; --png draws the fitness landscape."""
from __future__ import annotations

import json

import numpy as np

from .args import (CliError, add_format_options, add_hand_option, add_object_options, add_seed_option, add_view_option,
                   bounded_int, context, floats, object_arg, output_file, output_format)


def add(sub) -> None:
    t = sub.add_parser("touch", help="estimate an object's pose (and size) from one touch (Pub. I)",
                       description=__doc__)
    t.add_argument("--object", required=True, help="built-in object name (see `bayesgrasp objects`) or mesh file")
    t.add_argument("--true-pose", required=True, metavar="X,Y,YAW", help="the object's hidden pose (m, m, rad)")
    t.add_argument("--true-scale", type=float, default=1.0, help="the object's hidden uniform scale")
    t.add_argument("--estimate", required=True, metavar="X,Y,YAW", help="the initial guess (m, m, rad)")
    t.add_argument("--optimizer", default=None, choices=["pso", "sa", "firefly", "descent", "trust_region"],
                   help="the fit's optimiser: particle swarm (default), simulated annealing, firefly, gradient "
                        "descent or trust region (Pub. I compares them)")
    t.add_argument("--size", action="store_true", help="estimate the scale too (4 DoF; the guess is scale 1)")
    t.add_argument("--orientation-only", action="store_true", help="estimate the yaw alone, the position given")
    t.add_argument("--budget", type=bounded_int(1, 10**7), default=None,
                   help="fitness evaluations (re-simulated closings; default 2,000)")
    t.add_argument("--contact-term", default=None, choices=["flags", "surface"],
                   help="0/1 contact flags (default), or the continuous distance of the touching links to the surface")
    t.add_argument("--spread", type=float, default=None, help="finger spread of the touch (rad); default: the hand's")
    add_seed_option(t, "the optimiser's seed")
    add_hand_option(t)
    add_object_options(t, mass=False)
    add_format_options(t)
    add_view_option(t)
    t.add_argument("--png", default=None, metavar="PATH", help="write the fitness landscape to this PNG")
    t.set_defaults(run=run)


def _case(args) -> str:
    if args.size and args.orientation_only:
        raise CliError("--size and --orientation-only: choose one")
    return "pose_and_scale" if args.size else "orientation" if args.orientation_only else "pose"


def run(args) -> int:
    from ..planners import touch as T

    truth = np.array(floats(args.true_pose, 3, "--true-pose") + [args.true_scale])
    guess = np.array(floats(args.estimate, 3, "--estimate") + [1.0])
    if not (np.isfinite(args.true_scale) and args.true_scale > 0):
        raise CliError(f"--true-scale: must be positive, got {args.true_scale}")
    case = _case(args)
    if case == "orientation":
        guess[:2] = truth[:2]
    png = output_file(args.png, "--png")
    ctx = context(args, progress=False)
    given = {k: getattr(args, k) for k in ("optimizer", "budget", "contact_term") if getattr(args, k) is not None}
    settings = T.TouchSettings(unknowns=case, seed=ctx.seed, spread=args.spread, threads=0, **given)
    obj = object_arg(args)                          # in --units, read once
    planner = T.TouchPlanner(obj, guess, settings, hand=ctx.hand)
    world = T.touch_world(obj, truth[:3], truth[3], planner.model.hand)
    grasp = planner.plan().touch
    readings = T.read(world, grasp)
    r = planner.observe(grasp, readings)
    out = _result(args, planner, grasp, readings, r, truth, guess, case)
    if png:
        out["png"] = str(_landscape(planner, grasp, readings, truth, guess, png, args))
    fmt = output_format(args)
    if fmt == "ros":
        from ..io.grasp_schema import to_ros

        print(json.dumps(to_ros(out["grasp"], grasp_id=f"{args.object}-touch")))
    elif fmt == "json":
        print(json.dumps(out))
    else:
        _print(out)
    from .view import show_result

    show_result(args, out)
    return 0


def _errors(obj, state, truth) -> dict:
    from ..planners.touch import orientation_error, symmetry_order

    yaw = orientation_error(state[2], truth[2], symmetry_order(obj))
    return {"position_error": float(np.hypot(*(state[:2] - truth[:2]))),
            "orientation_error": None if yaw is None else yaw,
            "size_error": float(abs(state[3] - truth[3]) / truth[3])}


def _result(args, planner, grasp, readings, r, truth, guess, case) -> dict:
    from ..io.grasp_schema import hand_grasp_record

    names = list(planner.model.hand.core.link_names)
    est = np.asarray(planner.estimate, dtype=float)
    return {
        "object": args.object, "units": args.units, "case": case, "optimizer": planner.settings.optimizer,
        "contact_term": planner.settings.contact_term,
        "true_state": truth.tolist(), "initial": guess.tolist(), "estimate": est.tolist(),
        "top_grasp": {"x": grasp.x, "y": grasp.y, "yaw": grasp.yaw, "spread": grasp.spread},
        "grasp": hand_grasp_record(planner.model.hand, readings.hand_pose, readings.joints, grasp.spread),
        "readings": {"joint_angles": np.asarray(readings.joints).tolist(),
                     "joint_names": list(planner.model.hand.core.joint_names),
                     "contact_links": [n for n, c in zip(names, readings.contact) if c],
                     "hand_pose": np.asarray(readings.hand_pose).tolist()},
        **{k: v for k, v in r.to_dict().items() if k not in ("initial", "state", "stopped", "cpu_seconds")},
        "errors_before": _errors(planner.model.object, guess, truth),
        "errors_after": _errors(planner.model.object, est, truth),
    }


def _landscape(planner, grasp, readings, truth, guess, png, args, n: int = 25):
    from .. import viz

    box = planner.settings.box
    xs = np.linspace(guess[0] - box[0], guess[0] + box[0], n)
    ys = np.linspace(guess[1] - box[0], guess[1] + box[0], n)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    states = np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, truth[2]), np.full(X.size, truth[3])])
    model, ct = planner.model, planner.settings.contact_term
    f_xy = model.fitness(grasp, readings, states, contact_term=ct, threads=0).total.reshape(n, n)
    yaws = np.linspace(guess[2] - box[1], guess[2] + box[1], 121)
    at = [np.column_stack([np.full(yaws.size, p[0]), np.full(yaws.size, p[1]), yaws, np.full(yaws.size, p[3])])
          for p in (truth, planner.estimate)]
    f_yaw = [model.fitness(grasp, readings, s, contact_term=ct, threads=0).total for s in at]
    L = {"xs": xs, "ys": ys, "f_xy": f_xy, "yaws": yaws, "f_yaw_truth": f_yaw[0], "f_yaw_estimate": f_yaw[1],
         "truth": truth, "initial": guess, "estimate": planner.estimate}
    return viz.plot_touch_landscape(L, png, f"{args.object}: one touch, {planner.settings.optimizer}")


def _deg(v):
    return "undefined (body of revolution)" if v is None else f"{np.degrees(v):.2f} deg"


def _print(o: dict) -> None:
    g, rd = o["top_grasp"], o["readings"]
    print(f"touch on {o['object']} ({o['case']}, {o['optimizer']}, contact term {o['contact_term']})")
    print(f"  true state      x={o['true_state'][0]:.4f} y={o['true_state'][1]:.4f} "
          f"yaw={o['true_state'][2]:.4f} scale={o['true_state'][3]:.3f}")
    print(f"  executed grasp  top grasp at x={g['x']:.4f} y={g['y']:.4f} yaw={g['yaw']:.4f}, spread {g['spread']:.3f}")
    print("  readings        joints (deg): " + ", ".join(f"{n}={np.degrees(v):.1f}"
                                                           for n, v in zip(rd["joint_names"], rd["joint_angles"])))
    print(f"                  contacts: {', '.join(rd['contact_links']) or 'none'}; "
          f"hand closed at z = {rd['hand_pose'][2][3]:.4f} m")
    if o["status"] != "estimated":
        print(f"  {o['message']}")
    e = o["estimate"]
    print(f"  estimate        x={e[0]:.4f} y={e[1]:.4f} yaw={e[2]:.4f} scale={e[3]:.3f}")
    print(f"  fitness         {o['initial_fitness']:.4g} at the guess -> {o['fitness']:.4g} "
          f"(joint {o['fitness_terms']['joint']:.3g}, contact {o['fitness_terms']['contact']:.3g}, "
          f"height {o['fitness_terms']['height']:.3g}); {o['evaluations']} evaluations in {o['seconds']:.2f} s")
    for when in ("before", "after"):
        er = o[f"errors_{when}"]
        print(f"  errors {when:<7}  position {1000 * er['position_error']:.1f} mm, orientation "
              f"{_deg(er['orientation_error'])}, size {100 * er['size_error']:.1f} %")
    tr = o["trace"]
    if tr["evaluations"]:
        k = np.unique(np.linspace(0, len(tr["evaluations"]) - 1, 6).astype(int))
        print("  trace           " + ", ".join(f"{tr['evaluations'][i]}: {tr['best_fitness'][i]:.3g}" for i in k))
    if "png" in o:
        print(f"  landscape       {o['png']}")
