"""Runs per second of the two experiment engines (local processes, Ray tasks) on 1 and 2 workers,
and the per-run costs a sweep's duration is estimated from.

Throughput: ``pub2`` runs (stability planner, success = lifted, top grasps) on the cube and the
mug, the models built beforehand into a shared cache (so only runs are timed), ``--runs`` per
object, into a fresh results file per configuration; the wall time from the first submitted run
to the last stored one. Ray's start (a local instance) is timed separately and not included.
Per-run costs: the median wall time of one run on one worker for ``pub2`` and the category
experiment ``pub5`` (3 task plans with registration against the training models and a lift
test each), its task grasps prepared beforehand.

    python bench/engines.py --out bench/results/engines.json [--runs 8] [--category-runs 2]
"""
import argparse
import json
import os
import sys
import tempfile
import time

import numpy as np

from bayesgrasp.experiments import RunContext
from bayesgrasp.experiments.driver import prepare
from bayesgrasp.experiments.engines import LocalEngine, RayEngine
from bayesgrasp.experiments.registry import get_experiment
from bayesgrasp.experiments.runner import ResultStore, Series, run_all


def throughput(engine, ctx, objects, runs):
    exp = get_experiment("pub2")
    series, fn = exp.make_run(exp, "stability", ctx.for_workers())
    with tempfile.TemporaryDirectory() as d:
        store = ResultStore(os.path.join(d, "results.sqlite"))
        t0 = time.perf_counter()
        run_all([Series(series, tuple(objects), runs, fn, seed_name=exp.seeds)], store, ctx.seed, engine, progress=False)
        seconds = time.perf_counter() - t0
        store.close()
    return len(objects) * runs / seconds, seconds


def per_run_seconds(name, objects, runs, ctx):
    exp = get_experiment(name)
    prepare(exp, objects, ctx, LocalEngine(1))
    series, fn = exp.make_run(exp, exp.methods[0], ctx.for_workers())
    times = []
    for o in objects:
        for i in range(runs):
            t0 = time.perf_counter()
            fn(series, o, i, 1000 + i)
            times.append(time.perf_counter() - t0)
    return float(np.median(times)), times


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="bench/results/engines.json")
    ap.add_argument("--runs", type=int, default=8, help="pub2 runs per object per configuration")
    ap.add_argument("--category-runs", type=int, default=2, help="pub5 runs per object for its per-run cost")
    ap.add_argument("--cache", default=None)
    a = ap.parse_args()
    ctx = RunContext(cache_dir=a.cache)
    objects = ("cube", "mug")
    prepare(get_experiment("pub2"), list(objects), ctx, LocalEngine(1))   # models into the cache
    out = {"objects": objects, "runs_per_object": a.runs, "throughput": {}}
    for workers in (1, 2):
        rate, s = throughput(LocalEngine(workers), ctx, objects, a.runs)
        out["throughput"][f"local_{workers}"] = {"runs_per_s": rate, "seconds": s}
        print(f"local {workers}: {rate:.3f} runs/s ({s:.1f} s)", file=sys.stderr, flush=True)
        t0 = time.perf_counter()
        ray_engine = RayEngine(workers=workers)
        start = time.perf_counter() - t0
        try:
            rate, s = throughput(ray_engine, ctx, objects, a.runs)
        finally:
            ray_engine.close()
        out["throughput"][f"ray_{workers}"] = {"runs_per_s": rate, "seconds": s, "ray_start_s": start}
        print(f"ray {workers}: {rate:.3f} runs/s ({s:.1f} s; Ray start {start:.1f} s)", file=sys.stderr, flush=True)
    pub2, _ = per_run_seconds("pub2", ["mug"], 4, ctx)
    pub5, times5 = per_run_seconds("pub5", ["mug/0", "bottle/0"], a.category_runs, ctx)
    out["per_run_s"] = {"pub2": pub2, "pub5": pub5, "pub5_all": times5}
    # On paper: a 10,000-run category sweep on 16 nodes, each running one run per core, at the
    # measured per-run cost and the measured 2-worker Ray efficiency (runs/s on 2 workers over
    # twice that on 1), cores per node 2 (this machine) or 32.
    eff = out["throughput"]["ray_2"]["runs_per_s"] / (2 * out["throughput"]["ray_1"]["runs_per_s"])
    out["ray_2_worker_efficiency"] = eff
    out["category_sweep_10000_hours"] = {f"16_nodes_x_{c}_cores": 10000 * pub5 / (16 * c * eff) / 3600
                                         for c in (2, 32)}
    os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
