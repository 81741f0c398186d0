"""``bayesgrasp experiment NAME``: run (or resume) one of the registered experiments."""
from __future__ import annotations

import argparse
import time

from .args import (SEED_MAX, CliError, add_context_options, add_families_option, bounded_int, context, hand_name,
                   out_dir, refuse_unread)


def add(sub) -> None:
    e = sub.add_parser("experiment", help="run (or resume) one of the thesis's experiments",
                       description="Runs (or resumes) one of the thesis's experiments, run by run in worker "
                                   "processes; every finished run is stored in the output directory's results.sqlite, "
                                   "so an interrupted experiment resumes without repeating a run.")
    e.add_argument("name", help="the experiment's name; `bayesgrasp experiment list` lists them")
    e.add_argument("--runs", type=bounded_int(1, 10**7), default=None, help="runs per object (default: the experiment's)")
    e.add_argument("--workers", type=bounded_int(1, 1024), default=1,
                   help="worker processes (engine local) or the local Ray instance's CPUs (engine ray)")
    e.add_argument("--engine", default="local", choices=["local", "ray"],
                   help="where the runs go: local worker processes (default) or Ray tasks (a local Ray instance, "
                        "or the cluster at --address); both store the same results for the same seeds")
    e.add_argument("--address", default=None, metavar="HOST:PORT",
                   help="an existing Ray cluster's address (engine ray; every node needs bayesgrasp installed and "
                        "--cache on storage they all share)")
    e.add_argument("--out", default=None, help="output directory (default: out/experiments/NAME)")
    e.add_argument("--objects", nargs="+", default=None, help="objects (default: the experiment's)")
    e.add_argument("--config", default=None, metavar="FILE.toml",
                   help="settings from a TOML file: runs, workers, engine, address, out, objects, hand, success, "
                        "lift, seed, cache, families at the top; [models], [planner] and [episode] tables (as --set) "
                        "and a [sweep] table (GROUP.FIELD = [values], or [sweep.GROUP] FIELD = [values]); an option "
                        "given on the command line (other than its default), --set and --sweep win over the file")
    e.add_argument("--sweep", action="append", default=[], metavar="GROUP.FIELD=V1,V2,...",
                   help="run the experiment at every combination of these values (repeatable; a grid), e.g. "
                        "--sweep planner.n_particles=250,500 --sweep episode.measurement_noise=0,0.02; fields as for "
                        "--set; one results file, each point's report in OUT/GROUP.FIELD=V_.../")
    add_context_options(e, lift=True)
    add_families_option(e)
    # the command line's defaults, read once here: --config fills only the options left at them
    e.set_defaults(run=run, config_defaults={k: e.get_default(k) for k in CONFIG_OPTIONS})


#: The TOML keys --config takes at its top level, with how each is checked.
CONFIG_KEYS = {"runs": int, "workers": int, "engine": str, "address": str, "out": str, "objects": list, "hand": str,
               "success": str, "lift": bool, "seed": int, "cache": str, "families": str}
#: The options --config may set (argparse destinations: lift is --no-lift's).
CONFIG_OPTIONS = tuple("no_lift" if k == "lift" else k for k in CONFIG_KEYS)


def apply_config(args, path: str, defaults: dict) -> None:
    """Fills ``args`` from the TOML file where the command line left an option at its default;
    [models] FIELD = VALUE becomes --set models.FIELD=VALUE before the command line's own --set."""
    import tomllib

    try:
        with open(path, "rb") as f:
            cfg = tomllib.load(f)
    except OSError as e:
        raise CliError(f"--config: cannot read {path}: {e.strerror or e}") from None
    except tomllib.TOMLDecodeError as e:
        raise CliError(f"--config: {path}: {e}") from None
    tables = {g: cfg.pop(g, {}) for g in ("models", "planner", "episode")}
    sweep = cfg.pop("sweep", {})
    for g, t in [*tables.items(), ("sweep", sweep)]:
        if not isinstance(t, dict):
            raise CliError(f"--config: {path}: {g} must be a table ([{g}])")
    for key, value in cfg.items():
        kind = CONFIG_KEYS.get(key)
        if kind is None:
            raise CliError(f"--config: {path}: unknown key {key!r} (known: {', '.join(CONFIG_KEYS)}, [models], "
                           f"[planner], [episode], [sweep])")
        if not isinstance(value, kind) or (kind is int and isinstance(value, bool)) or \
                (kind is list and not all(isinstance(v, str) for v in value)):
            raise CliError(f"--config: {path}: {key} must be {'a list of names' if kind is list else kind.__name__}, "
                           f"got {value!r}")
        if key == "lift":
            if args.no_lift == defaults["no_lift"]:
                args.no_lift = not value
        elif getattr(args, key) == defaults[key]:
            setattr(args, key, value)
    args.set = [f"{g}.{k}={_toml_value(v)}" for g, t in tables.items() for k, v in t.items()] + list(args.set)
    axes = {}
    for k, v in sweep.items():   # "group.field" = [...] or [sweep.group] field = [...]
        for key, values in ({f"{k}.{f}": x for f, x in v.items()} if isinstance(v, dict) else {k: v}).items():
            if not isinstance(values, list):
                raise CliError(f"--config: {path}: sweep {key} must be a list of values, got {values!r}")
            axes[key] = ",".join(_toml_value(x) for x in values)
    given = {a.partition("=")[0] for a in args.sweep}
    args.sweep = [f"{k}={v}" for k, v in axes.items() if k not in given] + list(args.sweep)


