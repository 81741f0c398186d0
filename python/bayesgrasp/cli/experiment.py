"""``bayesgrasp experiment NAME``: run (or resume) one of the registered experiments."""
from __future__ import annotations

import time

from .args import CliError, add_context_options, bounded_int, context, out_dir


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
    add_context_options(e, lift=True)
    e.set_defaults(run=run)


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
    for o in args.objects or ():
        load_object(o)  # a clear error for an unknown object
    out = out_dir(args.out or f"out/experiments/{args.name}")
    t0 = time.perf_counter()
    driver.run(args.name, out, context(args), runs=args.runs, workers=args.workers, objects=args.objects)
    print((out / "summary.md").read_text())
    print(f"{args.name}: done in {time.perf_counter() - t0:.0f} s; tables, plots and results.sqlite in {out}")
    return 0
