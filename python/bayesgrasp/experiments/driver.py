"""Running an experiment: build what the runs share once (models, task grasps), run every
(method, object, run) not yet stored, write the report. Any registered experiment
(:mod:`.registry`) runs this way."""
from __future__ import annotations

from pathlib import Path
from typing import Dict, Optional, Sequence

from .context import RunContext
from .registry import get_experiment
from .runner import ResultStore, run_experiment


def run(name: str, out_dir, ctx: Optional[RunContext] = None, runs: Optional[int] = None, workers: int = 1,
        objects: Optional[Sequence[str]] = None) -> dict:
    """Runs (or resumes) experiment ``name`` into ``out_dir`` and writes its tables and plots.
    Returns the summary dict (also written as summary.json). Progress (model building, the
    progress bar) is shown when ``ctx.progress`` is set."""
    exp = get_experiment(name)
    ctx = ctx or RunContext()
    runs = exp.runs if runs is None else int(runs)
    if runs < 1:
        raise ValueError(f"runs: must be at least 1, got {runs}")
    if workers < 1:
        raise ValueError(f"workers: must be at least 1, got {workers}")
    objects = list(exp.objects if objects is None else objects)
    out = Path(out_dir)
    worker_ctx = ctx.for_workers()
    runs_of = {method: exp.make_run(exp, method, worker_ctx) for method in exp.methods}  # (series, fn)
    settings = ctx.result_settings()
    store = ResultStore(out / "results.sqlite")
    results: Dict[str, list] = {}
    try:
        # Refuse a resume under other settings before building anything.
        for series, _ in runs_of.values():
            store.check_settings(series, settings)
        if exp.prepare is not None:
            exp.prepare(exp, objects, ctx)
        for method, (series, fn) in runs_of.items():
            results[method] = run_experiment(series, objects, runs, fn, store, ctx.seed, workers,
                                             progress=ctx.progress is not None, settings=settings)
        store.flatten()
    finally:
        store.close()
    summary = exp.report(exp, results, out)
    if exp.finish is not None:
        exp.finish(exp, objects, ctx, out)
    return summary