def _toml_value(v) -> str:
    if isinstance(v, (list, tuple)):
        return ",".join(_toml_value(x) for x in v)
    return "none" if v is None else str(v).lower() if isinstance(v, bool) else str(v)


def sweep_points(args) -> list:
    """--sweep's grid as [(params, args for that point)]: each value read as its field's type
    (parse_set), a field swept twice or a tuple-valued field refused."""
    import copy

    from ..experiments.sweep import grid
    from .args import parse_set

    axes = {}
    for a in args.sweep:
        key, sep, text = a.partition("=")
        if not sep or not text:
            raise CliError(f"--sweep: expected GROUP.FIELD=V1,V2,...; got {a!r}")
        if key in axes:
            raise CliError(f"--sweep: {key} is swept twice")
        group, field = key.split(".", 1) if "." in key else (key, "")
        values = []
        for t in text.split(","):
            try:
                v = getattr(parse_set([f"{key}={t}"]), group)[field]
            except CliError as e:
                raise CliError(str(e).replace("--set", "--sweep", 1)) from None
            if isinstance(v, tuple):
                raise CliError(f"--sweep: {key} holds several numbers; sweep a single-valued field")
            values.append(v)
        axes[key] = values
    try:
        points = grid(axes)
    except ValueError as e:
        raise CliError(f"--{e}") from None
    out = []
    for params in points:
        a = copy.copy(args)
        a.set = list(args.set) + [f"{k}={_toml_value(v)}" for k, v in params.items()]
        out.append((params, a))
    return out


def run(args) -> int:
    from ..experiments import driver
    from ..experiments.engines import check_engine, make_engine
    from ..experiments.registry import EXPERIMENTS, experiment_names, get_experiment
    from ..objects import load_object

    if args.name == "list":
        for name in experiment_names():
            exp = EXPERIMENTS[name]
            print(f"{name:<16} {exp.description} (reads: {', '.join(exp.reads) or 'no run settings'})")
        return 0
    try:
        get_experiment(args.name)
    except ValueError as e:
        raise CliError(str(e)) from None
    if args.config:
        apply_config(args, args.config, args.config_defaults)
        if (args.runs is not None and args.runs < 1) or args.workers < 1 or not 0 <= args.seed <= SEED_MAX:
            raise CliError(f"--config: {args.config}: runs and workers must be at least 1, seed in [0, 2^63 - 1]")
        if args.engine not in ("local", "ray"):
            raise CliError(f"--config: {args.config}: engine must be 'local' or 'ray', got {args.engine!r}")
        if args.success not in ("lift", "epsilon"):
            raise CliError(f"--config: {args.config}: success must be 'lift' or 'epsilon', got {args.success!r}")
        try:
            hand_name(args.hand)
        except argparse.ArgumentTypeError as e:
            raise CliError(f"--config: {args.config}: {e}") from None
    for o in args.objects or ():
        load_object(o)  # a clear error for an unknown object
    exp = get_experiment(args.name)
    refuse_unread(args, exp.reads, f"experiment {exp.name}")    # not silently dropped
    try:                         # before the output directory or the cache is created
        check_engine(args.engine, args.workers, args.address)
    except ValueError as e:      # its errors name the field: engine, workers or address
        raise CliError(f"--{e}") from None
    out = out_dir(args.out or f"out/experiments/{args.name}")
    ctx = context(args)
    points = None
    if args.sweep:
        from ..experiments.sweep import Point, run_sweep

        points = [Point(params, context(a)) for params, a in sweep_points(args)]
    t0 = time.perf_counter()
    try:
        engine = make_engine(args.engine, args.workers, args.address)
    except ValueError as e:      # its errors name the field: engine, workers or address
        field, _, why = str(e).partition(": ")
        raise CliError(f"--{field}: {why}" if field in ("engine", "workers", "address") else f"--engine: {e}") from None
    try:
        if points is not None:
            run_sweep(args.name, out, points, runs=args.runs, objects=args.objects, engine=engine,
                      progress=ctx.progress)
            print((out / "sweep.md").read_text())
            print(f"{args.name}: sweep of {len(points)} points done in {time.perf_counter() - t0:.0f} s; per-point "
                  f"reports, sweep.csv and results.sqlite in {out}")
            return 0
        driver.run(args.name, out, ctx, runs=args.runs, objects=args.objects, engine=engine)
    finally:
        engine.close()
    print((out / "summary.md").read_text())
    print(f"{args.name}: done in {time.perf_counter() - t0:.0f} s; tables, plots and results.sqlite in {out}")
    return 0
