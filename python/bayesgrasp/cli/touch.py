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
    from ..io.results import touch_document, touch_grasp
    from ..loop.touch_trial import touch_once
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
    trial = touch_once(T.TouchPlanner(obj, guess, settings, hand=ctx.hand_model), obj, truth)
    out = touch_document(trial, args.object, args.units, case)
    landscape = _landscape(trial, png, args) if png else None
    if landscape is not None:
        out["png"] = str(landscape)
    fmt = output_format(args)
    if fmt == "ros":
        from ..io.grasp_schema import to_ros

        print(json.dumps(to_ros(touch_grasp(trial), grasp_id=f"{args.object}-touch")))
    elif fmt == "json":
        print(json.dumps(out))
    else:
        _print(trial, args.object, case, landscape)
    from .view import show_result

    show_result(args, out)
    return 0


def _landscape(trial, png, args, n: int = 25):
    """The fitness around the guess: over x, y at the true yaw and scale, and over yaw at the
    truth's and the estimate's position."""
    from .. import viz

    planner, grasp, readings, truth, guess = trial.planner, trial.touch, trial.readings, trial.truth, trial.initial

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


def _print(t, name: str, case: str, landscape) -> None:
    """The text report of a :class:`~bayesgrasp.loop.touch_trial.TouchTrial`."""
    g, rd, fit, settings = t.touch, t.readings, t.fit, t.planner.settings
    ts, e = t.truth, t.estimate
    print(f"touch on {name} ({case}, {settings.optimizer}, contact term {settings.contact_term})")
    print(f"  true state      x={ts[0]:.4f} y={ts[1]:.4f} yaw={ts[2]:.4f} scale={ts[3]:.3f}")
    print(f"  executed grasp  top grasp at x={g.x:.4f} y={g.y:.4f} yaw={g.yaw:.4f}, spread {g.spread:.3f}")
    print("  readings        joints (deg): " + ", ".join(f"{n}={np.degrees(v):.1f}" for n, v in
                                                           zip(t.planner.model.hand.core.joint_names, rd.joints)))
    print(f"                  contacts: {', '.join(t.contact_links) or 'none'}; "
          f"hand closed at z = {np.asarray(rd.hand_pose)[2, 3]:.4f} m")
    _print_fit(fit, e)
    for when, er in (("before", t.errors_before), ("after", t.errors_after)):
        print(f"  errors {when:<7}  position {1000 * er.position_error:.1f} mm, orientation "
              f"{_deg(er.orientation_error)}, size {100 * er.size_error:.1f} %")
    _print_trace(fit)
    if landscape is not None:
        print(f"  landscape       {landscape}")


def _print_fit(fit, e) -> None:
    """The fit's status, estimate and fitness (``fit``: the optimiser's EstimateResult)."""
    from ..planners.touch import EstimateStatus

    if fit.status != EstimateStatus.estimated:
        print(f"  {fit.message}")
    print(f"  estimate        x={e[0]:.4f} y={e[1]:.4f} yaw={e[2]:.4f} scale={e[3]:.3f}")
    print(f"  fitness         {fit.initial_fitness:.4g} at the guess -> {fit.fitness:.4g} "
          f"(joint {fit.joint_term:.3g}, contact {fit.contact_term:.3g}, "
          f"height {fit.height_term:.3g}); {fit.evaluations} evaluations in {fit.seconds:.2f} s")


def _print_trace(fit) -> None:
    evaluations, best = list(fit.trace_evaluations), list(fit.trace_fitness)
    if evaluations:
        k = np.unique(np.linspace(0, len(evaluations) - 1, 6).astype(int))
        print("  trace           " + ", ".join(f"{evaluations[i]}: {best[i]:.3g}" for i in k))
