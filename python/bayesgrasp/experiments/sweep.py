"""Parameter sweeps: one experiment over a grid of settings (e.g. measurement noise x particle
count), every point's runs on one engine with one progress bar, stored in one results file.

A point's series are stored as ``SERIES@LABEL`` (e.g. ``pub2/stability@planner.n_particles=250``)
with the point's full settings and its parameters (``sweep``) in the settings table; every point
uses the same seeds (the same problems), so differences between points come from the settings.
Each point's report goes to ``OUT/LABEL/``; ``OUT/sweep.json``, ``sweep.csv``, ``sweep.md`` and
``sweep.png`` put the points side by side.
"""
from __future__ import annotations

import csv
import itertools
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Dict, List, Sequence

from ..loop.context import RunContext
from .driver import prepare
from .engines import LocalEngine
from .registry import get_experiment
from .report import mpl, save_figure
from .runner import ResultStore, Series, run_all


@dataclass(frozen=True)
class Point:
    """One grid point: its parameters ({"planner.n_particles": 250, ...}) and run context."""

    params: Dict[str, object]
    ctx: RunContext

    @property
    def label(self) -> str:
        return "_".join(f"{k}={v}" for k, v in self.params.items())


def grid(axes: Dict[str, Sequence]) -> List[Dict[str, object]]:
    """Every combination of the axes' values, the first axis slowest: [{key: value, ...}, ...]."""
    if not axes:
        raise ValueError("sweep: no parameters")
    for k, values in axes.items():
        if len(values) == 0:
            raise ValueError(f"sweep: {k} has no values")
        if len(set(map(str, values))) != len(values):
            raise ValueError(f"sweep: {k} repeats a value: {list(values)}")
    keys = list(axes)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(axes[k] for k in keys))]


def _headline(summary: dict) -> Dict[str, float]:
    """A report's summary as flat numbers: per method, the last value of each per-attempt list
    and every scalar number."""
    out = {}
    for method, v in summary.items():
        if not isinstance(v, dict):
            continue
        for k, x in v.items():
            if isinstance(x, list) and x and all(isinstance(e, (int, float)) for e in x):
                out[f"{method}.{k.replace('_by_attempt', '')}_final"] = float(x[-1])
            elif isinstance(x, (int, float)) and not isinstance(x, bool):
                out[f"{method}.{k}"] = float(x)
    return out


def run_sweep(name: str, out_dir, points: Sequence[Point], runs=None, objects=None, engine=None,
              progress: Callable[[str], None] = None) -> List[dict]:
    """Runs (or resumes) experiment ``name`` at every point into ``out_dir``; returns one row per
    point: its parameters and its report's headline numbers."""
    exp = get_experiment(name)
    if not points:
        raise ValueError("sweep: no points")
    if len({p.label for p in points}) != len(points):
        raise ValueError("sweep: two points have the same parameters")
    runs = exp.runs if runs is None else int(runs)
    if runs < 1:
        raise ValueError(f"runs: must be at least 1, got {runs}")
    engine = engine or LocalEngine(1)
    objects = list(exp.objects if objects is None else objects)
    out = Path(out_dir)
    store = ResultStore(out / "results.sqlite")
    plans = []  # (point, {method: series name}, [Series])
    try:
        for p in points:
            settings = {**p.ctx.result_settings().to_dict(), "sweep": {k: _plain(v) for k, v in p.params.items()}}
            names, series = {}, []
            for method in exp.methods:
                base, fn = exp.make_run(exp, method, p.ctx.for_workers())
                names[method] = f"{base}@{p.label}"
                store.check_settings(names[method], settings)   # before anything is built
                series.append(Series(names[method], tuple(objects), runs, fn, seed_name=exp.seeds))
            plans.append((p, names, series))
        for i, (p, _, _) in enumerate(plans):
            if progress is not None:
                progress(f"sweep point {i + 1}/{len(plans)} ({p.label}): preparing")
            prepare(exp, objects, p.ctx, engine)
        done = run_all([s for _, _, ss in plans for s in ss], store, points[0].ctx.seed, engine,
                       progress=progress is not None)
        store.flatten()
    finally:
        store.close()
    rows = []
    for p, names, _ in plans:
        written = exp.report(exp, {m: done[s] for m, s in names.items()}, out / p.label)
        rows.append({**p.params, **_headline(written.summary), "dir": p.label})
    _write_summary(name, rows, list(points[0].params), out)
    return rows


def _plain(v):
    return v if isinstance(v, (int, float, str, bool)) or v is None else str(v)


def _write_summary(name: str, rows: List[dict], axes: List[str], out: Path) -> None:
    (out / "sweep.json").write_text(json.dumps(rows, indent=1))
    cols = list(dict.fromkeys(k for r in rows for k in r))
    with open(out / "sweep.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        w.writerows(rows)
    shown = axes + [c for c in cols if c.endswith("success_final")] + [c for c in cols if c.endswith("plan_ms_median")]
    fmt = lambda v: f"{v:.3f}" if isinstance(v, float) else str(v)  # noqa: E731
    md = [f"# {name}: sweep over {', '.join(axes)}", "", "| " + " | ".join(shown + ["report"]) + " |",
          "|" + "---|" * (len(shown) + 1)]
    md += ["| " + " | ".join(fmt(r.get(c, "")) for c in shown) + f" | [{r['dir']}]({r['dir']}/summary.md) |"
           for r in rows]
    md += ["", "Every point runs the same problems (seeds); success_final: success by the last attempt over all "
               "runs; each point's own report is in its directory.", ""]
    metric = next((c for c in cols if c.endswith("success_final")), None)
    if metric is not None:
        _plot(rows, axes, metric, out / "sweep.png", name)
        md += ["![sweep](sweep.png)", ""]
    (out / "sweep.md").write_text("\n".join(md))


def _plot(rows: List[dict], axes: List[str], metric: str, path: Path, name: str) -> None:
    """``metric`` against the first axis, one line per combination of the other axes."""
    plt = mpl()
    x_axis, rest = axes[0], axes[1:]
    fig, ax = plt.subplots(figsize=(6, 4))
    groups: Dict[tuple, list] = {}
    for r in rows:
        groups.setdefault(tuple(r[a] for a in rest), []).append(r)
    numeric = all(isinstance(r[x_axis], (int, float)) for r in rows)
    for key, rs in groups.items():
        xs = [r[x_axis] for r in rs] if numeric else list(range(len(rs)))
        label = ", ".join(f"{a}={v}" for a, v in zip(rest, key)) or None
        ax.plot(xs, [r[metric] for r in rs], "o-", label=label)
        if not numeric:
            ax.set_xticks(xs, [str(r[x_axis]) for r in rs])
    ax.set_xlabel(x_axis)
    ax.set_ylabel(metric)
    ax.set_ylim(0, 1.05)
    ax.set_title(f"{name}: {metric}")
    if rest:
        ax.legend(fontsize=8)
    save_figure(fig, path)
