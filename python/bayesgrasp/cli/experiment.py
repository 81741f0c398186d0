"""``bayesgrasp experiment NAME``: run (or resume) one of the registered experiments."""
from __future__ import annotations

import argparse
import time

from .args import SEED_MAX, CliError, add_context_options, add_families_option, bounded_int, context, hand_name, out_dir


def add(sub) -> None:
    e = sub.add_parser("experiment", help="run (or resume) one of the thesis's experiments",
                       description="Runs (or resumes) one of the thesis's experiments, run by run in worker "
                                   "processes; every finished run is stored in the output directory's results.sqlite, "
                                   "so an interrupted experiment resumes without repeating a run.")
    e.add_argument("name", help="the experiment's name; `bayesgrasp experiment list` lists them")
    e.add_argument("--runs", type=bounded_int(1, 10**7), default=None, help="runs per object (default: the experiment's)")
    e.add_argument("--workers", type=bounded_int(1, 1024), default=1, help="worker processes")
    e.add_argument("--out", default=None, help="output directory (default: out/experiments/NAME)")
    e.add_argument("--objects", nargs="+", default=None, help="objects (default: the experiment's)")
    e.add_argument("--config", default=None, metavar="FILE.toml",
                   help="settings from a TOML file: runs, workers, out, objects, hand, success, lift, seed, cache, "
                        "families at "
                        "the top and a [models] table (ModelSettings fields); an option given on the command line "
                        "(other than its default) and --set win over the file")
    add_context_options(e, lift=True)
    add_families_option(e)
    e.set_defaults(run=run)


#: The TOML keys --config takes at its top level, with the option each sets and how it is checked.
CONFIG_KEYS = {"runs": int, "workers": int, "out": str, "objects": list, "hand": str, "success": str,
               "lift": bool, "seed": int, "cache": str, "families": str}


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
    models = cfg.pop("models", {})
    if not isinstance(models, dict):
        raise CliError(f"--config: {path}: models must be a table ([models])")
    for key, value in cfg.items():
        kind = CONFIG_KEYS.get(key)
        if kind is None:
            raise CliError(f"--config: {path}: unknown key {key!r} (known: {', '.join(CONFIG_KEYS)}, [models])")
        if not isinstance(value, kind) or (kind is int and isinstance(value, bool)) or \
                (kind is list and not all(isinstance(v, str) for v in value)):
            raise CliError(f"--config: {path}: {key} must be {'a list of names' if kind is list else kind.__name__}, "
                           f"got {value!r}")
        if key == "lift":
            if args.no_lift == defaults["no_lift"]:
                args.no_lift = not value
        elif getattr(args, key) == defaults[key]:
            setattr(args, key, value)
    args.set = [f"models.{k}={'none' if v is None else str(v).lower() if isinstance(v, bool) else v}"
                for k, v in models.items()] + list(args.set)


def run(args) -> int:
    from ..experiments import driver
    from ..experiments.registry import EXPERIMENTS, experiment_names, get_experiment
    from ..objects import load_object

    if args.name == "list":
        for name in experiment_names():
            print(f"{name:<14} {EXPERIMENTS[name].description}")
        return 0
    try:
        get_experiment(args.name)
    except ValueError as e:
        raise CliError(str(e)) from None
    if args.config:
        apply_config(args, args.config, {"runs": None, "workers": 1, "out": None, "objects": None,
                                         "hand": "barrett_bh8", "success": "lift", "no_lift": False, "seed": 0,
                                         "families": "top",
                                         "cache": None})
        if (args.runs is not None and args.runs < 1) or args.workers < 1 or not 0 <= args.seed <= SEED_MAX:
            raise CliError(f"--config: {args.config}: runs and workers must be at least 1, seed in [0, 2^63 - 1]")
        if args.success not in ("lift", "epsilon"):
            raise CliError(f"--config: {args.config}: success must be 'lift' or 'epsilon', got {args.success!r}")
        try:
            hand_name(args.hand)
        except argparse.ArgumentTypeError as e:
            raise CliError(f"--config: {args.config}: {e}") from None
    for o in args.objects or ():
        load_object(o)  # a clear error for an unknown object
    out = out_dir(args.out or f"out/experiments/{args.name}")
    t0 = time.perf_counter()
    driver.run(args.name, out, context(args), runs=args.runs, workers=args.workers, objects=args.objects)
    print((out / "summary.md").read_text())
    print(f"{args.name}: done in {time.perf_counter() - t0:.0f} s; tables, plots and results.sqlite in {out}")
    return 0
