"""Running an experiment: build what the runs share once (models, task grasps), run every
(method, object, run) not yet stored, write the report. Any registered experiment
(:mod:`.registry`) runs this way, on any engine (:mod:`.engines`)."""
from __future__ import annotations

import time
from functools import partial
from pathlib import Path
from typing import Dict, Optional, Sequence

from ..loop.context import RunContext
from .engines import LocalEngine
from .registry import get_experiment
from .report import Report
from .runner import ResultStore, Series, run_all


def _prepare_object(obj: str, name: str, ctx: RunContext) -> float:
    """Engine task: experiment ``name``'s shared inputs of one object (its models) built or
    loaded into the cache; returns the seconds it took."""
    from . import get_experiment as registered  # importing the package registers every experiment

    t0 = time.perf_counter()
    exp = registered(name)
    exp.prepare_object(exp, obj, ctx)
    return time.perf_counter() - t0


def prepare(exp, objects: Sequence[str], ctx: RunContext, engine) -> None:
    """What the runs share, built once: per object as engine tasks (in parallel; each writes the
    model cache the runs then read) when the experiment has ``prepare_object``, then its
    ``prepare`` in this process."""
    if exp.prepare_object is not None:
        local = isinstance(engine, LocalEngine) and engine.workers == 1
        task = partial(_prepare_object, name=exp.name, ctx=ctx if local else ctx.for_workers())
        for obj, seconds in engine.map(task, list(objects)):
            if ctx.progress is not None:
                ctx.progress(f"{exp.name}: {obj} prepared ({seconds:.0f} s)")
    if exp.prepare is not None:
        exp.prepare(exp, list(objects), ctx)


def run(name: str, out_dir, ctx: Optional[RunContext] = None, runs: Optional[int] = None, workers: int = 1,
        objects: Optional[Sequence[str]] = None, engine=None) -> Report:
    """Runs (or resumes) experiment ``name`` into ``out_dir`` and writes its tables and plots.
    ``engine``: where the runs go (default: ``workers`` local processes; not both). Returns the report's
    :class:`~.report.Report` (where it was written, and summary.json's content). Progress (model building, the progress bar) is shown
    when ``ctx.progress`` is set."""
    exp = get_experiment(name)
    ctx = ctx or RunContext()
    runs = exp.runs if runs is None else int(runs)
    if runs < 1:
        raise ValueError(f"runs: must be at least 1, got {runs}")
    if workers < 1:
        raise ValueError(f"workers: must be at least 1, got {workers}")
    if engine is not None and workers != 1:
        raise ValueError(f"workers: the engine has its own ({workers} would be ignored); give one of the two")
    engine = engine or LocalEngine(workers)
    objects = list(exp.objects if objects is None else objects)
    out = Path(out_dir)
    worker_ctx = ctx.for_workers()
    runs_of = {method: exp.make_run(exp, method, worker_ctx) for method in exp.methods}  # (series, fn)
    settings = ctx.result_settings().to_dict()
    store = ResultStore(out / "results.sqlite")
    try:
        # Refuse a resume under other settings before building anything.
        for series, _ in runs_of.values():
            store.check_settings(series, settings)
        prepare(exp, objects, ctx, engine)
        todo = [Series(name, tuple(objects), runs, fn, seed_name=exp.seeds) for name, fn in runs_of.values()]
        done = run_all(todo, store, ctx.seed, engine, progress=ctx.progress is not None, settings=settings)
        results: Dict[str, list] = {method: done[series] for method, (series, _) in runs_of.items()}
        store.flatten()
    finally:
        store.close()
    written = exp.report(exp, results, out)
    if exp.finish is not None:
        exp.finish(exp, objects, ctx, out)
    return written
